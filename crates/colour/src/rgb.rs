//! RGB colour spaces by their published primaries: the one RGB-space type, [`RgbSpace`]. It
//! serves the working space of the RGB-based baselines ([`RgbSpace::with_white`]), tests and
//! measurements of the uplift on whole gamuts (sRGB, Rec.2020, ACEScg, ACES2065-1), and the
//! matrices a file's own primaries and white declare (OpenEXR `chromaticities`, PNG `cHRM`).
//! Images go through OCIO where the config has the file's colour space, else through
//! [`RgbSpace::to_xyz_adapted`].

use crate::mat3::{self, Mat3};
use nalgebra::{Matrix3, Vector3};

/// An RGB space: chromaticities of its red, green and blue primaries and of its white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbSpace {
    /// A short name for messages and reports (`sRGB`, `ACEScg`, or where a file's chromaticities
    /// came from); it takes no part in the matrices.
    pub name: &'static str,
    /// CIE 1931 xy of the red, green and blue primaries, in that order.
    pub primaries: [[f64; 2]; 3],
    /// CIE 1931 xy of the space's own white, the colour of RGB (1, 1, 1).
    pub white: [f64; 2],
}

/// ITU-R BT.709-6, Table 1 (sRGB, IEC 61966-2-1, has the same primaries and D65 white).
pub const SRGB: RgbSpace = RgbSpace {
    name: "sRGB",
    primaries: [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]],
    white: [0.3127, 0.3290],
};

/// ITU-R BT.2020-2, Table 3.
pub const REC2020: RgbSpace = RgbSpace {
    name: "Rec.2020",
    primaries: [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
    white: [0.3127, 0.3290],
};

/// ACES AP1 primaries (ACEScg), Academy S-2014-004, with the ACES white (≈ D60).
pub const ACESCG: RgbSpace = RgbSpace {
    name: "ACEScg",
    primaries: [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
    white: [0.32168, 0.33767],
};

/// ACES AP0 primaries (ACES2065-1), SMPTE ST 2065-1:2012, with the ACES white.
pub const ACES2065_1: RgbSpace = RgbSpace {
    name: "ACES2065-1",
    primaries: [[0.7347, 0.2653], [0.0, 1.0], [0.0001, -0.0770]],
    white: [0.32168, 0.33767],
};

/// P3 primaries (SMPTE EG 432-1, ST 2113) with the D65 white: P3-D65.
pub const P3_D65: RgbSpace = RgbSpace {
    name: "P3-D65",
    primaries: [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
    white: [0.3127, 0.3290],
};

/// Adobe RGB (1998), Adobe's specification, 4.3.
pub const ADOBE_RGB: RgbSpace = RgbSpace {
    name: "Adobe RGB (1998)",
    primaries: [[0.64, 0.33], [0.21, 0.71], [0.15, 0.06]],
    white: [0.3127, 0.3290],
};

fn xyz_of(xy: [f64; 2]) -> Vector3<f64> {
    Vector3::new(xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1])
}

/// The linear Bradford cone-response matrix (Lam 1985; as in Lindbloom's and colour-science's
/// tables).
fn bradford_cone() -> Matrix3<f64> {
    Matrix3::new(
        0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296,
    )
}

fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
}

/// The linear Bradford chromatic adaptation from white `from` to white `to` (XYZ, any scale:
/// both are normalised to Y = 1), as a matrix on XYZ.
pub fn bradford(from: [f64; 3], to: [f64; 3]) -> [[f64; 3]; 3] {
    rows(&bradford_matrix(
        Vector3::from(from) / from[1],
        Vector3::from(to) / to[1],
    ))
}

fn bradford_matrix(from: Vector3<f64>, to: Vector3<f64>) -> Matrix3<f64> {
    let b = bradford_cone();
    let scale = Matrix3::from_diagonal(&(b * to).component_div(&(b * from)));
    b.try_inverse().expect("Bradford is invertible") * scale * b
}

/// The normalised primary matrix (SMPTE RP 177-1993) of `primaries` for white `w` (XYZ),
/// from the chromaticity coordinates (x, y, 1 − x − y) so that primaries with y = 0 (those
/// of CIE XYZ) work; `None` when the primaries are not independent.
fn npm(primaries: &[[f64; 2]; 3], w: Vector3<f64>) -> Option<Matrix3<f64>> {
    let p = Matrix3::from_columns(&primaries.map(|[x, y]| Vector3::new(x, y, 1.0 - x - y)));
    let s = p.try_inverse()? * w;
    let m = p * Matrix3::from_diagonal(&s);
    m.iter().all(|v| v.is_finite()).then_some(m)
}

impl RgbSpace {
    /// The matrix from linear RGB of this space to XYZ relative to `white` (Y = 1), e.g. the
    /// white of a model's colorimetry. The normalised primary matrix is made for the space's
    /// own white; a space whose white is within 1e-3 in xy of `white` (the D65 spaces) takes
    /// `white` itself, so RGB (1, 1, 1) maps to it exactly, and any other is adapted with the
    /// linear Bradford transform.
    pub fn to_xyz(&self, white: [f64; 3]) -> [[f64; 3]; 3] {
        let target = Vector3::from(white) / white[1];
        let own = xyz_of(self.white);
        let near = (own[0] / (own[0] + 1.0 + own[2]) - target[0] / target.sum()).abs() < 1e-3
            && (1.0 / (own[0] + 1.0 + own[2]) - 1.0 / target.sum()).abs() < 1e-3;
        let w = if near { target } else { own };
        let mut m = npm(&self.primaries, w).expect("primaries are independent");
        if !near {
            m = bradford_matrix(w, target) * m;
        }
        m *= white[1];
        rows(&m)
    }

    /// The matrix from linear RGB to XYZ relative to `white` (Y = 1) exactly as a file's
    /// primaries and white declare it: the normalised primary matrix for the space's own
    /// white, then linear Bradford adaptation to `white` (none when they are equal). `None`
    /// when the chromaticities describe no RGB space (white with y ≤ 0, dependent primaries,
    /// values not finite).
    pub fn to_xyz_adapted(&self, white: [f64; 3]) -> Option<[[f64; 3]; 3]> {
        let [wx, wy] = self.white;
        if !(wy > 0.0 && wx.is_finite() && white[1] > 0.0) {
            return None;
        }
        let own = xyz_of(self.white);
        let m = bradford_matrix(own, Vector3::from(white) / white[1])
            * npm(&self.primaries, own)?
            * white[1];
        m.iter().all(|v| v.is_finite()).then(|| rows(&m))
    }

    /// The inverse of [`RgbSpace::to_xyz`]: XYZ relative to `white` to linear RGB.
    pub fn from_xyz(&self, white: [f64; 3]) -> [[f64; 3]; 3] {
        let m = self.to_xyz(white);
        let inv = Matrix3::from_fn(|r, c| m[r][c])
            .try_inverse()
            .expect("primaries are independent");
        rows(&inv)
    }

    /// Linear RGB ↔ XYZ with the space's primaries and `white` (XYZ, Y = 1) as its white, not
    /// adapted: RGB (1, 1, 1) is `white`. The working space of the RGB-based baselines (Smits
    /// 1999, Jakob 2019): sRGB's primaries with the white of the colorimetry in use (D65 gives
    /// sRGB itself; E the space colour-science calls "Smits 1999"). The normalised primary
    /// matrix of SMPTE RP 177-1993 (Eq. 3.3–3.5): columns are the primaries' XYZ scaled so that
    /// RGB (1, 1, 1) maps to `white`.
    pub fn with_white(&self, white: [f64; 3]) -> Linear {
        let p = self.primaries.map(|[x, y]| [x / y, 1.0, (1.0 - x - y) / y]);
        // P has the primaries as columns.
        let pm = [0, 1, 2].map(|r| [p[0][r], p[1][r], p[2][r]]);
        let s = mat3::mul_vec(&mat3::inverse(&pm), white);
        let to_xyz = [0, 1, 2].map(|r| [0, 1, 2].map(|c| pm[r][c] * s[c]));
        Linear {
            to_xyz,
            to_rgb: mat3::inverse(&to_xyz),
        }
    }

    /// XYZ of the space's own white with Y = 1 (D65 for sRGB).
    pub fn white_xyz(&self) -> [f64; 3] {
        xyz_of(self.white).into()
    }
}

/// The sRGB transfer function (IEC 61966-2-1): linear [0, 1] to the encoded value.
pub fn srgb_encode(v: f64) -> f64 {
    if v <= 0.0031308 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_encode`]: an encoded sRGB value to linear.
pub fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear RGB ↔ XYZ of one space for one white ([`RgbSpace::with_white`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    /// XYZ = to_xyz · RGB (rows X, Y, Z).
    pub to_xyz: Mat3,
    /// RGB = to_rgb · XYZ.
    pub to_rgb: Mat3,
}

impl Linear {
    /// Linear RGB of an XYZ colour: `to_rgb · xyz`.
    pub fn rgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        mat3::mul_vec(&self.to_rgb, xyz)
    }

    /// XYZ of a linear RGB colour: `to_xyz · rgb`.
    pub fn xyz(&self, rgb: [f64; 3]) -> [f64; 3] {
        mat3::mul_vec(&self.to_xyz, rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mat3::mul_vec as apply;

    #[test]
    fn srgb_matrix_matches_iec_61966_2_1() {
        // IEC 61966-2-1 (sRGB) RGB → XYZ, to its four decimals, for the D65 white of BT.709.
        let published = [
            [0.4124, 0.3576, 0.1805],
            [0.2126, 0.7152, 0.0722],
            [0.0193, 0.1192, 0.9505],
        ];
        let m = SRGB.to_xyz(xyz_of(SRGB.white).into());
        for r in 0..3 {
            for c in 0..3 {
                assert!((m[r][c] - published[r][c]).abs() < 1e-4, "{m:?}");
            }
        }
    }

    #[test]
    fn from_xyz_inverts_to_xyz_and_the_transfer_function_round_trips() {
        let white = SRGB.white_xyz();
        let rgb = [0.2, 0.5, 0.9];
        let back = apply(&SRGB.from_xyz(white), apply(&SRGB.to_xyz(white), rgb));
        assert!((0..3).all(|k| (back[k] - rgb[k]).abs() < 1e-12), "{back:?}");
        for v in [0.0, 0.002, 0.0031308, 0.01, 0.18, 0.5, 1.0] {
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-12, "{v}");
        }
        // Middle grey: 0.18 linear is code value 118 of 255 (IEC 61966-2-1).
        assert_eq!((srgb_encode(0.18) * 255.0).round(), 118.0);
    }

    #[test]
    fn adapted_matrix_handles_cie_xyz_primaries_and_equals_to_xyz_for_other_whites() {
        // CIE XYZ as OpenEXR declares it: (1, 0), (0, 1), (0, 0), white E. Its own matrix is
        // the identity; to D65 it is Bradford from E.
        let xyz = RgbSpace {
            name: "CIE XYZ",
            primaries: [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]],
            white: [1.0 / 3.0, 1.0 / 3.0],
        };
        let e = [1.0, 1.0, 1.0];
        let id = xyz.to_xyz_adapted(e).unwrap();
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (id[r][c] - f64::from(u8::from(r == c))).abs() < 1e-12,
                    "{id:?}"
                );
            }
        }
        let d65 = SRGB.white_xyz();
        let same = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
            (0..3).all(|r| (0..3).all(|c| (a[r][c] - b[r][c]).abs() < 1e-14))
        };
        assert!(same(xyz.to_xyz_adapted(d65).unwrap(), bradford(e, d65)));
        // Away from the target white, both constructions are the same Bradford adaptation.
        assert!(same(
            ACESCG.to_xyz_adapted(d65).unwrap(),
            ACESCG.to_xyz(d65)
        ));
        // A white with y = 0 or collinear primaries declare nothing.
        let bad = RgbSpace {
            white: [0.3, 0.0],
            ..SRGB
        };
        assert!(bad.to_xyz_adapted(d65).is_none());
        let flat = RgbSpace {
            primaries: [[0.3, 0.3], [0.4, 0.4], [0.5, 0.5]],
            ..SRGB
        };
        assert!(flat.to_xyz_adapted(d65).is_none());
    }

    #[test]
    fn white_maps_to_the_target_white() {
        let target = [0.9504, 1.0, 1.0889];
        for space in [SRGB, REC2020, ACESCG, ACES2065_1] {
            let w = apply(&space.to_xyz(target), [1.0; 3]);
            for k in 0..3 {
                assert!((w[k] - target[k]).abs() < 1e-12, "{}: {w:?}", space.name);
            }
        }
    }

    #[test]
    fn acescg_matrices_match_published_ones() {
        let close = |m: [[f64; 3]; 3], p: [[f64; 3]; 3], tol: f64| {
            (0..3).all(|r| (0..3).all(|c| (m[r][c] - p[r][c]).abs() < tol))
        };
        // AP1 → XYZ for the ACES white, as in aces-dev (ACESlib.Transform_Common).
        let m = ACESCG.to_xyz(xyz_of(ACESCG.white).into());
        let published = [
            [0.6624541811, 0.1340042065, 0.1561876870],
            [0.2722287168, 0.6740817658, 0.0536895174],
            [-0.0055746495, 0.0040607335, 1.0103391003],
        ];
        assert!(close(m, published, 1e-9), "{m:?}");
        // AP1 → linear Rec.709 with Bradford to D65 (the ACEScg → sRGB matrix of the ACES
        // configs and colour-science), composed from ours: the adaptation path is right.
        let d65: [f64; 3] = xyz_of(SRGB.white).into();
        let to_srgb = Matrix3::from_fn(|r, c| SRGB.to_xyz(d65)[r][c])
            .try_inverse()
            .unwrap()
            * Matrix3::from_fn(|r, c| ACESCG.to_xyz(d65)[r][c]);
        let published = [
            [1.70505, -0.62179, -0.08326],
            [-0.13026, 1.14080, -0.01055],
            [-0.02400, -0.12897, 1.15297],
        ];
        let m = [0, 1, 2].map(|r| [0, 1, 2].map(|c| to_srgb[(r, c)]));
        assert!(close(m, published, 1e-4), "{m:?}");
    }

    #[test]
    fn the_working_space_under_d65_is_iec_61966_2_1() {
        let a = crate::Colorimetry::new(
            crate::Grid::new(360.0, 780.0, 1.0).unwrap(),
            crate::Observer::Cie1931,
            crate::Illuminant::D65,
        )
        .unwrap();
        let ws = SRGB.with_white(a.white_xyz());
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
