//! Wavelength grids and resampling of tabulated data onto them.

// The value lives below error, whose NotCovered names it.
pub use crate::grid_value::Grid;

use crate::error::Error;

impl Grid {
    /// The most bands a grid has.
    pub const MAX_BANDS: usize = 100_000;

    /// How near END − START must be to a whole number of steps, relative to that number.
    pub const WHOLE_STEPS: f64 = 1e-9;

    /// The paper's grid: 380–730 nm at 10 nm, 36 bands.
    pub const PAPER: Grid = Grid {
        start: 380.0,
        end: 730.0,
        step: 10.0,
    };

    /// The grid from `start` to `end` (nm, both included) every `step` nm, checked: all finite,
    /// `0 < start <= end`, `step > 0`, `end - start` a whole number of steps (to 1e-9 relative)
    /// and at most 100 000 bands. [`Error::Grid`] says which rule failed.
    pub fn new(start: f64, end: f64, step: f64) -> Result<Grid, Error> {
        let bad = |why: &str| Error::Grid(format!("{start}:{end}:{step}: {why}"));
        if !(start.is_finite() && end.is_finite() && step.is_finite()) {
            return Err(bad("start, end and step must be finite numbers"));
        }
        if step <= 0.0 {
            return Err(bad("the step must be positive"));
        }
        if start <= 0.0 || end < start {
            return Err(bad("need 0 < START <= END"));
        }
        let intervals = (end - start) / step;
        if (intervals - intervals.round()).abs() > Grid::WHOLE_STEPS * intervals.max(1.0) {
            return Err(bad("END - START must be a whole number of steps"));
        }
        if intervals.round() + 1.0 > Grid::MAX_BANDS as f64 {
            return Err(bad("more than 100000 bands"));
        }
        Ok(Grid { start, end, step })
    }

    /// The number of bands, at least 1 (`start == end` is one band).
    pub fn len(&self) -> usize {
        ((self.end - self.start) / self.step).round() as usize + 1
    }

    /// Always `false`: a grid has at least one band.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The i-th wavelength, computed from the start so that no rounding error accumulates.
    pub fn wavelength(&self, i: usize) -> f64 {
        self.start + self.step * i as f64
    }

    /// Every wavelength of the grid in nm, ascending ([`Grid::wavelength`] of 0..len).
    pub fn wavelengths(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.wavelength(i)).collect()
    }

    /// Values of tabulated data at this grid's wavelengths, by linear interpolation (data that
    /// already has a sample at a grid wavelength is taken as is, as the paper did). `what` names
    /// the data in errors. The table must be sorted and cover the grid.
    pub fn resample(
        &self,
        what: &str,
        wavelengths: &[f64],
        values: &[f64],
    ) -> Result<Vec<f64>, Error> {
        debug_assert_eq!(wavelengths.len(), values.len());
        let (Some(&first), Some(&last)) = (wavelengths.first(), wavelengths.last()) else {
            return Err(Error::Coverage(format!("{what} has no samples")));
        };
        // A tolerance of a millionth of a nanometre absorbs grids written with rounding.
        let tol = 1e-6;
        if first > self.start + tol || last < self.end - tol {
            return Err(Error::NotCovered {
                what: what.to_string(),
                first,
                last,
                grid: *self,
            });
        }
        let mut out = Vec::with_capacity(self.len());
        let mut j = 0;
        for i in 0..self.len() {
            let w = self.wavelength(i).clamp(first, last);
            while j + 1 < wavelengths.len() && wavelengths[j + 1] < w {
                j += 1;
            }
            let (w0, v0) = (wavelengths[j], values[j]);
            if (w - w0).abs() <= tol || j + 1 == wavelengths.len() {
                out.push(v0);
                continue;
            }
            let (w1, v1) = (wavelengths[j + 1], values[j + 1]);
            if (w1 - w).abs() <= tol {
                out.push(v1);
            } else {
                let t = (w - w0) / (w1 - w0);
                out.push(v0 + t * (v1 - v0));
            }
        }
        Ok(out)
    }
}

impl std::str::FromStr for Grid {
    type Err = Error;

    /// Parses `START:END:STEP` in nanometres.
    fn from_str(s: &str) -> Result<Grid, Error> {
        let parts: Vec<&str> = s.split(':').collect();
        let [a, b, c] = parts.as_slice() else {
            return Err(Error::Grid(format!(
                "'{s}': expected START:END:STEP in nanometres, e.g. 380:730:10"
            )));
        };
        let num = |t: &str| {
            t.trim().parse::<f64>().map_err(|_| {
                Error::Grid(format!(
                    "'{s}': '{t}' is not a number (expected START:END:STEP, e.g. 380:730:10)"
                ))
            })
        };
        Grid::new(num(a)?, num(b)?, num(c)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_grid_has_36_bands() {
        let g: Grid = "380:730:10".parse().unwrap();
        assert_eq!(g, Grid::PAPER);
        assert_eq!(g.len(), 36);
        assert_eq!(g.wavelength(35), 730.0);
        assert_eq!("380:780:5".parse::<Grid>().unwrap().len(), 81);
        assert_eq!("550:550:1".parse::<Grid>().unwrap().len(), 1);
    }

    #[test]
    fn malformed_grids_are_refused() {
        for bad in [
            "",
            "380:730",
            "380:730:0",
            "380:730:-10",
            "730:380:10",
            "380:735:10",
            "a:730:10",
            "380:730:10:1",
            "0:10:1",
            "nan:730:10",
        ] {
            assert!(bad.parse::<Grid>().is_err(), "{bad} should be refused");
        }
    }

    #[test]
    fn resampling_takes_samples_and_interpolates_between() {
        let g = Grid::new(400.0, 420.0, 5.0).unwrap();
        let wl = [390.0, 400.0, 410.0, 420.0, 430.0];
        let v = [9.0, 1.0, 2.0, 4.0, 9.0];
        assert_eq!(
            g.resample("t", &wl, &v).unwrap(),
            vec![1.0, 1.5, 2.0, 3.0, 4.0]
        );
    }

    #[test]
    fn resampling_refuses_a_grid_it_does_not_cover() {
        let g = Grid::new(380.0, 800.0, 10.0).unwrap();
        let err = g.resample("D65", &[380.0, 780.0], &[1.0, 1.0]).unwrap_err();
        assert!(
            matches!(&err, Error::NotCovered { what, first, last, grid }
                if what == "D65" && *first == 380.0 && *last == 780.0 && *grid == g),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(text.contains("D65 covers 380–780 nm"), "{text}");
        assert!(
            text.contains("does not cover the grid 380:800:10"),
            "{text}"
        );
    }
}
