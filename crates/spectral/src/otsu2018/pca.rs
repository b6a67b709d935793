//! One cluster's PCA and its uplift matrices (Eq. 5–8), and its reconstruction error computed
//! from the scatter matrix alone, so that split search never revisits the spectra.
//!
//! Spectra may carry weights (training that does not let the largest set decide): every sum
//! below is Σ w·(…), the mean is Σ w·s / Σ w and the error Σ w·‖s − r‖². A weight is applied
//! as `w·s` before anything else is multiplied, so a weight of 1 changes no bit.

use nalgebra::{DMatrix, Matrix3, SymmetricEigen};
use specconv_colour::Colorimetry;

/// First-and-second-moment sums of a set of spectra: what PCA and the error need.
#[derive(Debug, Clone)]
pub struct Moments {
    /// Number of spectra added.
    pub count: usize,
    /// Σ w, the weights of the spectra added (their count when all weigh 1).
    pub weight: f64,
    /// Σ w·s
    pub sum: Vec<f64>,
    /// Σ w·s·sᵀ, row-major n×n.
    pub outer: Vec<f64>,
}

impl Moments {
    /// The moments of no spectra of `n` bands.
    pub fn zero(n: usize) -> Moments {
        Moments {
            count: 0,
            weight: 0.0,
            sum: vec![0.0; n],
            outer: vec![0.0; n * n],
        }
    }

    /// Adds spectrum `s` (`n` bands) with weight 1.
    pub fn add(&mut self, s: &[f64]) {
        self.add_weighted(s, 1.0);
    }

    /// Adds spectrum `s` (`n` bands) with weight `w`.
    pub fn add_weighted(&mut self, s: &[f64], w: f64) {
        let n = self.sum.len();
        self.count += 1;
        self.weight += w;
        for i in 0..n {
            let wsi = w * s[i];
            self.sum[i] += wsi;
            let row = &mut self.outer[i * n..(i + 1) * n];
            for (o, sj) in row.iter_mut().zip(s) {
                *o += wsi * sj;
            }
        }
    }

    /// `self − other`, for the far side of a split.
    pub fn minus(&self, other: &Moments) -> Moments {
        let mut out = Moments::zero(self.sum.len());
        self.minus_into(other, &mut out);
        out
    }

    /// [`Moments::minus`] into `out` (of the same size), which the split search reuses.
    pub fn minus_into(&self, other: &Moments, out: &mut Moments) {
        out.count = self.count - other.count;
        out.weight = self.weight - other.weight;
        for ((o, a), b) in out.sum.iter_mut().zip(&self.sum).zip(&other.sum) {
            *o = a - b;
        }
        for ((o, a), b) in out.outer.iter_mut().zip(&self.outer).zip(&other.outer) {
            *o = a - b;
        }
    }

    /// Σ w·‖s‖², the scale for [`check_rank`].
    pub fn energy(&self) -> f64 {
        let n = self.sum.len();
        (0..n).map(|i| self.outer[i * n + i]).sum()
    }

    /// μ = Σ w·s / Σ w (NaN when no spectra were added).
    pub fn mean(&self) -> Vec<f64> {
        self.sum.iter().map(|s| s / self.weight).collect()
    }

    /// The scatter matrix Σ w·(s − μ)(s − μ)ᵀ = Σ w·s·sᵀ − (Σ w)·μ·μᵀ.
    pub fn scatter(&self) -> Vec<f64> {
        let mut c = Vec::new();
        self.scatter_into(&mut c, &mut Vec::new());
        c
    }

    /// [`Moments::scatter`] into `c`, with `mu` as room for the mean: no allocation once
    /// they have grown.
    pub fn scatter_into(&self, c: &mut Vec<f64>, mu: &mut Vec<f64>) {
        let n = self.sum.len();
        mu.clear();
        mu.extend(self.sum.iter().map(|s| s / self.weight));
        c.resize(n * n, 0.0);
        let count = self.weight;
        let rows = c.chunks_exact_mut(n).zip(self.outer.chunks_exact(n));
        for ((row, outer), &mi) in rows.zip(mu.iter()) {
            for ((cij, &oij), &mj) in row.iter_mut().zip(outer).zip(mu.iter()) {
                *cij = oij - count * mi * mj;
            }
        }
    }
}

/// What a lower bound on a cluster's error needs, in O(n) per spectrum: the sums behind the
/// error of the best *linear* reconstruction of spectra from their XYZ. With H = C·Aᵀ and
/// G = A·C·Aᵀ, K = H·G⁻¹ minimises tr((I − K·A)·C·(I − K·A)ᵀ) over all n×3 maps K (least
/// squares of s − μ on x = A·(s − μ)), at E* = tr(C) − tr(G⁻¹·Hᵀ·H). A fit's reconstruction
/// r − μ = B·M⁻¹·A·(s − μ) is one such map (K = B·M⁻¹), so E* ≤ [`Fit::error`] for any basis:
/// the split search skips candidates whose E* already exceeds a split it has.
#[derive(Debug, Clone)]
pub struct ErrorFloor {
    /// The sums are of s − origin (and x − A·origin), which centring does not see: with the
    /// origin at the whole cluster's mean, the sums of a part cancel little when centred.
    origin: Vec<f64>,
    origin_x: [f64; 3],
    /// Σ w
    weight: f64,
    /// Σ w·s
    sum: Vec<f64>,
    /// Σ w·‖s‖²
    energy: f64,
    /// Σ w·x with x = A·s
    sum_x: [f64; 3],
    /// Σ w·x·xᵀ
    xx: [[f64; 3]; 3],
    /// Σ w·s·xᵀ, row-major n×3.
    sx: Vec<[f64; 3]>,
}

impl ErrorFloor {
    /// No spectra yet; sums taken from `origin` (any spectrum; best near the spectra's mean).
    pub fn zero(origin: &[f64], a: &Colorimetry) -> ErrorFloor {
        let n = origin.len();
        ErrorFloor {
            origin: origin.to_vec(),
            origin_x: a.xyz(origin),
            weight: 0.0,
            sum: vec![0.0; n],
            energy: 0.0,
            sum_x: [0.0; 3],
            xx: [[0.0; 3]; 3],
            sx: vec![[0.0; 3]; n],
        }
    }

    /// Adds spectrum `s` with its XYZ `x` = A·s, weight 1.
    pub fn add(&mut self, s: &[f64], x: [f64; 3]) {
        self.add_weighted(s, x, 1.0);
    }

    /// Adds spectrum `s` with its XYZ `x` = A·s and weight `w`.
    pub fn add_weighted(&mut self, s: &[f64], x: [f64; 3], w: f64) {
        self.weight += w;
        let x: [f64; 3] = std::array::from_fn(|j| x[j] - self.origin_x[j]);
        for (((m, sx), &v), &o) in self
            .sum
            .iter_mut()
            .zip(&mut self.sx)
            .zip(s)
            .zip(&self.origin)
        {
            let v = v - o;
            let wv = w * v;
            *m += wv;
            self.energy += wv * v;
            (0..3).for_each(|j| sx[j] += wv * x[j]);
        }
        for i in 0..3 {
            let wx = w * x[i];
            self.sum_x[i] += wx;
            (0..3).for_each(|j| self.xx[i][j] += wx * x[j]);
        }
    }

    /// `self − other` into `out`, for the far side of a split.
    pub fn minus_into(&self, other: &ErrorFloor, out: &mut ErrorFloor) {
        debug_assert!(self.origin == other.origin && self.origin == out.origin);
        out.weight = self.weight - other.weight;
        out.energy = self.energy - other.energy;
        for ((o, a), b) in out.sum.iter_mut().zip(&self.sum).zip(&other.sum) {
            *o = a - b;
        }
        for ((o, a), b) in out.sx.iter_mut().zip(&self.sx).zip(&other.sx) {
            *o = std::array::from_fn(|j| a[j] - b[j]);
        }
        out.sum_x = std::array::from_fn(|i| self.sum_x[i] - other.sum_x[i]);
        out.xx = std::array::from_fn(|i| std::array::from_fn(|j| self.xx[i][j] - other.xx[i][j]));
    }

    /// tr(C), the error of reconstructing every spectrum by the mean.
    pub fn variance(&self) -> f64 {
        let count = self.weight;
        self.energy - self.sum.iter().map(|s| s * s).sum::<f64>() / count
    }

    /// E*, at least 0; 0 (no bound) when the colours do not span three dimensions well enough
    /// for G⁻¹ to be computed accurately.
    /// G = A·C·Aᵀ, the scatter of the colours.
    pub fn colour_scatter(&self) -> [[f64; 3]; 3] {
        let count = self.weight;
        let mean_x = self.sum_x.map(|v| v / count);
        std::array::from_fn(|i| {
            std::array::from_fn(|j| self.xx[i][j] - count * mean_x[i] * mean_x[j])
        })
    }

    /// E*, the lower bound on [`Fit::error`] of the spectra added; 0 (no bound) when G is singular
    /// or too ill-conditioned for E* to be accurate.
    pub fn floor(&self) -> f64 {
        let count = self.weight;
        let mean_x = self.sum_x.map(|v| v / count);
        let g = self.colour_scatter();
        let g = Matrix3::from_fn(|i, j| g[i][j]);
        let Some(g_inv) = g.try_inverse() else {
            return 0.0;
        };
        // Rounding in G, relative to its size, is about ε·‖Σ x·xᵀ‖/‖G‖; G⁻¹ magnifies it by
        // G's condition. Far below 1e-8 of the floor, or no floor.
        let raw = Matrix3::from_fn(|i, j| self.xx[i][j]).norm();
        let accurate = f64::EPSILON * raw * g_inv.norm() <= 1e-10;
        if !accurate {
            return 0.0;
        }
        // HᵀH with H = Σ s·xᵀ − N·μ·x̄ᵀ, row by row.
        let mut hh = Matrix3::zeros();
        for (sx, &s) in self.sx.iter().zip(&self.sum) {
            let h: [f64; 3] = std::array::from_fn(|j| sx[j] - s * mean_x[j]);
            for i in 0..3 {
                for j in 0..3 {
                    hh[(i, j)] += h[i] * h[j];
                }
            }
        }
        let floor = self.variance() - (g_inv * hh).trace();
        if floor.is_finite() {
            floor.max(0.0)
        } else {
            0.0
        }
    }
}

/// The scatter matrix of a set of spectra computed around their mean (two passes, for accuracy).
pub fn centred_scatter(spectra: &[&[f64]]) -> (Vec<f64>, Vec<f64>) {
    weighted_scatter(spectra, |_| 1.0)
}

/// [`centred_scatter`] with spectrum k weighing `weight(k)`: the weighted mean and
/// Σ w·(s − μ)(s − μ)ᵀ.
pub fn weighted_scatter(spectra: &[&[f64]], weight: impl Fn(usize) -> f64) -> (Vec<f64>, Vec<f64>) {
    let n = spectra[0].len();
    let mut mu = vec![0.0; n];
    let mut total = 0.0;
    for (k, s) in spectra.iter().enumerate() {
        let w = weight(k);
        total += w;
        for (m, v) in mu.iter_mut().zip(*s) {
            *m += w * v;
        }
    }
    mu.iter_mut().for_each(|m| *m /= total);
    let mut c = vec![0.0; n * n];
    let mut d = vec![0.0; n];
    for (k, s) in spectra.iter().enumerate() {
        let w = weight(k);
        for i in 0..n {
            d[i] = s[i] - mu[i];
        }
        for i in 0..n {
            let wdi = w * d[i];
            for j in 0..n {
                c[i * n + j] += wdi * d[j];
            }
        }
    }
    (mu, c)
}

/// A cluster's three principal components and what the uplift needs of them.
#[derive(Debug, Clone)]
pub struct Fit {
    /// b₁, b₂, b₃: unit eigenvectors of the scatter matrix, by decreasing eigenvalue.
    pub basis: [Vec<f64>; 3],
    /// M = A·[b₁ b₂ b₃] (Eq. 6), row-major.
    pub m: [[f64; 3]; 3],
    /// M⁻¹, row-major.
    pub m_inv: [[f64; 3]; 3],
    /// σ_max(M) / σ_min(M).
    pub condition: f64,
    /// Σ ‖s − r‖² over the cluster's spectra (Eq. 13).
    pub error: f64,
}

/// Why a cluster cannot be fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unfit {
    /// M is singular or its condition number is above the bound.
    IllConditioned(f64),
    /// The spectra vary in fewer than three independent directions (the count): the missing
    /// principal components would be rounding noise, and so would the uplift along them.
    Rank(usize),
}

/// Variance below this share of the spectra's energy Σ‖s‖² is rounding, not data (an amplitude
/// of 1e-6 of the spectra; measured spectra carry three or four digits).
pub const RANK_TOL: f64 = 1e-12;

/// Checks that each basis vector carries variance bᵀ·C·b above [`RANK_TOL`]·`energy` of the
/// scatter `c` (n×n, row-major); `energy` is Σ‖s‖² of the spectra behind it.
pub fn check_rank(c: &[f64], basis: &[Vec<f64>; 3], energy: f64) -> Result<(), Unfit> {
    let n = basis[0].len();
    // bᵀ·C·b = Σᵢ bᵢ·(rowᵢ·b) for the three vectors at once: each sum in the order of one
    // vector's own, so the same bits.
    let mut variance = [-0.0; 3];
    for (i, row) in c.chunks_exact(n).enumerate() {
        let d = dots([&basis[0], &basis[1], &basis[2]], row);
        for k in 0..3 {
            variance[k] += basis[k][i] * d[k];
        }
    }
    rank(variance, energy)
}

/// [`check_rank`] with C·B given (`cb`, the tracker's): O(n).
pub fn check_rank_products(
    basis: &[Vec<f64>; 3],
    cb: &[Vec<f64>; 3],
    energy: f64,
) -> Result<(), Unfit> {
    rank(std::array::from_fn(|k| dot(&basis[k], &cb[k])), energy)
}

fn rank(variance: [f64; 3], energy: f64) -> Result<(), Unfit> {
    // By decreasing eigenvalue: the rank is the count of leading vectors above the floor.
    let floor = RANK_TOL * energy;
    match variance.iter().position(|&v| v.is_nan() || v <= floor) {
        Some(rank) => Err(Unfit::Rank(rank)),
        None => Ok(()),
    }
}

/// PCA of a cluster from its scatter matrix `c` (n×n, row-major), with its error.
pub fn fit(c: &[f64], a: &Colorimetry, max_condition: f64) -> Result<Fit, Unfit> {
    fit_basis(c, a, max_condition, top_three(c, a.bands()))
}

/// As [`fit`] with the basis given: the exact eigenvectors, or a tracker's converged estimate.
///
/// With r = B·M⁻¹·A·(s − μ) + μ, s − r = (I − B·M⁻¹·A)(s − μ) = P·(s − μ), so the summed error
/// is tr(P·C·Pᵀ) = tr(C) − 2·tr(M⁻¹·A·C·B) + tr(M⁻¹·G·M⁻ᵀ) with G = A·C·Aᵀ, using BᵀB = I:
/// a few 3×n products, no pass over the spectra. (For exact eigenvectors A·C·B = M·Λ.)
pub fn fit_basis(
    c: &[f64],
    a: &Colorimetry,
    max_condition: f64,
    basis: [Vec<f64>; 3],
) -> Result<Fit, Unfit> {
    let n = a.bands();
    let m = observed(a, &basis);
    let (condition, inv) = invert(&m, max_condition)?;
    let [b1, b2, b3] = [&basis[0][..], &basis[1][..], &basis[2][..]];
    // Rows of A·C (C is symmetric, so its rows are its columns).
    let w = [&a.weights[0][..], &a.weights[1][..], &a.weights[2][..]];
    let mut ac: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(n));
    for row in c.chunks_exact(n) {
        let d = dots(w, row);
        (0..3).for_each(|i| ac[i].push(d[i]));
    }
    let (g, acb) = (dots_3x3(w, &ac), dots_3x3([b1, b2, b3], &ac));
    let g = Matrix3::from_fn(|i, j| g[j][i]);
    let acb = Matrix3::from_fn(|i, j| acb[j][i]);
    let trace_c: f64 = (0..n).map(|i| c[i * n + i]).sum();
    Ok(fitted(basis, m, condition, inv, trace_c, &acb, &g))
}

/// As [`fit_basis`] from what the split search has at hand instead of C: `cb` = C·B (the
/// tracker's), G = A·C·Aᵀ (from colour sums, [`ErrorFloor::colour_scatter`]) and tr(C). O(n)
/// instead of O(n²); the same error up to rounding.
pub fn fit_products(
    a: &Colorimetry,
    max_condition: f64,
    basis: [Vec<f64>; 3],
    cb: &[Vec<f64>; 3],
    g: &[[f64; 3]; 3],
    trace_c: f64,
) -> Result<Fit, Unfit> {
    let m = observed(a, &basis);
    let (condition, inv) = invert(&m, max_condition)?;
    // A·C·B: column j is A·(C·b_j).
    let acb = Matrix3::from_fn(|i, j| dot(&a.weights[i], &cb[j]));
    let g = Matrix3::from_fn(|i, j| g[i][j]);
    Ok(fitted(basis, m, condition, inv, trace_c, &acb, &g))
}

/// M = A·[b₁ b₂ b₃] (Eq. 6).
fn observed(a: &Colorimetry, basis: &[Vec<f64>; 3]) -> [[f64; 3]; 3] {
    let [b1, b2, b3] = [&basis[0][..], &basis[1][..], &basis[2][..]];
    std::array::from_fn(|i| dots([b1, b2, b3], &a.weights[i]))
}

/// M's condition number and inverse, or why M is refused.
fn invert(m: &[[f64; 3]; 3], max_condition: f64) -> Result<(f64, Matrix3<f64>), Unfit> {
    let mm = Matrix3::from_fn(|i, j| m[i][j]);
    let sv = mm.singular_values();
    let (smax, smin) = (sv.max(), sv.min());
    let condition = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if condition.is_nan() || condition > max_condition {
        return Err(Unfit::IllConditioned(condition));
    }
    let inv = mm.try_inverse().ok_or(Unfit::IllConditioned(condition))?;
    Ok((condition, inv))
}

fn fitted(
    basis: [Vec<f64>; 3],
    m: [[f64; 3]; 3],
    condition: f64,
    inv: Matrix3<f64>,
    trace_c: f64,
    acb: &Matrix3<f64>,
    g: &Matrix3<f64>,
) -> Fit {
    let error = trace_c - 2.0 * (inv * acb).trace() + (inv * g * inv.transpose()).trace();
    Fit {
        basis,
        m,
        m_inv: std::array::from_fn(|i| std::array::from_fn(|j| inv[(i, j)])),
        condition,
        // Rounding can leave a perfectly fitted cluster a hair below zero.
        error: error.max(0.0),
    }
}

/// Follows the top three eigenvectors of a scatter matrix that changes a little at a time (one
/// spectrum moves across a candidate split), by block orthogonal iteration with Rayleigh–Ritz
/// started from the previous answer: a few n×n×P products instead of a full decomposition.
/// The block is wider than three (P = 6) so that the top three converge at the rate λ₇/λ₃, not
/// λ₄/λ₃. Falls back to the full decomposition when it does not converge.
#[derive(Debug, Default)]
pub struct Tracker {
    /// The block, row-major n×P: q[b·P + k] is vector k at band b.
    q: Vec<f64>,
    /// Block iterations run, for tests and benchmarks.
    pub iterations: usize,
    /// Full decompositions fallen back to, for tests and benchmarks.
    pub fallbacks: usize,
}

const P: usize = 6;

/// Three eigenvectors B and C·B.
pub type Tracked = ([Vec<f64>; 3], [Vec<f64>; 3]);

impl Tracker {
    /// Residual bound ‖C·v − θ·v‖ ≤ TOL·θ₁ on each of the top three Ritz pairs: the basis is
    /// then exact to about TOL/(relative eigengap), far below what changes a split decision.
    const TOL: f64 = 1e-10;
    const MAX_ITERATIONS: usize = 50;

    /// The top three eigenvectors B of `c` (n×n, row-major) and C·B.
    pub fn top_three(&mut self, c: &[f64], n: usize) -> Tracked {
        if n >= P && self.q.len() == n * P {
            if let Some(top) = self.iterate(c, n) {
                return top;
            }
            self.fallbacks += 1;
        }
        let v = top_eigenvectors(c, n, P.min(n));
        if n >= P {
            self.q = (0..n * P).map(|i| v[i % P][i / P]).collect();
        }
        let basis: [Vec<f64>; 3] = std::array::from_fn(|k| v[k].clone());
        let product =
            std::array::from_fn(|k| c.chunks_exact(n).map(|row| dot(row, &basis[k])).collect());
        (basis, product)
    }

    fn iterate(&mut self, c: &[f64], n: usize) -> Option<Tracked> {
        let mut z = vec![0.0; n * P];
        let (mut y, mut cy) = (vec![0.0; n * P], vec![0.0; n * P]);
        for _ in 0..Self::MAX_ITERATIONS {
            self.iterations += 1;
            // Z = C·Q, two rows at a time: twice the independent sums in flight, each summed
            // in the same order as one row alone.
            let mut rows = c.chunks_exact(n).zip(z.chunks_exact_mut(P));
            while let Some((row0, z0)) = rows.next() {
                let Some((row1, z1)) = rows.next() else {
                    let mut acc = [0.0; P];
                    for (cij, qj) in row0.iter().zip(blocks(&self.q)) {
                        for k in 0..P {
                            acc[k] += cij * qj[k];
                        }
                    }
                    z0.copy_from_slice(&acc);
                    break;
                };
                let (mut acc0, mut acc1) = ([0.0; P], [0.0; P]);
                for ((c0, c1), qj) in row0.iter().zip(row1).zip(blocks(&self.q)) {
                    for k in 0..P {
                        acc0[k] += c0 * qj[k];
                        acc1[k] += c1 * qj[k];
                    }
                }
                z0.copy_from_slice(&acc0);
                z1.copy_from_slice(&acc1);
            }
            // Rayleigh–Ritz: H = Qᵀ·C·Q, symmetrised.
            let mut hq = [[0.0; P]; P];
            for (qb, zb) in blocks(&self.q).zip(blocks(&z)) {
                for i in 0..P {
                    for j in 0..P {
                        hq[i][j] += qb[i] * zb[j];
                    }
                }
            }
            let h = std::array::from_fn(|i| std::array::from_fn(|j| (hq[i][j] + hq[j][i]) * 0.5));
            let (values, vectors) = jacobi(h);
            let mut order: [usize; P] = std::array::from_fn(|i| i);
            order.sort_by(|&i, &j| values[j].total_cmp(&values[i]));
            let w: [[f64; P]; P] =
                std::array::from_fn(|i| std::array::from_fn(|k| vectors[i][order[k]]));
            // Ritz vectors Y = Q·W and C·Y = Z·W.
            let ritz = blocks(&self.q).zip(blocks(&z));
            for ((qb, zb), (yb, cyb)) in ritz.zip(blocks_mut(&mut y).zip(blocks_mut(&mut cy))) {
                // Each sum over i in order from 0.0, the P sums side by side.
                let (mut sy, mut sz) = ([0.0; P], [0.0; P]);
                for i in 0..P {
                    for k in 0..P {
                        sy[k] += qb[i] * w[i][k];
                        sz[k] += zb[i] * w[i][k];
                    }
                }
                *yb = sy;
                *cyb = sz;
            }
            let theta: [f64; P] = std::array::from_fn(|k| values[order[k]]);
            // The three residuals' sums side by side, each in band order.
            let mut r2 = [-0.0; 3];
            for (yb, cyb) in blocks(&y).zip(blocks(&cy)) {
                for k in 0..3 {
                    r2[k] += (cyb[k] - theta[k] * yb[k]).powi(2);
                }
            }
            if r2.iter().all(|r| r.sqrt() <= Self::TOL * theta[0].abs()) {
                std::mem::swap(&mut self.q, &mut y);
                let column = |v: &[f64], k| (0..n).map(|b| v[b * P + k]).collect();
                return Some((
                    std::array::from_fn(|k| column(&self.q, k)),
                    std::array::from_fn(|k| column(&cy, k)),
                ));
            }
            std::mem::swap(&mut self.q, &mut cy);
            if !orthonormalise(&mut self.q, n) {
                return None;
            }
        }
        None
    }
}

/// Eigenvalues and eigenvectors (columns) of a small symmetric matrix by cyclic Jacobi
/// rotations. The tracker's H = Qᵀ·C·Q is nearly diagonal once Q is near the eigenvectors, where
/// Jacobi needs a sweep or two: a fifth of a general solver's work.
fn jacobi(mut a: [[f64; P]; P]) -> ([f64; P], [[f64; P]; P]) {
    let mut v: [[f64; P]; P] =
        std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64));
    let scale = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    // Off-diagonal entries below this are rounding of the diagonal ones.
    let negligible = f64::EPSILON * 1e-3 * scale;
    for _ in 0..50 {
        let mut rotated = false;
        for p in 0..P {
            for q in p + 1..P {
                let apq = a[p][q];
                if apq.abs() <= negligible || apq.is_nan() {
                    continue;
                }
                rotated = true;
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
                a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
        if !rotated {
            break;
        }
    }
    (std::array::from_fn(|i| a[i][i]), v)
}

/// The rows of a row-major n×P block, as arrays (no bounds checks within a row).
fn blocks(v: &[f64]) -> impl Iterator<Item = &[f64; P]> {
    v.chunks_exact(P).map(|r| r.try_into().expect("P columns"))
}

fn blocks_mut(v: &mut [f64]) -> impl Iterator<Item = &mut [f64; P]> {
    v.chunks_exact_mut(P)
        .map(|r| r.try_into().expect("P columns"))
}

/// Modified Gram–Schmidt on the columns of a row-major n×P block, twice for orthogonality to
/// working precision; false when they are (numerically) dependent.
fn orthonormalise(v: &mut [f64], n: usize) -> bool {
    // Column by column on a contiguous copy: the same operations in the same order.
    let mut cols = vec![0.0; n * P];
    for (b, row) in v.chunks_exact(P).enumerate() {
        for (k, &x) in row.iter().enumerate() {
            cols[k * n + b] = x;
        }
    }
    let independent = (|| {
        for _ in 0..2 {
            for k in 0..P {
                let (done, rest) = cols.split_at_mut(k * n);
                let vk = &mut rest[..n];
                for vj in done.chunks_exact(n) {
                    let d: f64 = vk.iter().zip(vj).map(|(x, y)| x * y).sum();
                    vk.iter_mut().zip(vj).for_each(|(x, y)| *x -= d * y);
                }
                let norm = vk.iter().map(|x| x.powi(2)).sum::<f64>().sqrt();
                if !(norm > 0.0 && norm.is_finite()) {
                    return false;
                }
                vk.iter_mut().for_each(|x| *x /= norm);
            }
        }
        true
    })();
    for (b, row) in v.chunks_exact_mut(P).enumerate() {
        for (k, x) in row.iter_mut().enumerate() {
            *x = cols[k * n + b];
        }
    }
    independent
}

/// The eigenvectors of the three largest eigenvalues of a symmetric matrix, signs fixed so
/// that each vector's largest-magnitude component is positive (PCA leaves the sign free; a
/// model must not).
pub(crate) fn top_three(c: &[f64], n: usize) -> [Vec<f64>; 3] {
    let mut v = top_eigenvectors(c, n, 3).into_iter();
    std::array::from_fn(|_| v.next().expect("three eigenvectors"))
}

/// The eigenvectors of the `k` largest eigenvalues, by decreasing eigenvalue, signs fixed.
fn top_eigenvectors(c: &[f64], n: usize, k: usize) -> Vec<Vec<f64>> {
    let eig = SymmetricEigen::new(DMatrix::from_row_slice(n, n, c));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| {
        eig.eigenvalues[j]
            .total_cmp(&eig.eigenvalues[i])
            .then(i.cmp(&j))
    });
    order[..k]
        .iter()
        .map(|&col| {
            let mut v: Vec<f64> = eig.eigenvectors.column(col).iter().copied().collect();
            let peak = v
                .iter()
                .copied()
                .fold(0.0f64, |p, x| if x.abs() > p.abs() { x } else { p });
            if peak < 0.0 {
                v.iter_mut().for_each(|x| *x = -*x);
            }
            v
        })
        .collect()
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `[dot(rows[0], v), …]` in one pass: the sums run side by side (no wait on one another), each
/// from −0.0 in index order as `Iterator::sum` adds, so each is [`dot`] bit for bit.
#[inline]
fn dots<const R: usize>(rows: [&[f64]; R], v: &[f64]) -> [f64; R] {
    let mut acc = [-0.0; R];
    // Rows cut to v's length up front: no bounds check in the loop.
    let rows = rows.map(|r| &r[..v.len()]);
    for (i, &vi) in v.iter().enumerate() {
        for r in 0..R {
            acc[r] += rows[r][i] * vi;
        }
    }
    acc
}

/// `d[j][i] = dot(rows[j], vs[i])`, as [`dots`].
fn dots_3x3(rows: [&[f64]; 3], vs: &[Vec<f64>; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|j| {
        let d = std::array::from_fn(|i| vs[i].as_slice());
        dots(d, rows[j])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Grid, Illuminant, Observer};

    fn colorimetry() -> Colorimetry {
        Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap()
    }

    /// Smooth pseudo-random spectra, reproducible without a random-number crate.
    fn spectra(count: usize, n: usize) -> Vec<Vec<f64>> {
        (0..count)
            .map(|k| {
                let (a, b, c) = (
                    (k as f64 * 0.37).sin(),
                    (k as f64 * 1.13).cos(),
                    (k as f64 * 0.71).sin(),
                );
                (0..n)
                    .map(|i| {
                        let t = i as f64 / n as f64;
                        0.5 + 0.2 * a * t
                            + 0.15 * b * (3.0 * t).sin()
                            + 0.1 * c * (7.0 * t).cos()
                            + 0.02 * (k as f64 * i as f64).sin()
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn error_from_scatter_equals_error_from_the_spectra() {
        let a = colorimetry();
        let data = spectra(50, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let (mu, c) = centred_scatter(&refs);
        let f = fit(&c, &a, 1e12).unwrap();
        let c_mu = a.xyz(&mu);
        let mut direct = 0.0;
        for s in &data {
            let cs = a.xyz(s);
            let d = [cs[0] - c_mu[0], cs[1] - c_mu[1], cs[2] - c_mu[2]];
            let w: Vec<f64> = (0..3).map(|i| dot(&f.m_inv[i], &d)).collect();
            for (i, si) in s.iter().enumerate() {
                let r = mu[i] + (0..3).map(|k| w[k] * f.basis[k][i]).sum::<f64>();
                direct += (si - r).powi(2);
            }
        }
        assert!(
            direct > 1e-3,
            "the test data must not be trivially reconstructible"
        );
        assert!(
            (f.error - direct).abs() < 1e-10 * direct,
            "{} vs {direct}",
            f.error
        );
    }

    #[test]
    fn moments_give_the_same_scatter_as_two_passes() {
        let data = spectra(30, 36);
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let (_, c2) = centred_scatter(&refs);
        let mut m = Moments::zero(36);
        data.iter().for_each(|s| m.add(s));
        let c1 = m.scatter();
        let worst = c1
            .iter()
            .zip(&c2)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn basis_is_orthonormal_with_fixed_signs() {
        let a = colorimetry();
        let data = spectra(40, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let f = fit(&centred_scatter(&refs).1, &a, 1e12).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let d = dot(&f.basis[i], &f.basis[j]);
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
            let peak =
                f.basis[i]
                    .iter()
                    .copied()
                    .fold(0.0f64, |p, x| if x.abs() > p.abs() { x } else { p });
            assert!(peak > 0.0);
        }
    }

    /// The error of regressing the centred spectra on their centred XYZ, solved directly by
    /// nalgebra's SVD least squares over the spectra (not from the sums).
    fn regression_error(data: &[Vec<f64>], a: &Colorimetry) -> f64 {
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let (mu, _) = centred_scatter(&refs);
        let (rows, n) = (data.len(), a.bands());
        let s = DMatrix::from_fn(rows, n, |r, b| data[r][b] - mu[b]);
        let x = DMatrix::from_fn(rows, 3, |r, i| {
            dot(&a.weights[i], &data[r]) - dot(&a.weights[i], &mu)
        });
        let k = x.clone().svd(true, true).solve(&s, 1e-14).unwrap();
        (s - x * k).norm_squared()
    }

    fn floor_of(data: &[Vec<f64>], a: &Colorimetry) -> ErrorFloor {
        let mut f = ErrorFloor::zero(&data[data.len() / 2], a);
        data.iter().for_each(|s| f.add(s, a.xyz(s)));
        f
    }

    #[test]
    fn the_floor_is_the_least_squares_error_of_reconstructing_spectra_from_xyz() {
        let a = colorimetry();
        let data = spectra(150, a.bands());
        let (direct, floor) = (regression_error(&data, &a), floor_of(&data, &a).floor());
        assert!(direct > 1e-3, "{direct}");
        assert!(
            (floor - direct).abs() <= 1e-9 * direct,
            "{floor} against {direct}"
        );
        // The far side of a split, by subtraction, is the rest's own floor.
        let mut rest = ErrorFloor::zero(&data[75], &a);
        let mut part = ErrorFloor::zero(&data[75], &a);
        data[..60].iter().for_each(|s| part.add(s, a.xyz(s)));
        floor_of(&data, &a).minus_into(&part, &mut rest);
        let direct = regression_error(&data[60..], &a);
        assert!((rest.floor() - direct).abs() <= 1e-9 * direct);
    }

    #[test]
    fn the_floor_is_below_every_fits_error_on_both_sides_of_every_split() {
        let a = colorimetry();
        let data = spectra(120, a.bands());
        let whole = floor_of(&data, &a);
        let mut far = ErrorFloor::zero(&data[60], &a);
        let mut closest = f64::INFINITY;
        for k in 8..data.len() - 8 {
            let mut near = ErrorFloor::zero(&data[60], &a);
            data[..k].iter().for_each(|s| near.add(s, a.xyz(s)));
            whole.minus_into(&near, &mut far);
            for (side, floor) in [(&data[..k], near.floor()), (&data[k..], far.floor())] {
                let refs: Vec<&[f64]> = side.iter().map(|s| s.as_slice()).collect();
                let error = fit(&centred_scatter(&refs).1, &a, f64::INFINITY)
                    .unwrap()
                    .error;
                assert!(
                    floor > 0.0 && floor <= error,
                    "split {k}: floor {floor}, error {error}"
                );
                closest = closest.min(error / floor);
            }
        }
        // A bound, not the error itself: PCA does not choose its basis for the observer.
        assert!(closest > 1.0 + 1e-6, "{closest}");
    }

    #[test]
    fn colours_in_fewer_than_three_dimensions_give_no_floor() {
        let a = colorimetry();
        let data: Vec<Vec<f64>> = (0..10)
            .map(|k| vec![0.1 + 0.05 * k as f64; a.bands()])
            .collect();
        assert_eq!(floor_of(&data, &a).floor(), 0.0);
    }

    #[test]
    fn jacobi_agrees_with_nalgebras_symmetric_eigen() {
        // A full matrix and a nearly diagonal one (the tracker's usual H), eigenvalues spread
        // over six orders of magnitude as a scatter's are.
        for offdiagonal in [1.0, 1e-4] {
            let h: [[f64; P]; P] = std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    let d = if i == j { 10f64.powi(-(i as i32)) } else { 0.0 };
                    d + offdiagonal * 1e-3 * ((i * j + i + j) as f64 * 0.9).sin()
                })
            });
            let (values, vectors) = jacobi(h);
            let m = nalgebra::SMatrix::<f64, P, P>::from_fn(|i, j| h[i][j]);
            let eig = SymmetricEigen::new(m);
            for k in 0..P {
                // Each Jacobi pair is an eigenpair: ‖H·v − λ·v‖ at rounding, λ among nalgebra's.
                let residual: f64 = (0..P)
                    .map(|i| {
                        let hv: f64 = (0..P).map(|j| h[i][j] * vectors[j][k]).sum();
                        (hv - values[k] * vectors[i][k]).powi(2)
                    })
                    .sum::<f64>()
                    .sqrt();
                assert!(residual < 1e-14, "{residual}");
                let nearest = eig
                    .eigenvalues
                    .iter()
                    .map(|e| (e - values[k]).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest < 1e-14, "{} off by {nearest}", values[k]);
            }
        }
    }

    #[test]
    fn tracker_follows_the_exact_subspace_as_spectra_are_added() {
        let data = spectra(120, 36);
        let mut m = Moments::zero(36);
        let mut tracker = Tracker::default();
        for (k, s) in data.iter().enumerate() {
            m.add(s);
            if k < 10 {
                continue;
            }
            let c = m.scatter();
            let tracked = tracker.top_three(&c, 36).0;
            let exact = top_three(&c, 36);
            // Same subspace: the projectors B·Bᵀ agree.
            for i in 0..36 {
                for j in 0..36 {
                    let p = |b: &[Vec<f64>; 3]| (0..3).map(|k| b[k][i] * b[k][j]).sum::<f64>();
                    assert!((p(&tracked) - p(&exact)).abs() < 1e-7, "step {k}");
                }
            }
        }
        assert_eq!(tracker.fallbacks, 0);
        assert!(
            tracker.iterations < 10 * 110,
            "{} iterations",
            tracker.iterations
        );
    }

    #[test]
    fn an_ill_conditioned_cluster_is_refused() {
        let a = colorimetry();
        let data = spectra(40, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let c = centred_scatter(&refs).1;
        let cond = fit(&c, &a, 1e12).unwrap().condition;
        assert_eq!(
            fit(&c, &a, cond * 0.5).unwrap_err(),
            Unfit::IllConditioned(cond)
        );
    }
}
