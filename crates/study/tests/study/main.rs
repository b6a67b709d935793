//! specconv-study's integration tests, one binary: a module per study.

mod extrapolation;
mod simulate;
