//! What a method costs: its f32 uplift timed tile by tile on a fixed sequence of random colours,
//! the same for every method and every run (the colours of a texture are unpredictable, and so
//! are these: a method's branches see what they would see on real data).

use specconv_colour::rgb::SRGB;
use specconv_colour::Colorimetry;
use specconv_spectral::Method;
use std::time::Instant;

/// A seeded linear congruential generator (Knuth's MMIX constants): reproducible random numbers
/// for timings and tests, not for anything that must be unpredictable.
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// The generator whose first state is `seed`: the same seed gives the same numbers everywhere.
    pub fn new(seed: u64) -> Lcg {
        Lcg(seed)
    }

    /// The next 53 random bits.
    pub fn next_bits(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 11
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.next_bits() as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}

/// Colours per tile of the timing, as the pipeline's strips hand them over.
pub const TILE: usize = 4096;

/// `n` random linear sRGB colours in [0, 1]³ (with the white of `a`) from `seed`, as XYZ in
/// f32, three per colour.
pub fn random_colours(a: &Colorimetry, n: usize, seed: u64) -> Vec<f32> {
    let ws = SRGB.with_white(a.white_xyz());
    let mut rng = Lcg::new(seed);
    let mut out = Vec::with_capacity(3 * n);
    for _ in 0..n {
        let xyz = ws.xyz([rng.uniform(), rng.uniform(), rng.uniform()]);
        out.extend(xyz.map(|v| v as f32));
    }
    out
}

/// The colours every method is timed on (`report`): [`random_colours`] of a fixed seed.
pub fn timing_colours(a: &Colorimetry, n: usize) -> Vec<f32> {
    random_colours(a, n, 0x2545_f491_4f6c_dd1d)
}

/// Uplifts `xyz` tile by tile into `out` (one tile of spectra), keeping the result alive.
pub fn uplift_tiles(m: &dyn Method, xyz: &[f32], out: &mut [f32]) {
    let n = m.grid().len();
    for tile in xyz.chunks(3 * TILE) {
        let o = &mut out[..tile.len() / 3 * n];
        m.uplift_f32(tile, o);
        std::hint::black_box(&o);
    }
}

/// Seconds to uplift `xyz` tile by tile on this thread, after one warm-up tile (caches, lazy
/// tables, page faults).
pub fn time_one_thread(m: &dyn Method, xyz: &[f32]) -> f64 {
    let n = m.grid().len();
    let mut out = vec![0f32; TILE * n];
    let warm = TILE.min(xyz.len() / 3);
    m.uplift_f32(&xyz[..3 * warm], &mut out[..n * warm]);
    let start = Instant::now();
    uplift_tiles(m, xyz, &mut out);
    start.elapsed().as_secs_f64()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sequence_is_seeded_and_uniform() {
        let (mut a, mut b) = (Lcg::new(7), Lcg::new(7));
        let xs: Vec<f64> = (0..1000).map(|_| a.uniform()).collect();
        assert!(xs
            .iter()
            .all(|&x| (0.0..1.0).contains(&x) && x == b.uniform()));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.05, "{mean}");
        assert_ne!(Lcg::new(8).uniform(), xs[0]);
    }
}
