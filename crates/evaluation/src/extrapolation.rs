//! How far a model's uplift strays on colours its leaves were not trained on.
//!
//! A leaf's map r = T·c + o is fitted to the training colours of its xy cell, but serves every
//! colour of the cell, and the outer cells reach far past the training data (Munsell has no
//! colour near the sRGB or Rec.2020 primaries). A wild T shows as spectra much larger than
//! their colour: we measure the **gain** of a spectrum r of colour c,
//!
//!   gain∞ = ‖r‖∞ / (X+Y+Z),   gain₂ = ‖r‖_rms / (X+Y+Z),  ‖r‖_rms = ‖r‖₂ / √n,
//!
//! per unit X+Y+Z because that is the size the uplift itself uses (the dark policy of
//! [`specconv_spectral::otsu2018::hard_inputs`] is linear in it), and it is positive on every RGB cube of non-negative
//! primaries. A flat reflectance ρ under D65 has gain ≈ 0.33 in both norms, whatever ρ. The
//! gain is scale-free (r of k·c is k·r up to the offset o, which the dark policy fades), so
//! a bound on it bounds the spectra of a whole gamut. The reference is the training spectra's
//! own gains: measured reflectances are what a physical spectrum of such a colour looks like.

use specconv_colour::Colorimetry;
use specconv_colour::{mat3::mul_vec as apply, rgb::RgbSpace};
use specconv_spectral::{Method, Uplifter};

/// Largest gains found in a set of spectra.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Gain {
    /// max ‖r‖∞ / (X+Y+Z)
    pub linf: f64,
    /// max ‖r‖_rms / (X+Y+Z)
    pub l2: f64,
    /// The colour with the largest gain∞.
    pub worst: [f64; 3],
    /// Colours measured.
    pub count: usize,
}

impl Gain {
    /// Adds spectrum `r` of colour `c`; colours with X+Y+Z ≤ 0 or non-finite are skipped.
    pub fn add(&mut self, c: [f64; 3], r: &[f64]) {
        let s = c[0] + c[1] + c[2];
        if !(s > 0.0 && s.is_finite()) {
            return;
        }
        let linf = r.iter().fold(0.0f64, |m, v| m.max(v.abs())) / s;
        let rms = (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt() / s;
        self.count += 1;
        if linf > self.linf {
            self.linf = linf;
            self.worst = c;
        }
        self.l2 = self.l2.max(rms);
    }
}

/// The colours of an RGB cube with `steps` values per axis from 0 to 1, as XYZ relative to
/// `white` (black included: [`Gain::add`] skips it).
pub fn rgb_cube(space: &RgbSpace, white: [f64; 3], steps: usize) -> Vec<[f64; 3]> {
    let m = space.to_xyz(white);
    let v = |i: usize| i as f64 / (steps - 1).max(1) as f64;
    let mut out = Vec::with_capacity(steps.pow(3));
    for r in 0..steps {
        for g in 0..steps {
            for b in 0..steps {
                out.push(apply(&m, [v(r), v(g), v(b)]));
            }
        }
    }
    out
}

/// Gains of the uplift of `colours`, per leaf of `up` (the leaf each colour's xy falls in).
pub fn uplift_gains(up: &Uplifter, colours: &[[f64; 3]]) -> Vec<Gain> {
    let n = up.bands();
    let mut per_leaf = Vec::new();
    let mut r = vec![0.0; n];
    for c in colours {
        up.uplift_f64(c, &mut r);
        let leaf = up.leaf(*c);
        if per_leaf.len() <= leaf {
            per_leaf.resize(leaf + 1, Gain::default());
        }
        per_leaf[leaf].add(*c, &r);
    }
    per_leaf
}

/// Gains of measured spectra themselves, per leaf of `up` (by the xy of their colour: for a
/// model's own training set, each leaf's training spectra).
pub fn training_gains(a: &Colorimetry, up: &Uplifter, spectra: &[Vec<f64>]) -> Vec<Gain> {
    let mut per_leaf = Vec::new();
    for s in spectra {
        let c = a.xyz(s);
        let leaf = up.leaf(c);
        if per_leaf.len() <= leaf {
            per_leaf.resize(leaf + 1, Gain::default());
        }
        per_leaf[leaf].add(c, s);
    }
    per_leaf
}

/// The largest of several gains, on each norm.
pub fn worst(gains: &[Gain]) -> Gain {
    gains.iter().fold(Gain::default(), |mut w, g| {
        if g.linf > w.linf {
            w.linf = g.linf;
            w.worst = g.worst;
        }
        w.l2 = w.l2.max(g.l2);
        w.count += g.count;
        w
    })
}
