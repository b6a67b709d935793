//! Any method on another wavelength grid: its spectra are interpolated onto the new grid and
//! then corrected so that their XYZ on the new grid is still the input colour exactly.
//!
//! Linear interpolation alone changes XYZ a little (the colour-matching functions are sampled
//! differently). The correction is the smallest change that restores it: r = L·r₀ + Aᵀ(AAᵀ)⁻¹
//! (c − A·L·r₀), with A the new grid's XYZ rows. Bands beyond the method's grid hold its end
//! values, so widening a grid extrapolates flat.

use crate::error::Error;
use crate::method::Tally;
use crate::Method;
use nalgebra::Matrix3;
use specconv_colour::{Colorimetry, Grid};

/// `inner` resampled onto the grid of `colorimetry`.
pub struct Resampled<M> {
    inner: M,
    colorimetry: Colorimetry,
    /// For each new band: the two source bands and the weight of the second.
    taps: Vec<(usize, usize, f64)>,
    /// Aᵀ(AAᵀ)⁻¹ by columns (one n-vector per XYZ component): the minimum-norm correction per
    /// unit of XYZ error.
    correction: [Vec<f64>; 3],
    /// Whether the new grid is the inner method's own: every tap is (b, b + 1, 0).
    same_grid: bool,
    name: String,
}

impl<M: Method> Resampled<M> {
    /// `colorimetry` is the setting of the new grid: the observer and illuminant the inner
    /// method's XYZ is defined under, sampled on the new grid.
    pub fn new(inner: M, colorimetry: Colorimetry) -> Result<Resampled<M>, Error> {
        let from = inner.grid();
        let taps = taps(from, colorimetry.grid);
        let correction = correction(&colorimetry)?;
        let same_grid = from == colorimetry.grid;
        // On its own grid only the colour is corrected (to another integration): same name.
        let name = if same_grid {
            inner.name().to_string()
        } else {
            format!("{} on {} nm", inner.name(), colorimetry.grid)
        };
        Ok(Resampled {
            inner,
            colorimetry,
            taps,
            correction,
            same_grid,
            name,
        })
    }

    /// One spectrum `r0` on the inner grid, resampled and corrected into `r` (of the new grid's
    /// length, reused across pixels so the per-pixel path does not allocate).
    fn resample<T: Copy + Into<f64>>(&self, c: [f64; 3], r0: &[T], r: &mut [f64]) {
        let at = |i: usize| -> f64 { r0[i].into() };
        if self.same_grid {
            // Interpolation at t = 0 would give each value itself.
            r.iter_mut().zip(r0).for_each(|(v, &x)| *v = x.into());
        } else {
            for (v, &(i, j, t)) in r.iter_mut().zip(&self.taps) {
                *v = at(i) + t * (at(j) - at(i));
            }
        }
        // A·r, its three sums side by side (three chains in flight instead of one), each in
        // band order as a lone sum would add, so the same bits.
        let a = &self.colorimetry.weights;
        let mut ar = [-0.0f64; 3];
        for (b, v) in r.iter().enumerate() {
            for k in 0..3 {
                ar[k] += a[k][b] * v;
            }
        }
        let e: [f64; 3] = std::array::from_fn(|k| c[k] - ar[k]);
        let [c0, c1, c2] = &self.correction;
        for (((v, k0), k1), k2) in r.iter_mut().zip(c0).zip(c1).zip(c2) {
            *v = *v + k0 * e[0] + k1 * e[1] + k2 * e[2];
        }
    }
}

/// For each band of `to`: the two bands of `from` it lies between and the weight of the second
/// (ends held flat).
pub(crate) fn taps(from: Grid, to: Grid) -> Vec<(usize, usize, f64)> {
    let n0 = from.len();
    to.wavelengths()
        .iter()
        .map(|&w| {
            let t = ((w - from.start) / from.step).clamp(0.0, (n0 - 1) as f64);
            let i = (t.floor() as usize).min(n0 - 1);
            let j = (i + 1).min(n0 - 1);
            (i, j, t - i as f64)
        })
        .collect()
}

/// Aᵀ(AAᵀ)⁻¹ by columns, A the XYZ rows of `colorimetry`: the smallest change of a spectrum per
/// unit of XYZ error (one n-vector per XYZ component).
pub(crate) fn correction(colorimetry: &Colorimetry) -> Result<[Vec<f64>; 3], Error> {
    let a = &colorimetry.weights;
    let gram = Matrix3::from_fn(|i, j| a[i].iter().zip(&a[j]).map(|(x, y)| x * y).sum::<f64>());
    let inv = gram.try_inverse().ok_or_else(|| {
        Error::Grid(format!(
            "{}: the grid cannot tell X, Y and Z apart",
            colorimetry.grid
        ))
    })?;
    Ok(std::array::from_fn(|k| {
        (0..colorimetry.bands())
            .map(|b| (0..3).map(|i| a[i][b] * inv[(i, k)]).sum())
            .collect()
    }))
}

impl<M: Method> Method for Resampled<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn grid(&self) -> Grid {
        self.colorimetry.grid
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let (n0, n) = (self.inner.grid().len(), self.colorimetry.bands());
        let mut tmp = vec![0.0; xyz.len() / 3 * n0];
        self.inner.uplift_f64(xyz, &mut tmp);
        for ((c, r0), r) in xyz
            .chunks_exact(3)
            .zip(tmp.chunks_exact(n0))
            .zip(out.chunks_exact_mut(n))
        {
            self.resample([c[0], c[1], c[2]], r0, r);
        }
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        self.uplift_f32_tallied(xyz, out, &mut Tally::default())
    }

    fn uplift_f32_tallied(&self, xyz: &[f32], out: &mut [f32], tally: &mut Tally) {
        let (n0, n) = (self.inner.grid().len(), self.colorimetry.bands());
        if self.same_grid {
            // Corrected in place: no spectra to hold twice (the block's copy cost page faults
            // and as long as the correction; the same arithmetic, so the same bits).
            self.inner.uplift_f32_tallied(xyz, out, tally);
            let mut scratch = vec![0.0; n];
            for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
                let c = [c[0] as f64, c[1] as f64, c[2] as f64];
                self.resample(c, r, &mut scratch);
                r.iter_mut().zip(&scratch).for_each(|(o, &v)| *o = v as f32);
            }
            return;
        }
        let mut tmp = vec![0.0f32; xyz.len() / 3 * n0];
        self.inner.uplift_f32_tallied(xyz, &mut tmp, tally);
        let mut scratch = vec![0.0; n];
        for ((c, r0), r) in xyz
            .chunks_exact(3)
            .zip(tmp.chunks_exact(n0))
            .zip(out.chunks_exact_mut(n))
        {
            let c = [c[0] as f64, c[1] as f64, c[2] as f64];
            self.resample(c, r0, &mut scratch);
            r.iter_mut().zip(&scratch).for_each(|(o, &v)| *o = v as f32);
        }
    }

    fn model_bytes(&self) -> usize {
        self.inner.model_bytes() + self.correction[0].len() * 3 * 8 + self.taps.len() * 24
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        self.inner.cluster_of(xyz)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Model, Uplifter};
    use specconv_colour::{Illuminant, Observer};

    #[test]
    fn resampled_spectra_keep_their_colour_on_the_new_grid() {
        let model = Model::builtin();
        for grid in ["400:700:5", "380:780:1", "380:730:10", "450:650:20"] {
            let grid: Grid = grid.parse().unwrap();
            let a = Colorimetry::new(grid, Observer::Cie1931, Illuminant::D65).unwrap();
            let m = Resampled::new(Uplifter::new(model).unwrap(), a.clone()).unwrap();
            assert_eq!(m.grid(), grid);
            let colours = [
                [0.2, 0.3, 0.1],
                [0.9505, 1.0, 1.089],
                [0.05, 0.02, 0.3],
                [0.0, 0.0, 0.0],
            ];
            let mut r = vec![0.0; grid.len()];
            for c in colours {
                m.uplift_f64(&c, &mut r);
                let back = a.xyz(&r);
                for k in 0..3 {
                    assert!((back[k] - c[k]).abs() < 1e-12, "{grid}: {c:?} → {back:?}");
                }
            }
        }
    }

    #[test]
    fn on_the_same_grid_nothing_changes() {
        let model = Model::builtin();
        let up = Uplifter::new(model).unwrap();
        let same =
            Resampled::new(Uplifter::new(model).unwrap(), model.colorimetry().unwrap()).unwrap();
        let c = [0.3, 0.2, 0.6];
        let (mut r1, mut r2) = (vec![0.0; 36], vec![0.0; 36]);
        up.uplift_f64(&c, &mut r1);
        same.uplift_f64(&c, &mut r2);
        let worst = r1
            .iter()
            .zip(&r2)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn interpolation_follows_the_source_between_its_samples() {
        // 5 nm bands between 10 nm samples lie halfway, before the tiny XYZ correction.
        let model = Model::builtin();
        let a = Colorimetry::new(
            "380:730:5".parse().unwrap(),
            Observer::Cie1931,
            Illuminant::D65,
        )
        .unwrap();
        let m = Resampled::new(Uplifter::new(model).unwrap(), a).unwrap();
        let up = Uplifter::new(model).unwrap();
        let c = [0.25, 0.2, 0.15];
        let (mut r10, mut r5) = (vec![0.0; 36], vec![0.0; 71]);
        up.uplift_f64(&c, &mut r10);
        m.uplift_f64(&c, &mut r5);
        for i in 0..35 {
            assert!(
                (r5[2 * i + 1] - 0.5 * (r10[i] + r10[i + 1])).abs() < 0.01,
                "band {}",
                2 * i + 1
            );
        }
    }
}
