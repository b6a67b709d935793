//! Smits, "An RGB-to-Spectrum Conversion for Reflectances" (J. Graphics Tools 4(4), 1999).
//!
//! The colour, in linear RGB of the working space, is split into white, the secondary (cyan,
//! magenta or yellow) made by the two largest components and the primary made by the largest
//! (Smits' Sec. 3), and the seven basis spectra are added with those weights. The basis spectra
//! are tabulated at ten wavelengths over 380–720 nm; between them they are interpolated linearly
//! and outside they are held constant, as colour-science does with them.

use crate::error::Error;

use crate::Method;
use specconv_colour::{Colorimetry, Grid, SpectralTable};

/// Smits 1999 on a colorimetry's grid, in the Rec. 709 working space with its white.
#[derive(Debug, Clone)]
pub struct Smits1999 {
    grid: Grid,
    bands: usize,
    space: specconv_colour::rgb::Linear,
    /// white, cyan, magenta, yellow, red, green, blue, each `bands` long, in f64 and f32.
    basis: [Vec<f64>; 7],
    basis32: [Vec<f32>; 7],
    to_rgb32: [[f32; 3]; 3],
}

const WHITE: usize = 0;
const CYAN: usize = 1;
const MAGENTA: usize = 2;
const YELLOW: usize = 3;
const RED: usize = 4;
const GREEN: usize = 5;
const BLUE: usize = 6;

/// The seven basis spectra, from Smits 1999, Table 1 (via ../shared/cie, see data/README.md).
pub fn basis_table() -> Result<SpectralTable, Error> {
    Ok(SpectralTable::parse(
        "smits1999_basis.csv",
        include_str!("../../data/smits1999_basis.csv"),
    )?)
}

impl Smits1999 {
    /// The method for colorimetry `a`: the basis spectra on its grid, the working space with its
    /// white.
    pub fn new(a: &Colorimetry) -> Result<Smits1999, Error> {
        let table = basis_table()?;
        let names = ["white", "cyan", "magenta", "yellow", "red", "green", "blue"];
        let mut basis: [Vec<f64>; 7] = Default::default();
        for (k, name) in names.iter().enumerate() {
            let column = table.column(name).ok_or_else(|| {
                Error::Unknown(format!("Smits basis spectrum {name} in the embedded table"))
            })?;
            basis[k] = a
                .grid
                .wavelengths()
                .iter()
                .map(|&l| hold_and_interpolate(&table.wavelengths, column, l))
                .collect();
        }
        let space = specconv_colour::rgb::SRGB.with_white(a.white_xyz());
        Ok(Smits1999 {
            grid: a.grid,
            bands: a.bands(),
            space,
            basis32: basis.clone().map(|b| b.iter().map(|&v| v as f32).collect()),
            basis,
            to_rgb32: space.to_rgb.map(|r| r.map(|v| v as f32)),
        })
    }

    /// The linear RGB of the working space that this method reads.
    pub fn working_space(&self) -> &specconv_colour::rgb::Linear {
        &self.space
    }

    /// Smits' conversion proper, from linear RGB of the working space (`out`: one spectrum).
    pub fn uplift_rgb(&self, rgb: [f64; 3], out: &mut [f64]) {
        let [(i, wi), (j, wj), (k, wk)] = Self::weights(rgb);
        let (bi, bj, bk) = (&self.basis[i], &self.basis[j], &self.basis[k]);
        for (b, o) in out.iter_mut().enumerate().take(self.bands) {
            *o = wi * bi[b] + wj * bj[b] + wk * bk[b];
        }
    }

    /// The basis spectra to add and their weights, for linear RGB (Smits 1999, Fig. 2).
    #[inline]
    fn weights<T>(rgb: [T; 3]) -> [(usize, T); 3]
    where
        T: Copy + PartialOrd + std::ops::Sub<Output = T>,
    {
        let [r, g, b] = rgb;
        if r <= g && r <= b {
            if g <= b {
                [(WHITE, r), (CYAN, g - r), (BLUE, b - g)]
            } else {
                [(WHITE, r), (CYAN, b - r), (GREEN, g - b)]
            }
        } else if g <= r && g <= b {
            if r <= b {
                [(WHITE, g), (MAGENTA, r - g), (BLUE, b - r)]
            } else {
                [(WHITE, g), (MAGENTA, b - g), (RED, r - b)]
            }
        } else if r <= g {
            [(WHITE, b), (YELLOW, r - b), (GREEN, g - r)]
        } else {
            [(WHITE, b), (YELLOW, g - b), (RED, r - g)]
        }
    }
}

/// Linear interpolation in a sorted table, constant beyond its ends.
fn hold_and_interpolate(w: &[f64], v: &[f64], l: f64) -> f64 {
    if l <= w[0] {
        return v[0];
    }
    let last = w.len() - 1;
    if l >= w[last] {
        return v[last];
    }
    let j = w.partition_point(|&x| x <= l) - 1;
    let t = (l - w[j]) / (w[j + 1] - w[j]);
    v[j] + t * (v[j + 1] - v[j])
}

impl Method for Smits1999 {
    fn name(&self) -> &str {
        "smits1999"
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn model_bytes(&self) -> usize {
        (7 * self.bands + 9) * std::mem::size_of::<f32>()
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let n = self.bands;
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            self.uplift_rgb(self.space.rgb([c[0], c[1], c[2]]), r);
        }
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        let n = self.bands;
        let m = &self.to_rgb32;
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            let rgb = m.map(|row| row[0] * c[0] + row[1] * c[1] + row[2] * c[2]);
            let [(i, wi), (j, wj), (k, wk)] = Self::weights(rgb);
            let (bi, bj, bk) = (&self.basis32[i], &self.basis32[j], &self.basis32[k]);
            for b in 0..n {
                r[b] = wi * bi[b] + wj * bj[b] + wk * bk[b];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Illuminant, Observer};

    #[test]
    fn white_is_nearly_flat_and_primaries_pick_their_spectra() {
        let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::E).unwrap();
        let s = Smits1999::new(&a).unwrap();
        let n = a.bands();
        let mut r = vec![0.0; n];
        s.uplift_f64(&s.space.xyz([1.0, 1.0, 1.0]), &mut r);
        assert!(r.iter().all(|v| (v - 1.0).abs() < 1e-3), "{r:?}");
        // Pure red: white·0 + magenta·0 + red·1.
        s.uplift_f64(&s.space.xyz([1.0, 0.0, 0.0]), &mut r);
        for (b, v) in r.iter().enumerate() {
            assert!((v - s.basis[RED][b]).abs() < 1e-12);
        }
        // 730 nm lies beyond the table's 720: held at the 720 value.
        assert_eq!(s.basis[RED][n - 1], 1.0149);
        // 385 nm is halfway-ish between 380 and 417.778 for red: 0.1012 → 0.0515.
        let v = hold_and_interpolate(&[380.0, 417.778], &[0.1012, 0.0515], 390.0);
        assert!((v - (0.1012 + (10.0 / 37.778) * (0.0515 - 0.1012))).abs() < 1e-15);
        // f32 agrees with f64.
        let c = s.space.xyz([0.3, 0.6, 0.2]);
        let mut r32 = vec![0f32; n];
        s.uplift_f32(&c.map(|v| v as f32), &mut r32);
        s.uplift_f64(&c, &mut r);
        assert!(r
            .iter()
            .zip(&r32)
            .all(|(a, b)| (a - *b as f64).abs() < 1e-5));
    }
}
