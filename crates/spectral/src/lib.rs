//! The science of specconv: turning tristimulus colours into spectral reflectances with the
//! clustered PCA of Otsu, Yamamoto and Hachisuka, "Reproducing Spectral Reflectances from
//! Tristimulus Colors" (CGF 2018). Equation numbers in comments are the paper's.
//!
//! - [`Grid`]: wavelength grids and resampling of tabulated data onto them.
//! - [`Observer`], [`Illuminant`]: colour-matching functions (CIE 1931 2°, CIE 1964 10° and the
//!   Wyman 2013 fit the paper used) and light sources (CIE tables, blackbody).
//! - [`SpectralTable`]: measured spectra in CSV.
//! - [`Colorimetry`]: XYZ of a reflectance, normalised so that a perfect white has Y = 1.
//! - [`train`]: per-cluster PCA (Eq. 5–8) in a greedy kd-tree on xy (Eq. 10–13).
//! - [`Model`]: the trained tree and leaves, its versioned file, and the built-in model.
//! - [`Uplifter`]: the runtime, r = T·c + o per pixel, f32 and f64.
//! - [`emission`]: emission spectra of any brightness from a reflectance method (scale, uplift,
//!   scale back).
//! - [`eval`]: reconstruction error, round trip and range of a method on measured spectra.
//! - [`extrapolation`]: how large a model's spectra get on whole gamuts, per leaf.
//! - [`methods`]: the baselines behind the same [`Method`] trait: Smits 1999, Meng et al. 2015,
//!   Jakob & Hanika 2019; [`lab`]: CIELAB and CIEDE2000.
//! - [`simulate`]: spectral radiosity of small scenes, the colour shift of interreflection.
//!
//! This crate knows nothing of images, files by path, threads or FFI.
#![forbid(unsafe_code)]

pub mod blend;
pub mod bounded;
pub mod colorimetry;
pub mod emission;
pub mod eval;
pub mod extrapolation;
pub mod gamut;
pub mod grid;
pub mod hard;
pub mod lab;
pub mod methods;
pub mod model;
pub mod observer;
pub mod pca;
pub mod primaries;
pub mod resample;
pub mod simulate;
pub mod table;
pub mod train;
pub mod uplift;

pub use colorimetry::Colorimetry;
pub use grid::Grid;
pub use model::Model;
pub use observer::{Illuminant, Observer};
pub use table::SpectralTable;
pub use train::{train, TrainOptions, TrainingSet};
pub use uplift::{Method, Uplifter};

/// Everything that can go wrong in the science, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("bad wavelength grid {0}")]
    Grid(String),
    #[error("{0}")]
    Coverage(String),
    #[error("unknown {0}")]
    Unknown(String),
    #[error("{file}, line {line}: {msg}")]
    Csv {
        file: String,
        line: usize,
        msg: String,
    },
    #[error("{file}: {msg}")]
    Model { file: String, msg: String },
    #[error("cannot train: {0}")]
    Training(String),
    #[error("bad scene: {0}")]
    Scene(String),
    #[error("bad blend width {0}")]
    Blend(String),
}
