//! What specconv measures with uplift methods, above the methods themselves:
//!
//! - [`eval`]: reconstruction error, round trip and range of a method on measured spectra, and
//!   K-fold cross-validation of trained models.
//! - [`sets`]: cross-validation across measured sets (leave one set out), a training
//!   recipe's held-out score per set and on its worst set.
//! - [`cost`]: what a method's uplift costs, timed on a fixed sequence of random colours (and
//!   the workspace's one seeded generator, [`cost::Lcg`]).
//! - [`extrapolation`]: how large a model's spectra get on whole gamuts, per leaf.
//! - [`simulate`]: spectral radiosity of small scenes, the colour shift of interreflection.
//! - [`scene`]: the scene format of `specconv simulate` (TOML) and its checks.
//!
//! This crate knows nothing of images, files by path or FFI; it starts no threads.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod cost;
pub mod eval;
pub mod extrapolation;
pub mod scene;
pub mod sets;
pub mod simulate;

/// What can go wrong in a study, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Colour data that cannot be used (a grid, an observer or illuminant table, a CSV table).
    #[error(transparent)]
    Colour(#[from] specconv_colour::Error),
    /// An uplift method or its training failed (e.g. too few spectra for cross-validation).
    #[error(transparent)]
    Spectral(#[from] specconv_spectral::Error),
    /// A scene that cannot be simulated as asked (bad form factors, lights or materials, a
    /// diverging series, too many bounces or patches), with what to ask for instead.
    #[error("bad scene: {0}")]
    Scene(String),
}
