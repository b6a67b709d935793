//! specconv-spectral's integration tests, one binary: a module per subject.

mod baselines;
mod blend;
mod bounded;
mod colour_science;
mod emission;
mod fuzz_readers;
mod hard_inputs;
mod header_constants;
mod model;
mod paper;
mod reference_texels;
mod untrainable;
