//! The runtime: r = T_leaf·c + o_leaf, one small matrix multiply per pixel (Eq. 7–8 folded).

use super::blend::Blend;
use super::gamut::Gamut;
use super::tree::{Axis, Tree};
use crate::error::Error;
use crate::{Method, Model};
use specconv_colour::{Colorimetry, Grid};

/// A model prepared for uplifting: per leaf, T = B·M⁻¹ (n×3) and o = μ − T·c_μ, in f64 and f32.
///
/// Leaf choice: the kd-tree on the colour's xy; with [`Uplifter::with_blend`], colours near a
/// split line blend the maps of both sides ([`super::blend`]). Colours that are not ordinary take the policy
/// of [`super::hard_inputs`] (black → zero spectrum, dark colours scaled, NaN/±Inf → NaN in every
/// band, no overflow); every finite input gives a finite spectrum with XYZ(r) = c.
///
/// Speed: colours go through in blocks of 32: the leaves of a whole block are chosen
/// first, without a data-dependent branch (a random texture's leaves are unpredictable, and a
/// mispredicted branch per tree level cost more than the multiply), then the block is
/// multiplied, every leaf's T and o being hot in L1.
///
/// ```
/// use specconv_spectral::otsu2018::blend::DEFAULT_WIDTH;
/// use specconv_spectral::{Method, Model, Uplifter};
///
/// let model = Model::builtin();
/// let a = model.colorimetry()?; // CIE 1931 2°, D65, 380–730 nm at 10 nm
/// let up = Uplifter::new(model)?;
/// assert_eq!((up.name(), up.bands()), ("otsu2018", 36));
///
/// // A reflectance rising from 0.2 to 0.7: its colour, uplifted, gives back that colour
/// // exactly (Eq. 9), though not the same spectrum.
/// let s: Vec<f64> = a.grid.wavelengths().iter().map(|l| 0.2 + (l - 380.0) / 700.0).collect();
/// let c = a.xyz(&s);
/// let mut r = vec![0.0; up.bands()];
/// up.uplift_f64(&c, &mut r);
/// let back = a.xyz(&r);
/// assert!((0..3).all(|k| (back[k] - c[k]).abs() < 1e-9));
///
/// // Blending across cluster boundaries keeps the round trip.
/// let blended = Uplifter::new(model)?.with_blend(DEFAULT_WIDTH)?;
/// blended.uplift_f64(&c, &mut r);
/// let back = a.xyz(&r);
/// assert!((0..3).all(|k| (back[k] - c[k]).abs() < 1e-9));
/// # Ok::<(), specconv_spectral::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Uplifter {
    /// `otsu2018`, and the grid when moved onto another ([`Uplifter::onto`]).
    name: String,
    grid: Grid,
    bands: usize,
    white: [f64; 2],
    /// The model's colorimetry: where its real colours are, for the blend widths (`None` for
    /// maps read back from a compact texture, whose widths are given).
    colorimetry: Option<Colorimetry>,
    choose: Choose,
    /// Per leaf, `4 * bands` values: columns T·x̂, T·ŷ, T·ẑ and o, each `bands` long.
    f64s: Vec<f64>,
    f32s: Vec<f32>,
    /// Components below these magnitudes cannot overflow T·c + o in f64, f32 (`hard`).
    safe_f64: f64,
    safe_f32: f64,
    tree: Tree,
    /// Blending near split lines; `None`: the hard switch of Eq. 10.
    blend: Option<Blend>,
    /// With blending and `Choose::Cells`: per cell, the box of its points that no split blends
    /// ([`Blend::safe_box`]); a colour outside it takes the blended path.
    safe_boxes: Vec<[f64; 4]>,
}

/// How a chromaticity finds its leaf; both give the tree's answer (Eq. 10) for every xy.
#[derive(Debug, Clone)]
enum Choose {
    /// Trees of up to [`MAX_CELL_SPLITS`] splits. Each split compares one coordinate with one
    /// value, so the sorted values of each axis cut the plane into a grid of cells on which the
    /// tree's answer is constant. A coordinate's cell is the count of values it is ≥ (NaN: none,
    /// as the walk takes `below` at every split); the leaf is read from a table of cells.
    Cells {
        x: Vec<f64>,
        y: Vec<f64>,
        /// Leaf of cell (i, j) at `i * (y.len() + 1) + j`.
        leaf: Vec<u32>,
    },
    /// Larger trees: a walk of `depth` steps (the longest path), each a compare selecting
    /// the next node; a leaf steps to itself.
    Walk { steps: Vec<Step>, depth: usize },
}

/// Up to 31 splits (32 leaves, the most clusters the paper uses) counting beats walking.
const MAX_CELL_SPLITS: usize = 31;

/// One node of the tree. A colour goes to `next[1]` when its coordinate `axis` (0: x, 1: y)
/// is ≥ `value`, else to `next[0]`. A leaf steps to itself (value −∞).
#[derive(Debug, Clone, Copy)]
struct Step {
    value: f64,
    axis: u32,
    next: [u32; 2],
    /// The leaf's index; unused on splits.
    leaf: u32,
}

/// Colours per block. Short: choosing a block's leaves lets the stores of the previous block
/// drain to memory; with 64, uplifting a million colours (past the caches) cost a third more.
const BLOCK: usize = 32;

/// Marks a colour of the block that is not ordinary: it takes [`super::hard_inputs::uplift`].
const HARD: u32 = u32::MAX;
/// Marks an ordinary colour near a split line: it takes the blended map.
const BLEND: u32 = u32::MAX - 1;

impl Uplifter {
    /// Prepares `model`: T = B·M⁻¹ and o = μ − T·c_μ per leaf, the hard switch of Eq. 10 (no
    /// blend). Fails only when the model's colorimetry cannot be made.
    pub fn new(model: &Model) -> Result<Uplifter, Error> {
        let n = model.grid.len();
        let colorimetry = model.colorimetry()?;
        let white = colorimetry.white_xy();
        let choose = Choose::new(&model.tree);
        let f64s: Vec<f64> = model
            .leaves
            .iter()
            .flat_map(|leaf| {
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
        let f32s = f64s.iter().map(|&v| v as f32).collect();
        let (safe_f64, safe_f32) = super::hard_inputs::safe_limits(&f64s, n);
        Ok(Uplifter {
            name: "otsu2018".into(),
            grid: model.grid,
            bands: n,
            white,
            colorimetry: Some(colorimetry),
            choose,
            f64s,
            f32s,
            safe_f64,
            safe_f32,
            tree: model.tree.clone(),
            blend: None,
            safe_boxes: Vec::new(),
        })
    }

    /// Blends the leaves' maps within `width` (in xy) of every split line, so that spectra are
    /// continuous across cluster boundaries ([`super::blend`]); 0 is the hard switch of the
    /// paper, bit for bit. Splits whose sides differ too much get more than `width` (see
    /// [`Uplifter::split_widths`]). See [`super::blend::DEFAULT_WIDTH`].
    pub fn with_blend(mut self, width: f64) -> Result<Uplifter, Error> {
        super::blend::check_width(width)?;
        self.safe_boxes.clear();
        self.blend = None;
        if width > 0.0 {
            let Some(colorimetry) = &self.colorimetry else {
                return Err(Error::Blend(
                    "the widths of maps read back are given, not measured".into(),
                ));
            };
            let gamut = Gamut::new(colorimetry);
            let blend = Blend::new(&self.tree, width, &self.f64s, self.bands, &gamut);
            self.set_blend(blend);
        }
        Ok(self)
    }

    fn set_blend(&mut self, blend: Blend) {
        if let Choose::Cells { x, y, .. } = &self.choose {
            self.safe_boxes = (0..=x.len())
                .flat_map(|i| (0..=y.len()).map(move |j| (i, j)))
                .map(|(i, j)| blend.safe_box([corner(x, i), corner(y, j)]))
                .collect();
        }
        self.blend = Some(blend);
    }

    /// An uplifter from its parts as a compact texture's header gives them
    /// ([`crate::compact`]): the grid, the white point's chromaticity, the tree, per leaf its
    /// map (columns T·x̂, T·ŷ, T·ẑ and o, `grid.len()` each) and, when blended, the user's
    /// width and per node its split's width (0 for leaves). It uplifts as the uplifter whose
    /// parts they are, bit for bit.
    pub fn from_parts(
        grid: Grid,
        white: [f64; 2],
        tree: Tree,
        maps: Vec<f64>,
        blend: Option<(f64, Vec<f64>)>,
    ) -> Result<Uplifter, Error> {
        let n = grid.len();
        let leaves = maps.len() / (4 * n).max(1);
        let bad = |msg: String| Error::Model {
            file: "compact texture".into(),
            msg,
        };
        if maps.len() != leaves * 4 * n || leaves == 0 {
            return Err(bad(format!("{} map values for {n} bands", maps.len())));
        }
        tree.validate(leaves).map_err(bad)?;
        let (safe_f64, safe_f32) = super::hard_inputs::safe_limits(&maps, n);
        let mut up = Uplifter {
            name: "otsu2018".into(),
            grid,
            bands: n,
            white,
            colorimetry: None,
            choose: Choose::new(&tree),
            f32s: maps.iter().map(|&v| v as f32).collect(),
            f64s: maps,
            safe_f64,
            safe_f32,
            tree,
            blend: None,
            safe_boxes: Vec::new(),
        };
        if let Some((width, widths)) = blend {
            super::blend::check_width(width)?;
            let blend = Blend::with_widths(&up.tree, width, widths).map_err(bad)?;
            up.set_blend(blend);
        }
        Ok(up)
    }

    /// The tree the leaves are chosen by.
    pub fn tree(&self) -> &Tree {
        &self.tree
    }

    /// Per node of the tree, the width its split blends over (0 for leaves); `None` when the
    /// switch is hard.
    pub fn node_widths(&self) -> Option<Vec<f64>> {
        self.blend.as_ref().map(Blend::node_widths)
    }

    /// The maps moved onto the grid of `colorimetry` and corrected so that each spectrum's XYZ
    /// under it is the input colour exactly: each column interpolated as
    /// [`crate::resample::Resampled`] interpolates a spectrum (L), then T' = L·T + K·(I − A·L·T)
    /// and o' = L·o − K·A·L·o. The correction is linear, so these are the spectra `Resampled`
    /// makes, blends and dark colours' scaled offsets included; on the model's grid this is
    /// [`Uplifter::exact_under`].
    pub fn onto(mut self, colorimetry: &Colorimetry) -> Result<Uplifter, Error> {
        if colorimetry.grid == self.grid {
            return self.exact_under(colorimetry);
        }
        let taps = crate::resample::taps(self.grid, colorimetry.grid);
        let (n0, n) = (self.bands, colorimetry.bands());
        self.f64s = self
            .f64s
            .chunks_exact(n0)
            .flat_map(|col| {
                taps.iter()
                    .map(|&(i, j, t)| col[i] + t * (col[j] - col[i]))
                    .collect::<Vec<_>>()
            })
            .collect();
        // Named as the resampled method it replaces.
        self.name = format!("{} on {} nm", self.name, colorimetry.grid);
        (self.grid, self.bands) = (colorimetry.grid, n);
        self.exact_under(colorimetry)
    }

    /// The maps corrected so that each spectrum's XYZ under `colorimetry` (on the model's grid:
    /// another integration of it, such as every reader's) is the input colour exactly:
    /// T' = T + K·(I − A·T) and o' = o − K·A·o, with A the XYZ rows of `colorimetry` and
    /// K = Aᵀ(AAᵀ)⁻¹. These are the spectra [`crate::resample::Resampled`] makes on the same
    /// grid, whose correction is linear, so blends (Σ wᵢ = 1) and the dark colours' scaled maps
    /// are corrected alike; folded into the maps, it costs nothing per pixel. Blend widths are
    /// measured on the maps in use when [`Uplifter::with_blend`] is called.
    pub fn exact_under(mut self, colorimetry: &Colorimetry) -> Result<Uplifter, Error> {
        if colorimetry.grid != self.grid {
            return Err(Error::Grid(format!(
                "{}: the maps can only be corrected on the model's grid {} (resample instead)",
                colorimetry.grid, self.grid
            )));
        }
        let k = crate::resample::correction(colorimetry)?;
        let (a, n) = (&colorimetry.weights, self.bands);
        for map in self.f64s.chunks_exact_mut(4 * n) {
            // Column `col` of T should give the unit colour `col` (A·T = I), o should give 0.
            for (col, t) in map.chunks_exact_mut(n).enumerate() {
                let e: [f64; 3] = std::array::from_fn(|i| {
                    let at: f64 = a[i].iter().zip(&*t).map(|(w, v)| w * v).sum();
                    f64::from(u8::from(i == col)) - at
                });
                for (b, v) in t.iter_mut().enumerate() {
                    *v += k[0][b] * e[0] + k[1][b] * e[1] + k[2][b] * e[2];
                }
            }
        }
        self.f32s = self.f64s.iter().map(|&v| v as f32).collect();
        (self.safe_f64, self.safe_f32) = super::hard_inputs::safe_limits(&self.f64s, n);
        Ok(self)
    }

    /// The blend width in xy asked for, the least of any split; 0 when the switch is hard.
    pub fn blend_width(&self) -> f64 {
        self.blend.as_ref().map_or(0.0, Blend::width)
    }

    /// Per split (its node's index in the model's tree), the width it blends over: the blend
    /// width, or more where the split's sides need it. Empty when the switch is hard.
    pub fn split_widths(&self) -> Vec<(usize, f64)> {
        self.blend.as_ref().map_or(Vec::new(), Blend::split_widths)
    }

    /// Bands of every spectrum, the model's grid length.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// Chromaticity of the model's white point.
    pub fn white_xy(&self) -> [f64; 2] {
        self.white
    }

    /// A leaf's affine map in f64: columns T·x̂, T·ŷ, T·ẑ and o, each `bands()` long.
    pub fn affine(&self, leaf: usize) -> &[f64] {
        let m = 4 * self.bands;
        &self.f64s[leaf * m..(leaf + 1) * m]
    }

    /// The leaf a colour is uplifted by.
    #[inline]
    pub fn leaf(&self, xyz: [f64; 3]) -> usize {
        self.leaf_xy(specconv_colour::colorimetry::xy(xyz).unwrap_or(self.white))
    }

    /// The leaf of a chromaticity (with blending: the leaf of the hard switch).
    #[inline(always)]
    pub fn leaf_xy(&self, xy: [f64; 2]) -> usize {
        self.leaf_near::<false>(xy).0
    }

    /// The leaf of a chromaticity and, when `BLENDS`, whether a split on its path blends it.
    #[inline(always)]
    fn leaf_near<const BLENDS: bool>(&self, xy: [f64; 2]) -> (usize, bool) {
        match &self.choose {
            Choose::Cells { x, y, leaf } => {
                let i = x.iter().filter(|&&v| xy[0] >= v).count();
                let j = y.iter().filter(|&&v| xy[1] >= v).count();
                let k = i * (y.len() + 1) + j;
                let near = BLENDS && {
                    let b = &self.safe_boxes[k];
                    !(xy[0] >= b[0] && xy[0] <= b[1] && xy[1] >= b[2] && xy[1] <= b[3])
                };
                (leaf[k] as usize, near)
            }
            Choose::Walk { steps, depth } => {
                let mut i = 0;
                let mut near = false;
                for _ in 0..*depth {
                    let s = &steps[i];
                    let u = xy[(s.axis & 1) as usize];
                    if BLENDS {
                        // A leaf's value is −∞: never near.
                        near |= self.blend.as_ref().is_some_and(|b| b.near(i, u, s.value));
                    }
                    i = s.next[(u >= s.value) as usize] as usize;
                }
                (steps[i].leaf as usize, near)
            }
        }
    }

    /// The affine map of a chromaticity, as [`Uplifter::affine`]: the leaf's, or near a split
    /// line with blending, the blend of the leaves' maps written into `scratch`.
    pub(crate) fn map_xy<'a>(&'a self, xy: [f64; 2], scratch: &'a mut Vec<f64>) -> &'a [f64] {
        match &self.blend {
            Some(blend) => {
                let (leaf, near) = self.leaf_near::<true>(xy);
                if !near {
                    return self.affine(leaf);
                }
                let mut weights = Vec::new();
                blend.weights(xy, &mut weights);
                let m = 4 * self.bands;
                scratch.clear();
                scratch.resize(m, 0.0);
                for (leaf, w) in weights {
                    let t = &self.f64s[leaf as usize * m..][..m];
                    scratch.iter_mut().zip(t).for_each(|(r, t)| *r += w * t);
                }
                scratch
            }
            None => self.affine(self.leaf_xy(xy)),
        }
    }

    /// A colour that is not ordinary, by the policy of [`super::hard_inputs`].
    pub(crate) fn hard_input(&self, c: [f64; 3], put: impl FnMut(usize, f64)) {
        super::hard_inputs::uplift(self, c, put)
    }

    /// Leaves of a block of colours (`HARD` for colours that are not ordinary, `BLEND` for
    /// those that blending reaches, whose chromaticity goes to `xys`).
    #[inline(always)]
    fn block_leaves<T: Copy + Into<f64>>(
        &self,
        xyz: &[T],
        safe: f64,
        leaves: &mut [u32],
        xys: &mut [[f64; 2]],
    ) {
        if self.blend.is_some() {
            self.block_leaves_with::<T, true>(xyz, safe, leaves, xys)
        } else {
            self.block_leaves_with::<T, false>(xyz, safe, leaves, xys)
        }
    }

    #[inline(always)]
    fn block_leaves_with<T: Copy + Into<f64>, const BLENDS: bool>(
        &self,
        xyz: &[T],
        safe: f64,
        leaves: &mut [u32],
        xys: &mut [[f64; 2]],
    ) {
        for ((c, l), at) in xyz.chunks_exact(3).zip(leaves).zip(xys) {
            let c = [c[0].into(), c[1].into(), c[2].into()];
            *l = match super::hard_inputs::ordinary_xy(c, safe) {
                Some(xy) => match self.leaf_near::<BLENDS>(xy) {
                    (_, true) => {
                        *at = xy;
                        BLEND
                    }
                    (leaf, false) => leaf as u32,
                },
                None => HARD,
            };
        }
    }
}

/// A point of cell `i` along an axis of split values `v`: its lowest value, or NaN (≥ nothing)
/// for cell 0.
fn corner(v: &[f64], i: usize) -> f64 {
    if i == 0 {
        f64::NAN
    } else {
        v[i - 1]
    }
}

impl Choose {
    fn new(tree: &Tree) -> Choose {
        let values = |on: Axis| {
            let mut v: Vec<f64> = tree
                .splits()
                .filter(|(_, s)| s.axis == on)
                .map(|(_, s)| s.value)
                .collect();
            v.sort_by(f64::total_cmp);
            v.dedup();
            v
        };
        let (x, y) = (values(Axis::X), values(Axis::Y));
        if x.len() + y.len() <= MAX_CELL_SPLITS {
            let leaf = (0..=x.len())
                .flat_map(|i| (0..=y.len()).map(move |j| (i, j)))
                .map(|(i, j)| tree.walk([corner(&x, i), corner(&y, j)]) as u32)
                .collect();
            return Choose::Cells { x, y, leaf };
        }
        let steps = tree
            .iter()
            .enumerate()
            .map(|(i, node)| match (node.split(), node.leaf()) {
                (Some(s), _) => Step {
                    value: s.value,
                    axis: s.axis.index() as u32,
                    next: [s.below as u32, s.above as u32],
                    leaf: 0,
                },
                (None, leaf) => Step {
                    value: f64::NEG_INFINITY,
                    axis: 0,
                    next: [i as u32; 2],
                    leaf: leaf.expect("a node that does not split is a leaf") as u32,
                },
            })
            .collect();
        Choose::Walk {
            steps,
            depth: tree.depth(),
        }
    }

    /// Bytes read to choose a leaf.
    fn bytes(&self) -> usize {
        match self {
            Choose::Cells { x, y, leaf } => (x.len() + y.len()) * 8 + leaf.len() * 4,
            Choose::Walk { steps, .. } => std::mem::size_of_val(steps.as_slice()),
        }
    }
}

impl super::hard_inputs::AffineMaps for Uplifter {
    fn bands(&self) -> usize {
        Uplifter::bands(self)
    }

    fn white_xy(&self) -> [f64; 2] {
        Uplifter::white_xy(self)
    }

    fn map_xy<'a>(&'a self, xy: [f64; 2], scratch: &'a mut Vec<f64>) -> &'a [f64] {
        Uplifter::map_xy(self, xy, scratch)
    }
}

impl Method for Uplifter {
    fn name(&self) -> &str {
        &self.name
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        Some(self.leaf(xyz))
    }

    fn model_bytes(&self) -> usize {
        self.choose.bytes() + self.f32s.len() * 4 + std::mem::size_of_val(&self.safe_boxes[..])
    }

    /// Uplifts colours `xyz` (X, Y, Z per pixel) into `out` (`bands` values per pixel).
    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let n = self.bands;
        assert_eq!(
            xyz.len() / 3 * n,
            out.len(),
            "out must hold `bands` values per colour"
        );
        let (t, safe) = (&self.f64s[..], self.safe_f64);
        // A constant band count unrolls the multiply fully.
        if n == 36 {
            self.blocks(xyz, out, 36, t, safe, |v| v);
        } else {
            self.blocks(xyz, out, n, t, safe, |v| v);
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
        let (t, safe) = (&self.f32s[..], self.safe_f32);
        if n == 36 {
            self.blocks(xyz, out, 36, t, safe, super::hard_inputs::to_f32);
        } else {
            self.blocks(xyz, out, n, t, safe, super::hard_inputs::to_f32);
        }
    }
}

impl Uplifter {
    /// Block by block: the leaves, then r = T·c + o for ordinary colours (`t`: the leaves'
    /// maps in the output's type) and the policy of [`super::hard_inputs`] for the others, its f64
    /// result converted by `from_f64`.
    #[inline(always)]
    fn blocks<T>(
        &self,
        xyz: &[T],
        out: &mut [T],
        n: usize,
        t: &[T],
        safe: f64,
        from_f64: impl Fn(f64) -> T,
    ) where
        T: Copy + Into<f64> + std::ops::Mul<Output = T> + std::ops::Add<Output = T>,
    {
        let (mut leaves, mut xys) = ([HARD; BLOCK], [[0.0; 2]; BLOCK]);
        // The leaves of a blended colour and their weights (allocated at the first).
        let mut weights = Vec::new();
        for (xyz, out) in xyz.chunks(3 * BLOCK).zip(out.chunks_mut(n * BLOCK)) {
            self.block_leaves(xyz, safe, &mut leaves, &mut xys);
            for (((c, r), &l), &xy) in xyz
                .chunks_exact(3)
                .zip(out.chunks_exact_mut(n))
                .zip(&leaves)
                .zip(&xys)
            {
                let c = [c[0], c[1], c[2]];
                if l < BLEND {
                    kernel(&t[l as usize * 4 * n..][..4 * n], n, c, r);
                } else if l == BLEND {
                    // Σ wᵢ·(Tᵢ·c + oᵢ) straight from the leaves' maps, in the output's type.
                    let blend = self.blend.as_ref().expect("only blends mark colours BLEND");
                    blend.weights(xy, &mut weights);
                    for (k, &(leaf, w)) in weights.iter().enumerate() {
                        let m = &t[leaf as usize * 4 * n..][..4 * n];
                        kernel_weighted(m, n, c, from_f64(w), k == 0, r);
                    }
                } else {
                    let c64 = c.map(Into::into);
                    self.hard_input(c64, |b, v| r[b] = from_f64(v));
                }
            }
        }
    }
}

/// r = w·(T·c + o) when `first`, else r += w·(T·c + o): one leaf's share of a blend.
#[inline(always)]
fn kernel_weighted<T>(t: &[T], n: usize, c: [T; 3], w: T, first: bool, r: &mut [T])
where
    T: Copy + std::ops::Mul<Output = T> + std::ops::Add<Output = T>,
{
    let (tx, rest) = t.split_at(n);
    let (ty, rest) = rest.split_at(n);
    let (tz, o) = rest.split_at(n);
    let cw = c.map(|v| v * w);
    let r = &mut r[..n];
    if first {
        for b in 0..n {
            r[b] = o[b] * w + tx[b] * cw[0] + ty[b] * cw[1] + tz[b] * cw[2];
        }
    } else {
        for b in 0..n {
            r[b] = r[b] + o[b] * w + tx[b] * cw[0] + ty[b] * cw[1] + tz[b] * cw[2];
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

#[cfg(test)]
mod tests {
    use super::super::hard_inputs::{self as hard, DARK};
    use super::super::tree::{Node, Split};
    use super::*;

    /// The per-pixel path as it was before blocks and cells, kept as the reference: the tree
    /// walked node by node, then the multiply band by band, in f64.
    fn reference_f64(up: &Uplifter, tree: &Tree, xyz: &[f64]) -> Vec<f64> {
        let n = up.bands;
        let mut out = vec![0.0; xyz.len() / 3 * n];
        for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let c = [c[0], c[1], c[2]];
            match hard::ordinary_xy(c, up.safe_f64) {
                Some(xy) => {
                    let t = up.affine(tree.walk(xy));
                    for b in 0..n {
                        r[b] = t[3 * n + b] + t[b] * c[0] + t[n + b] * c[1] + t[2 * n + b] * c[2];
                    }
                }
                None => up.hard_input(c, |b, v| r[b] = v),
            }
        }
        out
    }

    /// The same in f32: the leaf chosen in f64, the multiply in f32 with T and o rounded.
    fn reference_f32(up: &Uplifter, tree: &Tree, xyz: &[f32]) -> Vec<f32> {
        let n = up.bands;
        let mut out = vec![0.0; xyz.len() / 3 * n];
        for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let c64 = [c[0] as f64, c[1] as f64, c[2] as f64];
            match hard::ordinary_xy(c64, up.safe_f32) {
                Some(xy) => {
                    let t: Vec<f32> = up.affine(tree.walk(xy)).iter().map(|&v| v as f32).collect();
                    for b in 0..n {
                        r[b] = t[3 * n + b] + t[b] * c[0] + t[n + b] * c[1] + t[2 * n + b] * c[2];
                    }
                }
                None => up.hard_input(c64, |b, v| r[b] = hard::to_f32(v)),
            }
        }
        out
    }

    /// The built-in model with its tree replaced by a chain of `splits` splits (alternating
    /// axes, values inside the locus), leaf i below split i: deep and unbalanced.
    fn chain(splits: usize) -> Model {
        let mut m = Model::builtin().clone();
        let mut rng = specconv_testkit::Lcg::new(splits as u64);
        let mut nodes = Vec::new();
        for i in 0..splits {
            let axis = if i % 2 == 0 { Axis::X } else { Axis::Y };
            let (at, leaf) = (nodes.len(), nodes.len() + 1);
            nodes.push(
                Split {
                    axis,
                    value: rng.range(0.15, 0.55),
                    below: leaf,
                    above: at + 2,
                }
                .into(),
            );
            nodes.push(Node::Leaf { leaf: i });
        }
        nodes.push(Node::Leaf { leaf: splits });
        m.tree = Tree::from(nodes);
        let leaves = Model::builtin().leaves.clone();
        m.leaves = (0..=splits)
            .map(|i| leaves[i % leaves.len()].clone())
            .collect();
        m
    }

    /// Split values of the tree and their neighbours, white, NaN, ±Inf, random xy.
    fn chromaticities(up: &Uplifter, tree: &Tree) -> Vec<[f64; 2]> {
        let mut v = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0, 1.0];
        for (_, s) in tree.splits() {
            v.extend([s.value, s.value.next_up(), s.value.next_down()]);
        }
        let mut rng = specconv_testkit::Lcg::new(7);
        let mut xy: Vec<[f64; 2]> = v
            .iter()
            .flat_map(|&a| v.iter().map(move |&b| [a, b]))
            .collect();
        xy.extend((0..20_000).map(|_| [rng.range(-0.5, 1.5), rng.range(-0.5, 1.5)]));
        xy.push(up.white_xy());
        xy
    }

    /// Colours of every kind: ordinary, negative components, xy exactly on splits, dark and
    /// near `DARK`, black and signed zeros, X+Y+Z ≤ 0, denormal, huge (near and past the
    /// overflow limits), NaN and ±Inf, and arbitrary bit patterns.
    fn colours(up: &Uplifter, tree: &Tree, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = specconv_testkit::Lcg::new(seed);
        let splits: Vec<f64> = tree.splits().map(|(_, s)| s.value).collect();
        let special = [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
        ];
        let mut out = Vec::new();
        for i in 0..40_000 {
            let c = [
                rng.range(0.0, 1.0),
                rng.range(0.0, 1.0),
                rng.range(0.0, 1.0),
            ];
            let c = match i % 12 {
                0..=3 => c,
                4 => [
                    rng.range(-1.0, 2.0),
                    rng.range(-1.0, 2.0),
                    rng.range(-1.0, 2.0),
                ],
                5 => {
                    // x (or y) exactly a split value: X+Y+Z = 1 exactly where the sum allows.
                    let v = splits[i % splits.len()];
                    let w = rng.range(0.0, 1.0 - v);
                    if i / 12 % 2 == 0 {
                        [v, w, 1.0 - v - w]
                    } else {
                        [w, v, 1.0 - v - w]
                    }
                }
                6 => c.map(|v| v * 10f64.powf(-rng.range(0.0, 320.0))),
                7 => {
                    let s = DARK * (1.0 + rng.range(-4.0, 4.0) * f64::EPSILON);
                    let t = c[0] + c[1] + c[2];
                    c.map(|v| v / t * s)
                }
                8 => [c[0], -c[1] - c[0] - rng.range(0.0, 1.0), c[2] * 0.0],
                9 => c.map(|v| v * rng.range(0.3, 3.0) * up.safe_f32),
                10 => {
                    let mut c = c.map(|v| v * 10f64.powf(rng.range(0.0, 300.0)));
                    c[i % 3] = special[rng.next_bits() as usize % special.len()];
                    c
                }
                _ => {
                    [0; 3].map(|_| f64::from_bits(rng.next_bits() << 11 | rng.next_bits() & 0x7ff))
                }
            };
            out.push(c);
        }
        out.extend(special.iter().map(|&v| [v, v, v]));
        out.extend([[0.0, -0.0, 0.0], [1e-310, 0.0, 0.0], [-1.0, 0.5, 0.5]]);
        out
    }

    fn models() -> Vec<Model> {
        vec![Model::builtin().clone(), chain(MAX_CELL_SPLITS), chain(40)]
    }

    #[test]
    fn both_leaf_choices_are_the_trees_for_every_chromaticity() {
        for model in models() {
            let up = Uplifter::new(&model).unwrap();
            let cells = matches!(up.choose, Choose::Cells { .. });
            assert_eq!(cells, model.tree.len() / 2 <= MAX_CELL_SPLITS);
            for xy in chromaticities(&up, &model.tree) {
                assert_eq!(up.leaf_xy(xy), model.tree.walk(xy), "{xy:?}");
            }
        }
    }

    /// With blending, the blocks' blended colours (Σ wᵢ·(Tᵢ·c + oᵢ) in the output's type)
    /// agree with the blended map of `map_xy`, which the hard-input policy uses, to rounding;
    /// for the leaf table (built-in model) and the walk (a chain of 40 splits).
    #[test]
    fn blended_blocks_agree_with_the_blended_map() {
        for model in [Model::builtin().clone(), chain(40)] {
            let up = Uplifter::new(&model).unwrap().with_blend(0.02).unwrap();
            let n = up.bands();
            let splits: Vec<(usize, f64)> = model
                .tree
                .splits()
                .map(|(_, s)| (s.axis.index(), s.value))
                .collect();
            let mut rng = specconv_testkit::Lcg::new(5);
            let (mut blended, mut scratch) = (0, Vec::new());
            let (mut r, mut r32) = (vec![0.0; n], vec![0.0f32; n]);
            for i in 0..20_000 {
                let (k, v) = splits[i % splits.len()];
                let mut xy = [rng.range(0.1, 0.6), rng.range(0.05, 0.6)];
                xy[k] = v + rng.range(-0.03, 0.03);
                let lum = rng.range(0.05, 1.0);
                let c = [xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]].map(|v| v * lum);
                let Some(at) = hard::ordinary_xy(c, up.safe_f64) else {
                    continue;
                };
                scratch.clear();
                let m = up.map_xy(at, &mut scratch);
                let want: Vec<f64> = (0..n)
                    .map(|b| m[3 * n + b] + m[b] * c[0] + m[n + b] * c[1] + m[2 * n + b] * c[2])
                    .collect();
                blended += !scratch.is_empty() as usize;
                up.uplift_f64(&c, &mut r);
                up.uplift_f32(&c.map(|v| v as f32), &mut r32);
                let size = want.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                for b in 0..n {
                    assert!((r[b] - want[b]).abs() <= 1e-13 * size, "{c:?}");
                    assert!((r32[b] as f64 - want[b]).abs() <= 1e-5 * size, "{c:?}");
                }
            }
            // Lines matter only inside their node's box: a fifth of the colours or more blend.
            assert!(blended > 3000, "{blended} blended");
        }
    }

    /// Bit for bit what the per-pixel path gave, in f64 and f32, for slices of any length.
    #[test]
    fn blocks_give_the_per_pixel_results_bit_for_bit() {
        for (k, model) in models().iter().enumerate() {
            let up = Uplifter::new(model).unwrap();
            let n = up.bands();
            let c64: Vec<f64> = colours(&up, &model.tree, k as u64).concat();
            let mut c32: Vec<f32> = c64.iter().map(|&v| v as f32).collect();
            // Arbitrary f32 bit patterns too: NaNs with payloads, denormals, huge values.
            let mut rng = specconv_testkit::Lcg::new(99);
            c32.extend((0..30_000).map(|_| f32::from_bits(rng.next_bits() as u32)));
            let want64 = reference_f64(&up, &model.tree, &c64);
            let want32 = reference_f32(&up, &model.tree, &c32);
            let bits64 = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let bits32 = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            // Whole slices, and pieces that start and end inside blocks.
            for piece in [usize::MAX, 1, BLOCK - 1, BLOCK + 1, 3 * BLOCK + 17] {
                let mut got64 = vec![0.0; want64.len()];
                for (c, r) in c64
                    .chunks(piece.saturating_mul(3))
                    .zip(got64.chunks_mut(piece.saturating_mul(n)))
                {
                    up.uplift_f64(c, r);
                }
                assert!(
                    bits64(&got64) == bits64(&want64),
                    "f64, model {k}, pieces of {piece}"
                );
                let mut got32 = vec![0.0; want32.len()];
                for (c, r) in c32
                    .chunks(piece.saturating_mul(3))
                    .zip(got32.chunks_mut(piece.saturating_mul(n)))
                {
                    up.uplift_f32(c, r);
                }
                assert!(
                    bits32(&got32) == bits32(&want32),
                    "f32, model {k}, pieces of {piece}"
                );
            }
        }
    }
}
