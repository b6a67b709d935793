//! The filters maketx makes MIP levels (and `--resize`s) with: OpenImageIO 2.4's `Filter2D`
//! family (`filter.cpp`), evaluated in `f32` with its arithmetic, so that levels filtered here
//! from the spectra are the levels maketx makes of the same values.
//!
//! A filter's width is in pixels of the smaller image (OpenImageIO's `resize` scales distances
//! by the size ratio); each has OpenImageIO's default width, scaled by the ratio when enlarging
//! (maketx's `setup_filter`).

use crate::choices::Filter;
use std::f32::consts::PI;

/// What a filter does: its kernel, as OpenImageIO's `Filter2D` evaluates it.
pub trait Kernel: Copy {
    /// Whether it has negative lobes: it can push a filtered value below the smallest (or above
    /// the largest) of those it weighs.
    fn has_negative_lobes(self) -> bool;
    /// OpenImageIO's default width (`filter2d_list`), in pixels of the smaller image.
    fn width(self) -> f32;
    /// Whether it is a product of one filter across and one down.
    fn separable(self) -> bool;
    /// The filter of `width` at `x` (OpenImageIO's `xfilt`), for a separable filter.
    fn along(self, x: f32, width: f32) -> f32;
    /// The filter of `width` × `height` at (`x`, `y`) (OpenImageIO's `operator()`).
    fn at(self, xy: (f32, f32), size: (f32, f32)) -> f32;
}

impl Kernel for Filter {
    /// Whether it has negative lobes: it can push a filtered value below the smallest (or above
    /// the largest) of those it weighs.
    fn has_negative_lobes(self) -> bool {
        use Filter::*;
        matches!(
            self,
            CatmullRom
                | Sinc
                | Lanczos3
                | RadialLanczos3
                | NukeLanczos6
                | Mitchell
                | Keys
                | Simon
                | Rifman
        )
    }

    /// OpenImageIO's default width (`filter2d_list`), in pixels of the smaller image.
    fn width(self) -> f32 {
        use Filter::*;
        match self {
            Box | Disk => 1.0,
            Triangle | SharpGaussian => 2.0,
            Gaussian | BlackmanHarris => 3.0,
            CatmullRom | Sinc | Mitchell | Bspline | Cubic | Keys | Simon | Rifman => 4.0,
            Lanczos3 | RadialLanczos3 | NukeLanczos6 => 6.0,
        }
    }

    /// Whether it is a product of one filter across and one down.
    fn separable(self) -> bool {
        !matches!(self, Filter::RadialLanczos3 | Filter::Disk)
    }

    /// The filter of `width` at `x` (OpenImageIO's `xfilt`), for a separable filter.
    fn along(self, x: f32, width: f32) -> f32 {
        use Filter::*;
        // Most are defined on [-1, 1] and scaled to the width by 2 / width.
        let unit = x * (2.0 / width);
        match self {
            Box | Disk => f32::from(u8::from(x.abs() <= width * 0.5)),
            Triangle => (1.0 - unit.abs()).max(0.0),
            Gaussian => gaussian(unit, -2.0),
            SharpGaussian => gaussian(unit, -4.0),
            CatmullRom => catmull_rom(x * (4.0 / width)),
            BlackmanHarris => blackman_harris(unit),
            Sinc => sinc(x, width / 2.0),
            Lanczos3 | RadialLanczos3 | NukeLanczos6 => lanczos3(x * (6.0 / width)),
            Mitchell => mitchell(unit),
            Bspline => bspline(x * (4.0 / width)),
            Cubic => cubic(unit, 0.0),
            Keys => cubic(unit, -0.5),
            Simon => cubic(unit, -0.75),
            Rifman => cubic(unit, -1.0),
        }
    }

    /// The filter of `width` × `height` at (`x`, `y`) (OpenImageIO's `operator()`).
    fn at(self, (x, y): (f32, f32), (width, height): (f32, f32)) -> f32 {
        match self {
            Filter::RadialLanczos3 => {
                let (x, y) = (x * (6.0 / width), y * (6.0 / height));
                lanczos3((x * x + y * y).sqrt())
            }
            Filter::Disk => {
                let (x, y) = (x / (width * 0.5), y / (height * 0.5));
                f32::from(u8::from(x * x + y * y < 1.0))
            }
            f => f.along(x, width) * f.along(y, height),
        }
    }
}

/// `exp(k·x²)` inside [-1, 1] with OpenImageIO's `fast_exp` (a polynomial `exp2`): its values,
/// not libm's, are those maketx weighs with.
fn gaussian(x: f32, k: f32) -> f32 {
    let x = x.abs();
    if x < 1.0 {
        fast_exp(k * (x * x))
    } else {
        0.0
    }
}

/// OpenImageIO 2.4's `fast_exp` (fmath.h): `fast_exp2(x / ln 2)`.
// Its polynomial's coefficients as fmath.h spells them (rounded to f32, as C++ rounds them).
#[allow(clippy::excessive_precision)]
fn fast_exp(x: f32) -> f32 {
    let x = (x * (1.0 / std::f64::consts::LN_2) as f32).clamp(-126.0, 126.0);
    let m = x as i32;
    let x = x - m as f32;
    // Crushes denormals, as OpenImageIO does.
    let x = 1.0 - (1.0 - x);
    let mut r = 1.333_364_984_02e-3_f32;
    for k in [
        9.810_352_697_968e-3,
        5.551_834_031_939e-2,
        0.240_179_330_110_5,
        0.693_144_857_883,
        1.0,
    ] {
        r = x * r + k;
    }
    f32::from_bits(r.to_bits().wrapping_add((m as u32) << 23))
}

fn catmull_rom(x: f32) -> f32 {
    let x = x.abs();
    let (x2, x3) = (x * x, x * x * x);
    if x >= 2.0 {
        0.0
    } else if x < 1.0 {
        3.0 * x3 - 5.0 * x2 + 2.0
    } else {
        -x3 + 5.0 * x2 - 8.0 * x + 4.0
    }
}

fn blackman_harris(x: f32) -> f32 {
    if !(-1.0..=1.0).contains(&x) {
        return 0.0;
    }
    // The classic window is centred at 0.5; one cosine and the multiple-angle identities, as
    // OpenImageIO computes it.
    let x = (x + 1.0) * 0.5;
    let c2 = (2.0 * PI * x).cos();
    let c4 = 2.0 * c2 * c2 - 1.0;
    let c6 = c2 * (2.0 * c4 - 1.0);
    0.35875 - 0.48829 * c2 + 0.14128 * c4 - 0.01168 * c6
}

fn sinc(x: f32, radius: f32) -> f32 {
    let x = x.abs();
    if x > radius {
        0.0
    } else if x < 0.0001 {
        1.0
    } else {
        (PI * x).sin() / (PI * x)
    }
}

fn lanczos3(x: f32) -> f32 {
    let x = x.abs();
    if x > 3.0 {
        return 0.0;
    }
    if x < 0.0001 {
        return 1.0;
    }
    // One sine and sin(3a) = 3 sin a − 4 sin³ a, as OpenImageIO computes it.
    let s1 = (x * (1.0 / 3.0) * PI).sin();
    let s3 = (-4.0 * s1 * s1 + 3.0) * s1;
    3.0 / (x * x * (PI * PI)) * s1 * s3
}

fn mitchell(x: f32) -> f32 {
    let x = x.abs();
    if x > 1.0 {
        return 0.0;
    }
    // The paper's B = C = 1/3 on [-2, 2].
    let x = x * 2.0;
    let x2 = x * x;
    let (b, c) = (1.0f32 / 3.0, 1.0f32 / 3.0);
    let sixth = 1.0f32 / 6.0;
    if x >= 1.0 {
        ((-b - 6.0 * c) * x * x2
            + (6.0 * b + 30.0 * c) * x2
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c))
            * sixth
    } else {
        ((12.0 - 9.0 * b - 6.0 * c) * x * x2 + (-18.0 + 12.0 * b + 6.0 * c) * x2 + (6.0 - 2.0 * b))
            * sixth
    }
}

fn bspline(x: f32) -> f32 {
    let x = x.abs();
    if x <= 1.0 {
        let t = 1.0 - x;
        0.5 * t * (t * (1.0 - t) + 1.0) + 1.0 / 6.0
    } else if x < 2.0 {
        let t = 2.0 - x;
        t * t * t / 6.0
    } else {
        0.0
    }
}

/// The cubic family on [-1, 1] (scaled from [-2, 2]) with parameter `a`.
fn cubic(x: f32, a: f32) -> f32 {
    let x = x.abs();
    if x > 1.0 {
        return 0.0;
    }
    let x = x * 2.0;
    if x >= 1.0 {
        a * (x * (x * (x - 5.0) + 8.0) - 4.0)
    } else {
        x * x * ((a + 2.0) * x - (a + 3.0)) + 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_description::Named;

    #[test]
    fn fast_exp_is_close_to_exp() {
        for x in [-4.0f32, -2.0, -0.5, -0.01, 0.0] {
            let (a, b) = (fast_exp(x), x.exp());
            assert!((a - b).abs() <= 3e-5 * b, "{x}: {a} {b}");
        }
    }

    #[test]
    fn every_filter_peaks_at_its_centre_and_ends_at_its_width() {
        for &f in Filter::ALL {
            let w = f.width();
            assert!(f.at((0.0, 0.0), (w, w)) > 0.0, "{f}");
            assert_eq!(f.at((w * 0.51, 0.0), (w, w)), 0.0, "{f}");
        }
    }
}
