//! Colour of spectra sampled at any wavelengths, integrated as the spectral EXR layout's
//! reference implementation does (afichet/spectral-exr, `SpectrumConverter`): the spectrum is
//! interpolated linearly onto the observer's tabulated 1 nm grid, wherever that grid, the
//! spectrum's range and (for reflectances) the illuminant's table overlap, and summed there.
//!
//! - emission: XYZ = Σ S(λ)·x̄(λ) over the 1 nm samples, no normalisation (the layout's
//!   ∫ S0·x̄ dλ with dλ = 1 nm); [`EmissionUnits`] scales it for the other conventions;
//! - reflectance: XYZ = Σ r(λ)·I(λ)·x̄(λ) / Σ I(λ)·ȳ(λ) over the same samples, so a perfect
//!   white has Y = 1.
//!
//! Outside the overlap nothing counts: bands beyond 830 nm (or beyond the illuminant's table)
//! are ignored, and a spectrum that stops at 730 nm has no light from 731–830 nm. Samples are
//! whole nanometres inside the spectrum's range (the reference rounds a fractional end to the
//! nearest one and extrapolates there; the difference is below a thousandth of a band).
//!
//! Both are linear in the band values, so [`Integration`] holds them as per-band weights: a
//! file's XYZ costs three dot products per pixel, whatever its grid.

use crate::error::Error;

use crate::{Colorimetry, Grid, Illuminant, Observer};

/// The observer's tabulated grid: CIE tables are 360–830 nm at 1 nm; the analytic Wyman 2013
/// fit is sampled on the same grid.
pub const TABLE: Grid = Grid {
    start: 360.0,
    end: 830.0,
    step: 1.0,
};

/// Luminous efficacy of radiation at 555 nm, lm/W (CIE 15:2018, Kₘ = 683 lm/W).
pub const KM: f64 = 683.0;

/// Linear interpolation of spectra at arbitrary increasing wavelengths onto whole nanometres.
#[derive(Debug, Clone)]
pub struct Onto {
    /// The 1 nm samples the spectrum reaches (inside the table and the limits).
    pub grid: Grid,
    /// Per sample: the two bands around it and the weight of the second.
    taps: Vec<(usize, usize, f64)>,
}

impl Onto {
    /// `wavelengths` (nm, strictly increasing) onto the table's samples inside them and inside
    /// `limits` (an illuminant's table, if any).
    pub fn new(wavelengths: &[f64], limits: Option<(f64, f64)>) -> Result<Onto, Error> {
        let (Some(&first), Some(&last)) = (wavelengths.first(), wavelengths.last()) else {
            return Err(Error::Coverage("a spectrum needs at least one band".into()));
        };
        if wavelengths.iter().any(|w| !w.is_finite())
            || wavelengths.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(Error::Grid(
                "band wavelengths must be finite and each distinct".into(),
            ));
        }
        let (lo, hi) = limits.unwrap_or((TABLE.start, TABLE.end));
        // A millionth of a nanometre absorbs wavelengths written with rounding.
        let tol = 1e-6;
        let start = (first - tol).ceil().max(TABLE.start).max(lo.ceil());
        let end = (last + tol).floor().min(TABLE.end).min(hi.floor());
        if end < start {
            return Err(Error::Coverage(format!(
                "the bands ({first}–{last} nm) do not overlap the observer's {}–{} nm{}: \
                 they have no colour",
                TABLE.start,
                TABLE.end,
                limits.map_or(String::new(), |(a, b)| format!(
                    " and the illuminant's {a}–{b} nm"
                ))
            )));
        }
        let grid = Grid::new(start, end, 1.0)?;
        let mut j = 0;
        let taps = grid
            .wavelengths()
            .iter()
            .map(|&l| {
                while j + 2 < wavelengths.len() && wavelengths[j + 1] < l - tol {
                    j += 1;
                }
                if wavelengths.len() == 1 {
                    return (0, 0, 0.0);
                }
                let (a, b) = (wavelengths[j], wavelengths[j + 1]);
                let t = ((l - a) / (b - a)).clamp(0.0, 1.0);
                (j, j + 1, t)
            })
            .collect();
        Ok(Onto { grid, taps })
    }

    /// The spectrum `values` (one per band) on [`Onto::grid`].
    pub fn apply<T: Copy + Into<f64>>(&self, values: &[T], out: &mut [f64]) {
        for (o, &(i, j, t)) in out.iter_mut().zip(&self.taps) {
            let (a, b) = (values[i].into(), values[j].into());
            *o = a + t * (b - a);
        }
    }

    /// Per-band weights of a linear functional given by its weights `w` on the 1 nm samples.
    fn pull_back(&self, w: &[f64], bands: usize) -> Vec<f64> {
        let mut out = vec![0.0; bands];
        for (&wl, &(i, j, t)) in w.iter().zip(&self.taps) {
            out[i] += (1.0 - t) * wl;
            out[j] += t * wl;
        }
        out
    }
}

/// XYZ of spectra sampled at given wavelengths: `xyz = Σ_b weights[k][b]·v[b]`.
#[derive(Debug, Clone)]
pub struct Integration {
    /// The band wavelengths (nm, strictly increasing) that the weights are for.
    pub wavelengths: Vec<f64>,
    /// The weights of X, Y and Z: `weights[k][b]` multiplies the value of band `b`.
    pub weights: [Vec<f64>; 3],
}

impl Integration {
    /// Emission in the layout's reference convention, XYZ = Σ S·x̄ over the 1 nm samples.
    pub fn emission(wavelengths: &[f64], observer: Observer) -> Result<Integration, Error> {
        let onto = Onto::new(wavelengths, None)?;
        let cmfs = observer.cmfs(&onto.grid)?;
        Ok(Integration {
            wavelengths: wavelengths.to_vec(),
            weights: cmfs.map(|c| onto.pull_back(&c, wavelengths.len())),
        })
    }

    /// Reflectance under `illuminant`, XYZ = Σ r·I·x̄ / Σ I·ȳ over the 1 nm samples.
    pub fn reflectance(
        wavelengths: &[f64],
        observer: Observer,
        illuminant: Illuminant,
    ) -> Result<Integration, Error> {
        let onto = Onto::new(wavelengths, illuminant.range())?;
        let fine = Colorimetry::new(onto.grid, observer, illuminant)?;
        Ok(Integration {
            wavelengths: wavelengths.to_vec(),
            weights: fine.weights.map(|c| onto.pull_back(&c, wavelengths.len())),
        })
    }

    /// The same weights scaled by `factor` (a unit convention).
    pub fn scaled(mut self, factor: f64) -> Integration {
        for w in &mut self.weights {
            w.iter_mut().for_each(|v| *v *= factor);
        }
        self
    }

    /// XYZ of one spectrum, one value per band in the order of `wavelengths`.
    pub fn xyz<T: Copy + Into<f64>>(&self, v: &[T]) -> [f64; 3] {
        self.weights
            .each_ref()
            .map(|w| w.iter().zip(v).map(|(a, &b)| a * b.into()).sum())
    }

    /// As a [`Colorimetry`] on `grid` (whose wavelengths these are), for the uplift stack.
    pub fn colorimetry(
        self,
        grid: Grid,
        observer: Observer,
        illuminant: Illuminant,
    ) -> Colorimetry {
        debug_assert_eq!(grid.len(), self.wavelengths.len());
        Colorimetry {
            grid,
            observer,
            illuminant,
            weights: self.weights,
        }
    }
}

/// An illuminant's relative power at each of `wavelengths` (nm, any spacing).
pub fn illuminant_at(illuminant: Illuminant, wavelengths: &[f64]) -> Result<Vec<f64>, Error> {
    wavelengths
        .iter()
        .map(|&w| Ok(illuminant.spd(&Grid::new(w, w, 1.0)?)?[0]))
        .collect()
}

/// What S0 values mean: the radiometric convention of emission files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EmissionUnits {
    /// The layout's reference: ∫ S0·x̄ dλ (1 nm steps) is the colour.
    #[default]
    Reference,
    /// ∫ S0·ȳ dλ / ∫ ȳ dλ = Y: a flat S0 = 1 has Y = 1 (pbrt-v4, Mitsuba 3).
    Normalised,
    /// The colour's Y is luminance in cd/m²; S0 is radiance in W·m⁻²·sr⁻¹·nm⁻¹: Y = 683·∫ S0·ȳ dλ.
    Photometric,
}

impl EmissionUnits {
    /// Every convention, the default ([`EmissionUnits::Reference`]) first.
    pub const ALL: [EmissionUnits; 3] = [
        EmissionUnits::Reference,
        EmissionUnits::Normalised,
        EmissionUnits::Photometric,
    ];

    /// The name in options and messages (`reference`, `normalised`, `photometric`); `FromStr`
    /// reads it back, ignoring case, and takes `normalized` too.
    pub fn name(self) -> &'static str {
        match self {
            EmissionUnits::Reference => "reference",
            EmissionUnits::Normalised => "normalised",
            EmissionUnits::Photometric => "photometric",
        }
    }

    /// XYZ of emission in this convention, for spectra at `wavelengths`.
    pub fn integration(
        self,
        wavelengths: &[f64],
        observer: Observer,
    ) -> Result<Integration, Error> {
        let reference = Integration::emission(wavelengths, observer)?;
        let factor = match self {
            EmissionUnits::Reference => 1.0,
            // Σ_b ȳ-weights = Σ ȳ over the samples: the hat functions sum to 1 at each.
            EmissionUnits::Normalised => 1.0 / reference.weights[1].iter().sum::<f64>(),
            EmissionUnits::Photometric => KM,
        };
        Ok(reference.scaled(factor))
    }
}

impl std::fmt::Display for EmissionUnits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for EmissionUnits {
    type Err = Error;
    fn from_str(s: &str) -> Result<EmissionUnits, Error> {
        EmissionUnits::ALL
            .into_iter()
            .find(|u| {
                u.name().eq_ignore_ascii_case(s)
                    || (s == "normalized" && *u == EmissionUnits::Normalised)
            })
            .ok_or_else(|| {
                Error::Unknown(format!(
                    "emission units '{s}': choose one of reference, normalised, photometric"
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_equal_interpolating_then_summing() {
        let wl = [380.0, 400.0, 450.5, 455.0, 520.0, 700.0, 780.0];
        let v = [0.1, 0.5, 0.2, 0.9, 0.3, 0.8, 0.4];
        let onto = Onto::new(&wl, None).unwrap();
        assert_eq!((onto.grid.start, onto.grid.end), (380.0, 780.0));
        let mut fine = vec![0.0; onto.grid.len()];
        onto.apply(&v, &mut fine);
        // 451 nm lies between 450.5 and 455: 0.2 + (0.5/4.5)·0.7.
        let at451 = fine[(451 - 380) as usize];
        assert!((at451 - (0.2 + 0.5 / 4.5 * 0.7)).abs() < 1e-12, "{at451}");
        let cmfs = Observer::Cie1931.cmfs(&onto.grid).unwrap();
        let direct: Vec<f64> = cmfs
            .iter()
            .map(|c| c.iter().zip(&fine).map(|(a, b)| a * b).sum())
            .collect();
        let e = Integration::emission(&wl, Observer::Cie1931)
            .unwrap()
            .xyz(&v);
        for k in 0..3 {
            assert!(
                (e[k] - direct[k]).abs() < 1e-9 * direct[k],
                "{e:?} {direct:?}"
            );
        }
    }

    #[test]
    fn white_is_one_and_a_flat_emission_is_the_integral_of_ybar() {
        let wl = Grid::PAPER.wavelengths();
        let r = Integration::reflectance(&wl, Observer::Cie1931, Illuminant::D65).unwrap();
        assert!((r.xyz(&vec![1.0; wl.len()])[1] - 1.0).abs() < 1e-12);
        let n = EmissionUnits::Normalised
            .integration(&wl, Observer::Cie1931)
            .unwrap();
        assert!((n.xyz(&vec![1.0; wl.len()])[1] - 1.0).abs() < 1e-12);
        // ∫ ȳ dλ over 380–730 nm of the CIE 1931 table: ≈106.8 (106.86 over 360–830).
        let e = Integration::emission(&wl, Observer::Cie1931).unwrap();
        let y = e.xyz(&vec![1.0; wl.len()])[1];
        assert!((y - 106.8).abs() < 0.1, "{y}");
    }

    #[test]
    fn spectra_outside_the_table_have_no_colour() {
        assert!(Integration::emission(&[900.0, 1000.0], Observer::Cie1931).is_err());
        assert!(Onto::new(&[500.0, 400.0], None).is_err());
        // The D65 table stops at 780 nm: reflectance stops there too.
        let o = Onto::new(&[380.0, 830.0], Illuminant::D65.range()).unwrap();
        assert_eq!(o.grid.end, 780.0);
    }
}
