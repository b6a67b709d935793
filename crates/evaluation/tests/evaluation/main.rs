//! specconv-evaluation's integration tests, one binary: a module per study.

mod colour_shift;
mod extrapolation;
mod simulate;
