//! XYZ of reflectances: the linear map A from an n-band spectrum to a tristimulus colour.

use crate::error::Error;

use crate::{Grid, Illuminant, Observer};

/// The setting in which reflectances become colours: grid, observer and illuminant.
///
/// XYZ of a reflectance r is Σ r·I·x̄ / Σ I·ȳ (likewise Y, Z), so a perfect white has Y = 1
/// whatever the grid. Under illuminant E this is the paper's Δ·Σ r·x̄ (Eq. 4) up to a
/// constant factor, which the uplift does not see: M and c_μ scale with it.
///
/// ```
/// use specconv_colour::{colorimetry::xy, Colorimetry, Grid, Illuminant, Observer};
///
/// let grid: Grid = "380:730:10".parse()?;
/// let c = Colorimetry::new(grid, Observer::Cie1931, Illuminant::D65)?;
/// assert_eq!(c.bands(), 36);
///
/// // The perfect reflector is the white: Y = 1, at D65's chromaticity.
/// let white = c.xyz(&vec![1.0; c.bands()]);
/// assert!((white[1] - 1.0).abs() < 1e-12);
/// let [x, y] = xy(white).unwrap();
/// assert!((x - 0.3127).abs() < 2e-3 && (y - 0.3290).abs() < 2e-3);
///
/// // A reflectance of 0.5 everywhere is a grey of half that luminance.
/// let grey = c.xyz(&vec![0.5; c.bands()]);
/// assert!((grey[1] - 0.5).abs() < 1e-12);
/// # Ok::<(), specconv_colour::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Colorimetry {
    /// The bands a reflectance is sampled on; each row of `weights` has one value per band.
    pub grid: Grid,
    /// The observer whose colour-matching functions `weights` holds, sampled on the grid.
    pub observer: Observer,
    /// The light the reflectances are seen under; its perfect reflector is the white, Y = 1.
    pub illuminant: Illuminant,
    /// Rows of A: the per-band weights giving X, Y and Z.
    pub weights: [Vec<f64>; 3],
}

impl Colorimetry {
    /// A's rows for `grid`, `observer` and `illuminant`: x̄·I, ȳ·I, z̄·I resampled onto the grid
    /// and divided by Σ I·ȳ. Fails with [`Error::Coverage`] when the observer's or the illuminant's
    /// table does not cover the grid (the analytic Wyman 2013 fit, E and blackbodies cover any
    /// grid), and with [`Error::Grid`] when Σ I·ȳ is not positive (the grid sees no light).
    pub fn new(
        grid: Grid,
        observer: Observer,
        illuminant: Illuminant,
    ) -> Result<Colorimetry, Error> {
        let cmfs = observer.cmfs(&grid)?;
        let spd = illuminant.spd(&grid)?;
        let norm: f64 = spd.iter().zip(&cmfs[1]).map(|(i, y)| i * y).sum();
        if norm <= 0.0 || !norm.is_finite() {
            return Err(Error::Grid(format!(
                "the grid {grid} sees no light: Σ I·ȳ = {norm} under {illuminant} with {observer}"
            )));
        }
        let weights = cmfs.map(|cmf| cmf.iter().zip(&spd).map(|(c, i)| c * i / norm).collect());
        Ok(Colorimetry {
            grid,
            observer,
            illuminant,
            weights,
        })
    }

    /// The number of bands: the length of every reflectance given to [`Colorimetry::xyz`].
    pub fn bands(&self) -> usize {
        self.grid.len()
    }

    /// XYZ of a reflectance sampled on the grid.
    pub fn xyz(&self, r: &[f64]) -> [f64; 3] {
        debug_assert_eq!(r.len(), self.bands());
        self.weights
            .each_ref()
            .map(|w| w.iter().zip(r).map(|(a, b)| a * b).sum())
    }

    /// XYZ of the perfect reflector (r = 1), Y = 1: the reference white of CIELAB.
    pub fn white_xyz(&self) -> [f64; 3] {
        self.weights.each_ref().map(|w| w.iter().sum::<f64>())
    }

    /// Chromaticity of the perfect reflector (r = 1): the illuminant's white point.
    pub fn white_xy(&self) -> [f64; 2] {
        let xyz = self.weights.each_ref().map(|w| w.iter().sum::<f64>());
        xy(xyz).expect("a white with Y = 1 has a chromaticity")
    }
}

/// CIE xy chromaticity, or `None` when X+Y+Z is not positive or not finite.
pub fn xy(xyz: [f64; 3]) -> Option<[f64; 2]> {
    let s = xyz[0] + xyz[1] + xyz[2];
    (s > 0.0 && s.is_finite()).then(|| [xyz[0] / s, xyz[1] / s])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_white_has_unit_luminance_and_the_illuminant_white_point() {
        let c = Colorimetry::new(
            Grid::new(360.0, 780.0, 1.0).unwrap(),
            Observer::Cie1931,
            Illuminant::D65,
        )
        .unwrap();
        let white = c.xyz(&vec![1.0; c.bands()]);
        assert!((white[1] - 1.0).abs() < 1e-12);
        // D65 white point, CIE 1931 2°: (0.31271, 0.32902) (CIE 15:2018, Table 1).
        let [x, y] = c.white_xy();
        assert!(
            (x - 0.31271).abs() < 2e-5 && (y - 0.32902).abs() < 2e-5,
            "{x} {y}"
        );
        // And in the XYZ that OCIO's CIE-XYZ-D65 uses: (0.9505, 1, 1.0888) to 1e-3.
        assert!(
            (white[0] - 0.9505).abs() < 1e-3 && (white[2] - 1.0888).abs() < 1e-3,
            "{white:?}"
        );
    }

    #[test]
    fn illuminant_a_white_point() {
        let c = Colorimetry::new(
            Grid::new(380.0, 780.0, 5.0).unwrap(),
            Observer::Cie1931,
            Illuminant::A,
        )
        .unwrap();
        // Illuminant A, CIE 1931 2°: (0.44757, 0.40745) (CIE 15:2018, Table 1).
        let [x, y] = c.white_xy();
        assert!(
            (x - 0.44757).abs() < 2e-4 && (y - 0.40745).abs() < 2e-4,
            "{x} {y}"
        );
    }

    #[test]
    fn chromaticity_is_undefined_without_positive_sum() {
        assert_eq!(xy([0.0, 0.0, 0.0]), None);
        assert_eq!(xy([1.0, -2.0, 0.5]), None);
        assert_eq!(xy([f64::NAN, 1.0, 1.0]), None);
        assert_eq!(xy([1.0, 1.0, 2.0]), Some([0.25, 0.25]));
    }
}
