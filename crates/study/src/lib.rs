//! What specconv measures with uplift methods, above the methods themselves:
//!
//! - [`eval`]: reconstruction error, round trip and range of a method on measured spectra, and
//!   K-fold cross-validation of trained models.
//! - [`cost`]: what a method's uplift costs, timed on a fixed sequence of random colours (and
//!   the workspace's one seeded generator, [`cost::Lcg`]).
//! - [`extrapolation`]: how large a model's spectra get on whole gamuts, per leaf.
//! - [`simulate`]: spectral radiosity of small scenes, the colour shift of interreflection.
//! - [`scene`]: the scene format of `specconv simulate` (TOML) and its checks.
//!
//! This crate knows nothing of images, files by path or FFI; it starts no threads.
#![forbid(unsafe_code)]

pub mod cost;
pub mod eval;
pub mod extrapolation;
pub mod scene;
pub mod simulate;

/// What can go wrong in a study, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Colour(#[from] specconv_colour::Error),
    #[error(transparent)]
    Spectral(#[from] specconv_spectral::Error),
    #[error("bad scene: {0}")]
    Scene(String),
}
