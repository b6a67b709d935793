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
pub mod grid;
pub mod integration;
pub mod lab;
pub mod mat3;
pub mod observer;
pub mod rgb;
pub mod solid;
pub mod table;

pub use colorimetry::Colorimetry;
pub use grid::Grid;
pub use integration::{EmissionUnits, Integration};
pub use observer::{Illuminant, Observer};
pub use table::SpectralTable;

/// What can go wrong with colour data, with what to do about it in the message.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A wavelength grid that cannot be used: malformed (not finite, not increasing, not a whole
    /// number of steps, more than 100 000 bands), band wavelengths not distinct, or a grid that
    /// sees no light under the illuminant. The text names the grid and what is wrong.
    #[error("bad wavelength grid {0}")]
    Grid(String),
    /// A table or illuminant that stops inside the grid it is resampled onto (a front-end may
    /// suggest a grid inside `first`–`last`).
    #[error("{what} covers {first}–{last} nm, which does not cover the grid {grid}")]
    NotCovered {
        /// The table or spectrum.
        what: String,
        /// Its first wavelength, nm.
        first: f64,
        /// Its last wavelength, nm.
        last: f64,
        /// The grid it was to be resampled onto.
        grid: crate::Grid,
    },
    /// Data that does not cover the wavelengths asked for otherwise: a table with no samples, or
    /// bands that do not overlap the observer's 360–830 nm at all.
    #[error("{0}")]
    Coverage(String),
    /// A name that is not known: an observer, an illuminant (or a blackbody temperature outside
    /// 100–1 000 000 K) or emission units; the text lists what to choose from.
    #[error("unknown {0}")]
    Unknown(String),
    /// A malformed CSV table ([`SpectralTable::parse`]).
    #[error("{file}, line {line}: {msg}")]
    Csv {
        /// The `source` name the table was parsed under (a file name).
        file: String,
        /// The line of the text, counted from 1 (blank lines included).
        line: usize,
        /// What is wrong on that line.
        msg: String,
    },
}
