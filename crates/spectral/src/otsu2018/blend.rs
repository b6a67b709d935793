//! Continuity across cluster boundaries (the paper's Section 6 names the jump as a limitation).
//!
//! With the hard switch of Eq. 10, two colours on either side of a split line get different
//! leaves, so the spectrum jumps there. Blending replaces each split's switch by a weight
//! s = smoothstep over [v − w, v + w] of the colour's coordinate, and evaluates the tree
//! recursively: f(split) = s·f(above) + (1 − s)·f(below), where a subtree is evaluated for
//! any xy, also outside its box. A leaf's f is continuous, so by induction every f is, and
//! the result is a convex combination of leaf maps, r = Σ wᵢ·(Tᵢ·c + oᵢ) with Σ wᵢ = 1. Each
//! leaf map keeps XYZ (A·Tᵢ = I, A·oᵢ = 0), so the blend does too: the round trip stays exact.
//!
//! Colours at least w from every split on their path get s ∈ {0, 1} at every split, that is
//! exactly the hard switch; the uplifter sends only the others here (see `Blend::safe_box`).
//!
//! **Width per split.** Across a split line the blended spectrum changes at most at the
//! smoothstep's largest slope, 1.5 / 2w = 0.75 / w per unit of xy, times the difference
//! between the two sides' maps there. Where a side extrapolates far from its training colours
//! that difference is large, and the user's width is not enough to keep the change below
//! [`MAX_SLOPE`]. So the user's width is the minimum: a split is widened to
//! w = 0.75·D·[`MARGIN`] / [`MAX_SLOPE`], D the largest L∞ difference between its two sides'
//! maps over the part of its line that is a boundary, for colours inside the object-colour
//! solid ([`super::gamut`]), computed once when the blend is made. Widening only the splits
//! that need it keeps the rest of the model, and its error on measured spectra, as it was.

use super::gamut::{self, Gamut};
use super::tree::Tree;
use crate::error::Error;

/// The default width in xy (`width_scan` in `tests/spectral/blend.rs`): with the per-split widening,
/// every boundary of the built-in and the paper's models stays below 1e-3 at any width, and
/// 0.02 is the widest round width at which the Munsell Table 1 Δe mean does not grow (0.03:
/// +2 %, 0.05: +14 %) while the splits that do not need widening still blend over a band.
pub const DEFAULT_WIDTH: f64 = 0.02;

/// Widths above this blend clusters across most of the gamut: refused as a mistake.
pub const MAX_WIDTH: f64 = 0.5;

/// The largest change of a spectrum (L∞) per unit change of its chromaticity that a split may
/// cause: 1e-3 for colours 1e-5 apart in xy.
pub const MAX_SLOPE: f64 = 1e-3 / 1e-5;

/// Safety factor on the derived width: it leaves room for the change of the sides' maps
/// themselves and for the sampling of the line.
pub const MARGIN: f64 = 1.5;

/// Points along each split line at which the sides' difference is measured: at least
/// `SAMPLES`, and at most half the width apart, since a crossing split's band changes the
/// difference over its width (a peak between samples was missed at width 0.002).
const SAMPLES: usize = 96;

/// Checks a blend width: finite, in [0, `MAX_WIDTH`].
pub fn check_width(width: f64) -> Result<(), Error> {
    if width.is_finite() && (0.0..=MAX_WIDTH).contains(&width) {
        Ok(())
    } else {
        Err(Error::Blend(format!(
            "{width}: the width must be a number from 0 (the paper's hard switch) to {MAX_WIDTH}, in xy (default {DEFAULT_WIDTH})"
        )))
    }
}

/// The tree with its switches softened, split by split.
#[derive(Debug, Clone)]
pub(crate) struct Blend {
    /// The user's width: the least of any split.
    width: f64,
    /// Per node of the tree, its split's width (0 for leaves).
    widths: Vec<f64>,
    tree: Tree,
}

impl Blend {
    /// Width `width` (> 0), widened where a split needs it (see the module); `maps`: per leaf,
    /// T·x̂, T·ŷ, T·ẑ and o, `n` bands each.
    pub(crate) fn new(tree: &Tree, width: f64, maps: &[f64], n: usize, gamut: &Gamut) -> Blend {
        debug_assert!(width > 0.0);
        let widths = tree
            .iter()
            .map(|node| if node.split().is_some() { width } else { 0.0 })
            .collect();
        let mut blend = Blend {
            width,
            widths,
            tree: tree.clone(),
        };
        // A split's sides depend on the widths of the splits below it, and its boundary on
        // those above: widths only grow, so a few passes settle them.
        for _ in 0..4 {
            let need = blend.needed_widths(maps, n, gamut);
            let mut grew = false;
            for (w, need) in blend.widths.iter_mut().zip(need) {
                if need > *w {
                    *w = need.min(MAX_WIDTH);
                    grew = true;
                }
            }
            if !grew {
                break;
            }
        }
        blend
    }

    /// The blend of `tree` with the widths `widths` given per node (0 for leaves), as
    /// [`Blend::node_widths`] lists them: a compact texture's. Refuses a list of another length,
    /// or a split's width below `width` or beyond [`MAX_WIDTH`].
    pub(crate) fn with_widths(tree: &Tree, width: f64, widths: Vec<f64>) -> Result<Blend, String> {
        if widths.len() != tree.len() {
            return Err(format!("{} widths for {} nodes", widths.len(), tree.len()));
        }
        for (i, _) in tree.splits() {
            if !(widths[i] >= width && widths[i] <= MAX_WIDTH) {
                return Err(format!(
                    "node {i}'s width {} is outside [{width}, {MAX_WIDTH}]",
                    widths[i]
                ));
            }
        }
        Ok(Blend {
            width,
            widths,
            tree: tree.clone(),
        })
    }

    /// Per node of the tree, its split's width (0 for leaves).
    pub(crate) fn node_widths(&self) -> Vec<f64> {
        self.widths.clone()
    }

    pub(crate) fn width(&self) -> f64 {
        self.width
    }

    /// Per split node (index in the tree), its width.
    pub(crate) fn split_widths(&self) -> Vec<(usize, f64)> {
        self.tree
            .splits()
            .map(|(i, _)| (i, self.widths[i]))
            .collect()
    }

    /// Per node, the width its split needs for [`MAX_SLOPE`] with the current widths (0 for
    /// leaves and splits whose line misses the locus).
    fn needed_widths(&self, maps: &[f64], n: usize, gamut: &Gamut) -> Vec<f64> {
        let mut need = vec![0.0; self.tree.len()];
        let (mut diff, mut weights) = (vec![0.0; 4 * n], Vec::new());
        // Each split with the box [x₀, x₁] × [y₀, y₁] where it has weight.
        for (i, split, bx) in self.tree.boxes(|i| self.widths[i]) {
            let (axis, value) = (split.axis, split.value);
            let (above, below) = (split.above, split.below);
            let k = axis.index();
            let Some(chord) = gamut.chord(axis, value) else {
                continue;
            };
            let (lo, hi) = (chord[0].max(bx[2 - 2 * k]), chord[1].min(bx[3 - 2 * k]));
            let mut largest = 0.0f64;
            let samples = ((hi - lo) / (0.5 * self.width)).ceil().clamp(0.0, 1e5) as usize;
            let samples = samples.max(SAMPLES);
            for s in 0..=samples {
                let mut xy = [value; 2];
                xy[1 - k] = lo + (hi - lo) * s as f64 / samples as f64;
                // Colours of this chromaticity in the solid: Y from 0 to `top`.
                let c = gamut::xyz(xy, 1.0);
                let top = gamut.reach(c);
                if !(lo <= hi && top.is_finite()) {
                    continue;
                }
                diff.fill(0.0);
                for (node, sign) in [(above, 1.0), (below, -1.0)] {
                    self.weights_from(node, sign, xy, &mut weights);
                    for &(leaf, w) in &weights {
                        let m = &maps[leaf as usize * 4 * n..][..4 * n];
                        diff.iter_mut().zip(m).for_each(|(d, t)| *d += w * t);
                    }
                }
                // Affine in Y: the largest difference is at Y = 0 or at Y = top.
                for b in 0..n {
                    let o = diff[3 * n + b];
                    let lin = diff[b] * c[0] + diff[n + b] * c[1] + diff[2 * n + b] * c[2];
                    largest = largest.max(o.abs()).max((top * lin + o).abs());
                }
            }
            need[i] = 0.75 * largest * MARGIN / MAX_SLOPE;
        }
        need
    }

    /// Weight of `above` at split node `i` of value `v` for coordinate `u`. The end tests use
    /// the same comparisons as [`Blend::safe_box`] and [`Blend::near`], so that outside the
    /// band the result is exactly the hard switch's.
    #[inline]
    fn above(&self, i: usize, u: f64, v: f64) -> f64 {
        let w = self.widths[i];
        if u >= v + w {
            1.0
        } else if u <= v - w {
            0.0
        } else {
            let t = (u - v + w) / (2.0 * w);
            t * t * (3.0 - 2.0 * t)
        }
    }

    /// Whether split node `i` of value `v` blends coordinate `u`.
    #[inline(always)]
    pub(crate) fn near(&self, i: usize, u: f64, v: f64) -> bool {
        let w = self.widths[i];
        u > v - w && u < v + w
    }

    /// The box [x₀, x₁] × [y₀, y₁] around `xy` in which every point takes the same path as
    /// `xy` and is at least the width from every split on it (empty when `xy` itself is
    /// not): there the blend is the hard switch. For the cells of the uplifter's leaf table.
    pub(crate) fn safe_box(&self, xy: [f64; 2]) -> [f64; 4] {
        let mut b = [
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
        ];
        // NaN (a cell's corner at −∞) goes below, as in the walk.
        self.tree.path(xy, |i, split, above| {
            let (k, value, w) = (split.axis.index(), split.value, self.widths[i]);
            if above {
                b[2 * k] = b[2 * k].max(value + w);
            } else {
                b[2 * k + 1] = b[2 * k + 1].min(value - w);
            }
        });
        b
    }

    /// The leaves with weight at `xy` and their weights wᵢ (Σ wᵢ = 1), into `out`: the blend
    /// is r = Σ wᵢ·(Tᵢ·c + oᵢ).
    #[inline]
    pub(crate) fn weights(&self, xy: [f64; 2], out: &mut Vec<(u32, f64)>) {
        self.weights_from(0, 1.0, xy, out);
    }

    /// As [`Blend::weights`] for the subtree at node `i`, every weight times `scale`.
    fn weights_from(&self, i: usize, scale: f64, xy: [f64; 2], out: &mut Vec<(u32, f64)>) {
        out.clear();
        self.add(i, scale, xy, out);
    }

    /// Recurses only where both sides have weight; a single side is followed in the loop, so
    /// the depth of the recursion is the number of nested bands the colour lies in.
    fn add(&self, mut i: usize, mut weight: f64, xy: [f64; 2], out: &mut Vec<(u32, f64)>) {
        while let Some(split) = self.tree.split(i) {
            let s = self.above(i, split.coordinate(xy), split.value);
            if s == 1.0 {
                i = split.above;
            } else if s == 0.0 {
                i = split.below;
            } else {
                self.add(split.below, weight * (1.0 - s), xy, out);
                weight *= s;
                i = split.above;
            }
        }
        let leaf = self.tree[i]
            .leaf()
            .expect("a node that does not split is a leaf");
        out.push((leaf as u32, weight));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_outside_the_range_are_refused_with_the_range() {
        for w in [0.0, 1e-6, DEFAULT_WIDTH, MAX_WIDTH] {
            assert!(check_width(w).is_ok(), "{w}");
        }
        for w in [-1e-3, MAX_WIDTH * 1.01, f64::NAN, f64::INFINITY] {
            let e = check_width(w).unwrap_err().to_string();
            assert!(
                e.contains("from 0") && e.contains(&MAX_WIDTH.to_string()),
                "{e}"
            );
        }
    }

    #[test]
    fn the_weight_is_smooth_monotone_and_exact_outside_the_band() {
        let b = Blend {
            width: 0.1,
            widths: vec![0.1],
            tree: Tree::single_leaf(),
        };
        assert_eq!(b.above(0, 0.5, 0.4), 1.0);
        assert_eq!(b.above(0, 0.3, 0.4), 0.0);
        assert!((b.above(0, 0.4, 0.4) - 0.5).abs() < 1e-15);
        let mut last = 0.0;
        for k in 0..=2000 {
            let u = 0.29 + 0.22 * k as f64 / 2000.0;
            let s = b.above(0, u, 0.4);
            assert!((0.0..=1.0).contains(&s) && s >= last, "{u}: {s}");
            // The largest slope of smoothstep over 2w is 1.5 / (2w).
            assert!(s - last <= 1.5 / 0.2 * 0.22 / 2000.0 + 1e-12, "{u}");
            last = s;
        }
    }
}
