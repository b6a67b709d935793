//! The colour basics of specconv, below every uplift method: what a spectrum's colour is.
//!
//! - [`Grid`]: wavelength grids and resampling of tabulated data onto them.
//! - [`SpectralTable`]: measured spectra in CSV.
//! - [`Observer`], [`Illuminant`]: colour-matching functions (CIE 1931 2°, CIE 1964 10° and the
//!   Wyman 2013 fit the paper used) and light sources (CIE tables, blackbody).
//! - [`Colorimetry`]: XYZ of a reflectance, normalised so that a perfect white has Y = 1, and
//!   chromaticity ([`colorimetry::xy`]).
//! - [`integration`]: XYZ of spectra at any wavelengths, as the spectral EXR layout's reference
//!   implementation integrates them; the emission units conventions.
//! - [`lab`]: CIELAB and CIEDE2000.
//! - [`rgb`]: the one RGB-space type, by primaries and white, and its matrices.
//! - [`mat3`]: the one 3×3 module (row-major `[[f64; 3]; 3]`): every small matrix of colour.
//! - [`solid`]: the object-colour solid {A·r : 0 ≤ r ≤ 1}, its exact projection and the colour
//!   on it nearest in CIELAB.
//!
//! This crate knows no uplift method, no image, no file by path, no thread and no FFI.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod colorimetry;
mod error;
pub mod grid;
mod grid_value;
pub mod integration;
pub mod lab;
pub mod mat3;
pub mod observer;
pub mod rgb;
pub mod solid;
pub mod table;

pub use colorimetry::Colorimetry;
pub use error::Error;
pub use grid::Grid;
pub use integration::{EmissionUnits, Integration};
pub use observer::{Illuminant, Observer};
pub use table::SpectralTable;
