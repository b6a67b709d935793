//! Half samples that keep a spectrum's colour: each band goes to one of the two half values
//! around it (so the error per band stays below one half step, 2⁻¹¹ relative, and a value in
//! [0, 1] stays there), and the choice carries the colour error of the bands before it, as
//! error diffusion does along an image row. Rounding each band to nearest leaves XYZ off by
//! up to ≈ 2.5e-4 relative; with the carry what is left is the last bands' step, where the
//! colour-matching functions are small.

use half::f16;

/// The half values just below and above `v` (both `v` when it is one; NaN stays NaN).
fn neighbours(v: f32) -> (f32, f32) {
    let h = f16::from_f32(v);
    let hv = h.to_f32();
    if hv == v || v.is_nan() {
        return (hv, hv);
    }
    // The next half towards +∞ (up) or −∞ from h.
    let step = |up: bool| -> f32 {
        if hv == 0.0 {
            return f16::from_bits(if up { 0x0001 } else { 0x8001 }).to_f32();
        }
        let away_from_zero = h.is_sign_positive() == up;
        let bits = h.to_bits();
        f16::from_bits(if away_from_zero { bits + 1 } else { bits - 1 }).to_f32()
    };
    if hv < v {
        (hv, step(true))
    } else {
        (step(false), hv)
    }
}

/// Rounds every band of `spectra` (`n` bands each) to a half value, which a half file stores
/// exactly, choosing below or above so that XYZ = `weights`·spectrum moves as little as the
/// bands allow: one pass carrying the colour error, then `SWEEPS` passes that flip a band to
/// its other neighbour where that brings the colour closer. Spectra with a non-finite band are
/// rounded to nearest.
pub fn round_to_half_keeping_colour(weights: &[Vec<f64>; 3], spectra: &mut [f32], n: usize) {
    // Each band's weights side by side, and its two half neighbours, found once per spectrum
    // (finding them is most of the cost).
    let w: Vec<[f64; 3]> = (0..n)
        .map(|b| [weights[0][b], weights[1][b], weights[2][b]])
        .collect();
    let mut pairs = vec![(0.0f32, 0.0f32); n];
    let size = |c: &[f64; 3]| c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    // The colour error after replacing `from` by `to` in band `b`.
    let moved = |carry: &[f64; 3], w: &[f64; 3], from: f32, to: f32| {
        let d = from as f64 - to as f64;
        [
            carry[0] + w[0] * d,
            carry[1] + w[1] * d,
            carry[2] + w[2] * d,
        ]
    };
    for spectrum in spectra.chunks_exact_mut(n) {
        if !spectrum.iter().all(|v| v.is_finite()) {
            spectrum
                .iter_mut()
                .for_each(|v| *v = f16::from_f32(*v).to_f32());
            continue;
        }
        // XYZ of (exact − rounded) over the bands done so far.
        let mut carry = [0.0f64; 3];
        for ((v, pair), w) in spectrum.iter_mut().zip(pairs.iter_mut()).zip(&w) {
            let (lo, hi) = neighbours(*v);
            *pair = (lo, hi);
            if lo == hi {
                *v = lo;
                continue;
            }
            let (with_lo, with_hi) = (moved(&carry, w, *v, lo), moved(&carry, w, *v, hi));
            let take_lo = !hi.is_finite() || (lo.is_finite() && size(&with_lo) <= size(&with_hi));
            (*v, carry) = if take_lo {
                (lo, with_lo)
            } else {
                (hi, with_hi)
            };
        }
        for _ in 0..SWEEPS {
            for ((v, &(lo, hi)), w) in spectrum.iter_mut().zip(&pairs).zip(&w) {
                let other = if *v == lo { hi } else { lo };
                if other == *v || !other.is_finite() {
                    continue;
                }
                let flipped = moved(&carry, w, *v, other);
                if size(&flipped) < size(&carry) {
                    (*v, carry) = (other, flipped);
                }
            }
        }
    }
}

/// Passes of single-band flips after the carrying pass.
const SWEEPS: usize = 2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_bracket_the_value() {
        for v in [1e-9f32, 0.1, 0.3333, 1.0, 1.0001, 3.7, 65000.0, -0.2, -1e-6] {
            let (lo, hi) = neighbours(v);
            assert!(lo <= v && v <= hi, "{v}: {lo} {hi}");
            assert_eq!(f16::from_f32(lo).to_f32(), lo);
            assert_eq!(f16::from_f32(hi).to_f32(), hi);
            // Adjacent halves: nothing in between.
            let mid = f16::from_f32(0.5 * (lo + hi)).to_f32();
            assert!(mid == lo || mid == hi, "{v}");
        }
        assert_eq!(neighbours(0.5), (0.5, 0.5));
    }

    #[test]
    fn carrying_the_colour_error_beats_rounding_to_nearest() {
        // Smooth weights like colour-matching functions, and pseudo-random spectra.
        let n = 36;
        let bump = |centre: f64, width: f64| -> Vec<f64> {
            (0..n)
                .map(|b| (-((b as f64 - centre) / width).powi(2)).exp() / 10.0)
                .collect()
        };
        let w = [bump(20.0, 6.0), bump(17.0, 7.0), bump(7.0, 4.0)];
        let xyz = |s: &[f32]| {
            w.each_ref()
                .map(|row| row.iter().zip(s).map(|(a, v)| a * *v as f64).sum::<f64>())
        };
        let (mut worst_nearest, mut worst_carried) = (0.0f64, 0.0f64);
        let mut seed = 12345u64;
        for _ in 0..500 {
            let spectrum: Vec<f32> = (0..n)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                    3.0 * (seed >> 40) as f32 / (1u64 << 24) as f32
                })
                .collect();
            let exact = xyz(&spectrum);
            let size = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let err = |s: &[f32]| {
                let got = xyz(s);
                (0..3).fold(0.0f64, |m, k| m.max((got[k] - exact[k]).abs() / size))
            };
            let nearest: Vec<f32> = spectrum
                .iter()
                .map(|v| f16::from_f32(*v).to_f32())
                .collect();
            let mut carried = spectrum.clone();
            round_to_half_keeping_colour(&w, &mut carried, n);
            for (c, v) in carried.iter().zip(&spectrum) {
                let (lo, hi) = neighbours(*v);
                assert!(*c == lo || *c == hi);
            }
            worst_nearest = worst_nearest.max(err(&nearest));
            worst_carried = worst_carried.max(err(&carried));
        }
        assert!(
            worst_carried * 5.0 < worst_nearest,
            "carried {worst_carried:e}, nearest {worst_nearest:e}"
        );
    }
}
