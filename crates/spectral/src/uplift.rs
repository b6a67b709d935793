//! The runtime: r = T_leaf·c + o_leaf, one small matrix multiply per pixel (Eq. 7–8 folded).

use crate::model::{Axis, Node};
use crate::{Error, Grid, Model};

/// One way of turning XYZ colours into spectra: the clustered PCA and the baselines alike, so
/// that evaluation, conversion and reports treat them the same.
pub trait Method: Send + Sync {
    /// The name used on the command line and in reports (`otsu2018`, …).
    fn name(&self) -> &str;
    /// The grid of the spectra it makes.
    fn grid(&self) -> Grid;
    /// Uplifts colours `xyz` (X, Y, Z per colour, white Y = 1) into `out` (one spectrum of
    /// `grid().len()` values per colour).
    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]);
    /// As `uplift_f64`, in single precision.
    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]);
    /// Bytes of the data the f32 uplift reads (tables, matrices, tree): the model's size.
    fn model_bytes(&self) -> usize;
    /// The cluster a colour is uplifted by, for methods that have clusters.
    fn cluster_of(&self, _xyz: [f64; 3]) -> Option<usize> {
        None
    }
}

/// A model prepared for uplifting: per leaf, T = B·M⁻¹ (n×3) and o = μ − T·c_μ, in f64 and f32.
///
/// Leaf choice: the kd-tree on the colour's xy. Colours that are not ordinary take the policy
/// of [`crate::hard`] (black → zero spectrum, dark colours scaled, NaN/±Inf → NaN in every
/// band, no overflow); every finite input gives a finite spectrum with XYZ(r) = c.
#[derive(Debug, Clone)]
pub struct Uplifter {
    grid: Grid,
    bands: usize,
    white: [f64; 2],
    /// (axis, value, below, above) per node; leaves have below = above = leaf index | LEAF.
    nodes: Vec<(usize, f64, u32, u32)>,
    /// Per leaf: columns T·x̂, T·ŷ, T·ẑ and o, each `bands` long, contiguous.
    f64s: Vec<Vec<f64>>,
    f32s: Vec<Vec<f32>>,
    /// Components below these magnitudes cannot overflow T·c + o in f64, f32 (`hard`).
    safe_f64: f64,
    safe_f32: f64,
}

const LEAF: u32 = 1 << 31;

impl Uplifter {
    pub fn new(model: &Model) -> Result<Uplifter, Error> {
        let n = model.grid.len();
        let white = model.colorimetry()?.white_xy();
        let nodes = model
            .tree
            .iter()
            .map(|node| match *node {
                Node::Split {
                    axis,
                    value,
                    below,
                    above,
                } => {
                    let ax = if axis == Axis::X { 0 } else { 1 };
                    let child = |c: usize| match model.tree[c] {
                        Node::Leaf { leaf } => leaf as u32 | LEAF,
                        Node::Split { .. } => c as u32,
                    };
                    (ax, value, child(below), child(above))
                }
                Node::Leaf { leaf } => {
                    (0, f64::NEG_INFINITY, leaf as u32 | LEAF, leaf as u32 | LEAF)
                }
            })
            .collect();
        let f64s: Vec<Vec<f64>> = model
            .leaves
            .iter()
            .map(|leaf| {
                let mut t = vec![0.0; 4 * n];
                for b in 0..n {
                    let mut o = leaf.mean[b];
                    for col in 0..3 {
                        // T[b][col] = Σ_k B[b][k]·M⁻¹[k][col]
                        let v: f64 = (0..3).map(|k| leaf.basis[k][b] * leaf.m_inv[k][col]).sum();
                        t[col * n + b] = v;
                        o -= v * leaf.c_mean[col];
                    }
                    t[3 * n + b] = o;
                }
                t
            })
            .collect();
        let f32s = f64s
            .iter()
            .map(|t| t.iter().map(|&v| v as f32).collect())
            .collect();
        let (safe_f64, safe_f32) = crate::hard::safe_limits(&f64s, n);
        Ok(Uplifter {
            grid: model.grid,
            bands: n,
            white,
            nodes,
            f64s,
            f32s,
            safe_f64,
            safe_f32,
        })
    }

    pub fn bands(&self) -> usize {
        self.bands
    }

    /// Chromaticity of the model's white point.
    pub fn white_xy(&self) -> [f64; 2] {
        self.white
    }

    /// A leaf's affine map in f64: columns T·x̂, T·ŷ, T·ẑ and o, each `bands()` long.
    pub fn affine(&self, leaf: usize) -> &[f64] {
        &self.f64s[leaf]
    }

    /// The leaf a colour is uplifted by.
    #[inline]
    pub fn leaf(&self, xyz: [f64; 3]) -> usize {
        self.leaf_xy(crate::colorimetry::xy(xyz).unwrap_or(self.white))
    }

    /// The leaf of a chromaticity.
    #[inline]
    pub fn leaf_xy(&self, xy: [f64; 2]) -> usize {
        let mut node = 0u32;
        loop {
            let (ax, value, below, above) = self.nodes[node as usize];
            node = if xy[ax] >= value { above } else { below };
            if node & LEAF != 0 {
                return (node & !LEAF) as usize;
            }
        }
    }
}

impl Method for Uplifter {
    fn name(&self) -> &str {
        "otsu2018"
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        Some(self.leaf(xyz))
    }

    fn model_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + self.f32s.iter().map(|t| t.len() * 4).sum::<usize>()
    }

    /// Uplifts colours `xyz` (X, Y, Z per pixel) into `out` (`bands` values per pixel).
    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let n = self.bands;
        assert_eq!(
            xyz.len() / 3 * n,
            out.len(),
            "out must hold `bands` values per colour"
        );
        for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let c = [c[0], c[1], c[2]];
            match crate::hard::ordinary_xy(c, self.safe_f64) {
                Some(xy) => kernel(&self.f64s[self.leaf_xy(xy)], n, c, r),
                None => crate::hard::uplift(self, c, |b, v| r[b] = v),
            }
        }
    }

    /// The leaf is chosen in double precision, so both precisions agree on it.
    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        let n = self.bands;
        assert_eq!(
            xyz.len() / 3 * n,
            out.len(),
            "out must hold `bands` values per colour"
        );
        for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let c64 = [c[0] as f64, c[1] as f64, c[2] as f64];
            match crate::hard::ordinary_xy(c64, self.safe_f32) {
                Some(xy) => kernel(&self.f32s[self.leaf_xy(xy)], n, [c[0], c[1], c[2]], r),
                None => crate::hard::uplift(self, c64, |b, v| r[b] = crate::hard::to_f32(v)),
            }
        }
    }
}

#[inline(always)]
fn kernel<T>(t: &[T], n: usize, c: [T; 3], r: &mut [T])
where
    T: Copy + std::ops::Mul<Output = T> + std::ops::Add<Output = T>,
{
    let (tx, rest) = t.split_at(n);
    let (ty, rest) = rest.split_at(n);
    let (tz, o) = rest.split_at(n);
    for b in 0..n {
        r[b] = o[b] + tx[b] * c[0] + ty[b] * c[1] + tz[b] * c[2];
    }
}
