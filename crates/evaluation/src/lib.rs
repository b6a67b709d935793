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
mod error;
pub mod eval;
pub mod extrapolation;
pub mod scene;
pub mod sets;
pub mod simulate;

pub use error::Error;
