//! The linear RGB working space of the RGB-based baselines (Smits 1999, Jakob 2019): the
//! Rec. 709 / sRGB primaries, with the white point of the colorimetry in use, so that RGB
//! (1, 1, 1) is the perfect reflector under that illuminant (D65 gives sRGB itself; E gives the
//! space colour-science calls "Smits 1999").

use crate::Colorimetry;

/// Chromaticities of the Rec. 709 primaries R, G, B (ITU-R BT.709-6, Table item 1.3; the same
/// primaries as IEC 61966-2-1 sRGB).
pub const REC709_PRIMARIES: [[f64; 2]; 3] = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]];

/// Linear RGB ↔ XYZ for the Rec. 709 primaries and a colorimetry's white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkingSpace {
    /// XYZ = to_xyz · RGB (rows X, Y, Z).
    pub to_xyz: [[f64; 3]; 3],
    /// RGB = to_rgb · XYZ.
    pub to_rgb: [[f64; 3]; 3],
}

impl WorkingSpace {
    /// The normalised primary matrix (SMPTE RP 177-1993, Eq. 3.3–3.5): columns are the
    /// primaries' XYZ scaled so that RGB (1, 1, 1) maps to the white's XYZ (Y = 1).
    pub fn rec709(a: &Colorimetry) -> WorkingSpace {
        let white = a.white_xyz();
        let p = REC709_PRIMARIES.map(|[x, y]| [x / y, 1.0, (1.0 - x - y) / y]);
        // P has the primaries as columns.
        let pm = [
            [p[0][0], p[1][0], p[2][0]],
            [p[0][1], p[1][1], p[2][1]],
            [p[0][2], p[1][2], p[2][2]],
        ];
        let s = mul_vec(&inverse3(&pm), white);
        let to_xyz = [0, 1, 2].map(|r| [0, 1, 2].map(|c| pm[r][c] * s[c]));
        WorkingSpace {
            to_xyz,
            to_rgb: inverse3(&to_xyz),
        }
    }

    pub fn rgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        mul_vec(&self.to_rgb, xyz)
    }

    pub fn xyz(&self, rgb: [f64; 3]) -> [f64; 3] {
        mul_vec(&self.to_xyz, rgb)
    }
}

pub fn mul_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// Inverse of a 3×3 matrix by cofactors. The matrices inverted here (primaries, Jacobians) are
/// checked by their callers; a singular one gives infinities, not a panic.
pub fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    // Transposed cofactors over the determinant.
    [0, 1, 2].map(|r| [0, 1, 2].map(|k| c(k, r) / det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Grid, Illuminant, Observer};

    #[test]
    fn srgb_matrix_under_d65_matches_iec_61966_2_1() {
        let a = Colorimetry::new(
            Grid::new(360.0, 780.0, 1.0).unwrap(),
            Observer::Cie1931,
            Illuminant::D65,
        )
        .unwrap();
        let ws = WorkingSpace::rec709(&a);
        // IEC 61966-2-1 (sRGB), Eq. 7 (rounded to 4 decimals there; our white is the D65 table
        // integrated, not the rounded xy, hence the tolerance).
        let iec = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        for (row, want) in ws.to_xyz.iter().zip(&iec) {
            for (v, w) in row.iter().zip(want) {
                assert!((v - w).abs() < 6e-4, "{:?}", ws.to_xyz);
            }
        }
        let back = ws.rgb(ws.xyz([0.2, 0.5, 0.9]));
        for (b, v) in back.iter().zip([0.2, 0.5, 0.9]) {
            assert!((b - v).abs() < 1e-14);
        }
        // White maps to the perfect reflector's XYZ.
        let w = ws.xyz([1.0; 3]);
        let aw = a.white_xyz();
        assert!((0..3).all(|k| (w[k] - aw[k]).abs() < 1e-14));
    }
}
