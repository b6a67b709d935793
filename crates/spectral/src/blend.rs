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
//! exactly the hard switch; the uplifter sends only the others here (see [`Blend::safe_box`]).

use crate::model::{Axis, Node};
use crate::Error;

/// The default width in xy. Measured (`tests/blend.rs`): the smallest round width for which
/// the largest jump across every boundary of the built-in and the paper's models, 1e-5 apart,
/// stays below 1e-3 with margin, while the Munsell Table 1 Δe mean grows by well under 5 %.
pub const DEFAULT_WIDTH: f64 = 0.02;

/// Widths above this blend clusters across most of the gamut: refused as a mistake.
pub const MAX_WIDTH: f64 = 0.5;

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

/// The tree with its switches softened to width `width` (> 0).
#[derive(Debug, Clone)]
pub(crate) struct Blend {
    width: f64,
    tree: Vec<Node>,
}

impl Blend {
    pub(crate) fn new(tree: &[Node], width: f64) -> Blend {
        debug_assert!(width > 0.0);
        Blend {
            width,
            tree: tree.to_vec(),
        }
    }

    pub(crate) fn width(&self) -> f64 {
        self.width
    }

    /// Weight of `above` at a split of value `v` for coordinate `u`. The end tests use the
    /// same comparisons as [`Blend::safe_box`] and [`Blend::near`], so that outside the band
    /// the result is exactly the hard switch's.
    #[inline]
    fn above(&self, u: f64, v: f64) -> f64 {
        let w = self.width;
        if u >= v + w {
            1.0
        } else if u <= v - w {
            0.0
        } else {
            let t = (u - v + w) / (2.0 * w);
            t * t * (3.0 - 2.0 * t)
        }
    }

    /// Whether a split of value `v` blends coordinate `u`.
    #[inline(always)]
    pub(crate) fn near(&self, u: f64, v: f64) -> bool {
        u > v - self.width && u < v + self.width
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
        let mut i = 0;
        while let Node::Split {
            axis,
            value,
            below,
            above,
        } = self.tree[i]
        {
            let k = if axis == Axis::X { 0 } else { 1 };
            // NaN (a cell's corner at −∞) goes below, as in the walk.
            if xy[k] >= value {
                b[2 * k] = b[2 * k].max(value + self.width);
                i = above;
            } else {
                b[2 * k + 1] = b[2 * k + 1].min(value - self.width);
                i = below;
            }
        }
        b
    }

    /// Adds the blended map of `xy` into `out` (4·n values, zeroed by the caller): Σ wᵢ times
    /// leaf i's columns in `maps` (T·x̂, T·ŷ, T·ẑ, o per leaf, `n` bands each).
    pub(crate) fn map(&self, xy: [f64; 2], maps: &[f64], n: usize, out: &mut [f64]) {
        self.add(0, 1.0, xy, maps, n, out);
    }

    /// Recurses only where both sides have weight; a single side is followed in the loop, so
    /// the depth of the recursion is the number of nested bands the colour lies in.
    fn add(
        &self,
        mut i: usize,
        mut weight: f64,
        xy: [f64; 2],
        maps: &[f64],
        n: usize,
        out: &mut [f64],
    ) {
        loop {
            match self.tree[i] {
                Node::Leaf { leaf } => {
                    let m = &maps[leaf * 4 * n..][..4 * n];
                    for (o, &t) in out.iter_mut().zip(m) {
                        *o += weight * t;
                    }
                    return;
                }
                Node::Split {
                    axis,
                    value,
                    below,
                    above,
                } => {
                    let u = if axis == Axis::X { xy[0] } else { xy[1] };
                    let s = self.above(u, value);
                    if s == 1.0 {
                        i = above;
                    } else if s == 0.0 {
                        i = below;
                    } else {
                        self.add(below, weight * (1.0 - s), xy, maps, n, out);
                        weight *= s;
                        i = above;
                    }
                }
            }
        }
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
        let b = Blend::new(&[Node::Leaf { leaf: 0 }], 0.1);
        assert_eq!(b.above(0.5, 0.4), 1.0);
        assert_eq!(b.above(0.3, 0.4), 0.0);
        assert!((b.above(0.4, 0.4) - 0.5).abs() < 1e-15);
        let mut last = 0.0;
        for k in 0..=2000 {
            let u = 0.29 + 0.22 * k as f64 / 2000.0;
            let s = b.above(u, 0.4);
            assert!((0.0..=1.0).contains(&s) && s >= last, "{u}: {s}");
            // The largest slope of smoothstep over 2w is 1.5 / (2w).
            assert!(s - last <= 1.5 / 0.2 * 0.22 / 2000.0 + 1e-12, "{u}");
            last = s;
        }
    }
}
