//! The wavelength grid as a value: its three numbers and how it is written (`380:730:10`).
//! [`grid`](crate::grid) checks, parses and resamples onto it.

use serde::{Deserialize, Serialize};

/// An evenly spaced wavelength grid, both ends included: `380:730:10` is 380, 390, …, 730 nm.
///
/// ```
/// use specconv_colour::Grid;
///
/// let g: Grid = "380:730:10".parse()?;
/// assert_eq!(g, Grid::PAPER);
/// assert_eq!((g.len(), g.wavelength(35)), (36, 730.0));
/// assert_eq!(g.to_string(), "380:730:10");
/// assert!("380:735:10".parse::<Grid>().is_err()); // not a whole number of steps
///
/// // Tabulated data onto the grid, by linear interpolation.
/// let coarse = Grid::new(400.0, 420.0, 5.0)?;
/// let values = coarse.resample("t", &[400.0, 410.0, 420.0], &[1.0, 2.0, 4.0])?;
/// assert_eq!(values, [1.0, 1.5, 2.0, 3.0, 4.0]);
/// # Ok::<(), specconv_colour::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// The first wavelength, nm (> 0).
    pub start: f64,
    /// The last wavelength, nm, included: `start` plus a whole number of steps.
    pub end: f64,
    /// The spacing, nm (> 0).
    ///
    /// [`Grid::new`] and parsing check the fields; a literal (such as [`Grid::PAPER`]) or a
    /// deserialised grid is not checked.
    pub step: f64,
}

impl std::fmt::Display for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.start, self.end, self.step)
    }
}
