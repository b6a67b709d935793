//! Hard inputs: what the clustered-PCA uplift ([`crate::Uplifter`]) makes of colours that are
//! not ordinary. Every finite input gives a finite spectrum r with XYZ(r) = c (up to rounding
//! and to the range of the output type); nothing panics.
//!
//! | input | outcome |
//! |---|---|
//! | NaN or ±Inf in any component | NaN in every band (callers count these) |
//! | black, (0, 0, 0) or signed zeros | the zero spectrum: physical, XYZ exactly 0 |
//! | X+Y+Z ≤ 0, not black (negative luminance, no chromaticity) | r = T·c with T of the white point's leaf: linear, so \|r\| shrinks with \|c\| |
//! | 0 < X+Y+Z < [`DARK`] (near black, denormals included) | the same chromaticity uplifted at X+Y+Z = `DARK` and scaled down: r = T·c + (s/`DARK`)·o |
//! | X+Y+Z ≥ `DARK`, negative components, xy outside the locus or the training domain, HDR | the leaf of its xy and r = T·c + o (Eq. 7–8); may leave [0, 1], see [`crate::bounded`] |
//! | components so large that T·c + o would overflow the output type | computed in f64 from c / max\|c\| and scaled, saturating at ± the type's largest finite value |
//!
//! Why fade o for dark colours: the uplift is affine, r = T·c + o, and o is a spectrum whose XYZ
//! is zero (A·o = 0, since A·T = I and A·o = A·μ − c_μ = 0). Any r = T·c + λ·o keeps the round
//! trip exact. With λ = 1 a colour near black becomes ≈ o, an oscillating metameric black whose
//! shape is set by the noise in c; with λ = s/`DARK` the spectrum is s/`DARK` times the
//! uplift of the same chromaticity at X+Y+Z = `DARK`, so its shape is that of a real dark
//! material, it shrinks to the zero spectrum with c, and it is continuous at s = `DARK`.

/// X+Y+Z below which a colour is uplifted as its chromaticity at X+Y+Z = `DARK`, scaled down.
/// 0.01 (Y ≈ 0.003 for a grey) lies below every colour of the Munsell and ColorChecker sets
/// (the darkest Munsell chip has X+Y+Z ≈ 0.03), so the paper's tables are untouched.
pub const DARK: f64 = 1e-2;

/// The chromaticity of an ordinary colour (finite, X+Y+Z ≥ `DARK`, every |component| < `safe`),
/// for the fast path; `None` sends the colour to [`uplift`]. NaN fails every comparison.
#[inline(always)]
pub(crate) fn ordinary_xy(c: [f64; 3], safe: f64) -> Option<[f64; 2]> {
    let s = c[0] + c[1] + c[2];
    (s >= DARK && c[0].abs() < safe && c[1].abs() < safe && c[2].abs() < safe)
        .then(|| [c[0] / s, c[1] / s])
}

/// Largest |component| for which |T·c + o| stays below half the largest f64 and f32, over all
/// leaves (`leaves`: columns T·x̂, T·ŷ, T·ẑ, o per leaf, `n` bands each, leaf after leaf).
pub(crate) fn safe_limits(leaves: &[f64], n: usize) -> (f64, f64) {
    let (mut lin, mut off) = (0.0f64, 0.0f64);
    for t in leaves.chunks_exact(4 * n) {
        for b in 0..n {
            lin = lin.max(t[b].abs() + t[n + b].abs() + t[2 * n + b].abs());
            off = off.max(t[3 * n + b].abs());
        }
    }
    let limit = |max: f64| {
        if lin > 0.0 {
            ((0.5 * max - off) / lin).max(0.0)
        } else {
            f64::INFINITY
        }
    };
    (limit(f64::MAX), limit(f32::MAX as f64))
}

/// Saturating conversion to f32: finite stays finite, NaN stays NaN.
#[inline]
pub(crate) fn to_f32(v: f64) -> f32 {
    v.clamp(-(f32::MAX as f64), f32::MAX as f64) as f32
}

/// What the policy needs of an uplift: its affine maps by chromaticity (the runtime implements
/// it; defined here so that this module needs nothing above it).
pub(crate) trait AffineMaps {
    fn bands(&self) -> usize;
    /// Chromaticity of the white point.
    fn white_xy(&self) -> [f64; 2];
    /// The affine map of a chromaticity: columns T·x̂, T·ŷ, T·ẑ and o (the leaf's, or near a
    /// split line the blend of the leaves' maps, written into `scratch`).
    fn map_xy<'a>(&'a self, xy: [f64; 2], scratch: &'a mut Vec<f64>) -> &'a [f64];
}

/// The policy of the module table for one colour that is not ordinary; `put(band, value)`.
pub(crate) fn uplift(up: &impl AffineMaps, c: [f64; 3], mut put: impl FnMut(usize, f64)) {
    let n = up.bands();
    if c.iter().any(|v| !v.is_finite()) {
        (0..n).for_each(|b| put(b, f64::NAN));
        return;
    }
    let m = c[0].abs().max(c[1].abs()).max(c[2].abs());
    if m == 0.0 {
        (0..n).for_each(|b| put(b, 0.0));
        return;
    }
    // Work on u = c / m (|u| ≤ 1): no overflow in the sum, no precision lost to denormals in xy.
    let u = c.map(|v| v / m);
    let su = u[0] + u[1] + u[2];
    let (xy, weight_o) = if su > 0.0 {
        let s = su * m;
        ([u[0] / su, u[1] / su], (s / DARK).min(1.0))
    } else {
        (up.white_xy(), 0.0)
    };
    // The leaf's map, or the blend of the leaves' maps near a split line.
    let mut scratch = Vec::new();
    let t = up.map_xy(xy, &mut scratch);
    for b in 0..n {
        let lin = t[b] * u[0] + t[n + b] * u[1] + t[2 * n + b] * u[2];
        let v = lin * m + weight_o * t[3 * n + b];
        put(b, v.clamp(-f64::MAX, f64::MAX));
    }
}
