//! What can go wrong with colour data: this crate's error, with what to do in the message.

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
        grid: crate::grid_value::Grid,
    },
    /// Data that does not cover the wavelengths asked for otherwise: a table with no samples, or
    /// bands that do not overlap the observer's 360–830 nm at all.
    #[error("{0}")]
    Coverage(String),
    /// A name that is not known: an observer, an illuminant (or a blackbody temperature outside
    /// 100–1 000 000 K) or emission units; the text lists what to choose from.
    #[error("unknown {0}")]
    Unknown(String),
    /// A malformed CSV table ([`SpectralTable::parse`](crate::SpectralTable::parse)).
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
