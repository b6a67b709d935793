//! Meng, Simon, Hanika and Dachsbacher, "Physically Meaningful Rendering using Tristimulus
//! Colours" (CGF 34(4), 2015): the smoothest spectrum with the given colour,
//!
//! ```text
//! minimise ‖D·r‖²  subject to  A·r = c            (their Eq. 4, D: first differences)
//! ```
//!
//! and their bounded variant that adds 0 ≤ r ≤ 1.
//!
//! Without bounds the problem is an equality-constrained least squares whose KKT system
//! [DᵀD Aᵀ; A 0]·[r; λ] = [0; c] is linear in c, so r = T·c with T (n×3) solved once: one small
//! matrix multiply per colour, like the clustered PCA. With bounds it is a convex quadratic
//! programme solved per colour by a primal–dual active-set iteration (Hintermüller, Ito and
//! Kunisch, SIAM J. Optim. 13(3), 2002); the free bands of each iterate solve a tridiagonal system
//! (DᵀD restricted to them), so an iteration costs O(n). A colour that no reflectance in [0, 1]
//! can have (outside the object-colour solid) keeps the unbounded solution: values in [0, 1]
//! "where it can", an exact colour always.

// Band loops index several arrays in step.
#![allow(clippy::needless_range_loop)]

use crate::error::Error;

use crate::Method;
use nalgebra::DMatrix;
use specconv_colour::{Colorimetry, Grid};

/// Meng et al. 2015 on a colorimetry's grid: the smoothest spectrum with the colour (see the
/// module), unbounded or with 0 ≤ r ≤ 1.
#[derive(Debug, Clone)]
pub struct Meng2015 {
    grid: Grid,
    bands: usize,
    bounded: bool,
    /// The upper bound of the bounded variant: 1, or +∞ for colour-science's 0 ≤ r.
    upper: f64,
    /// Columns T·x̂, T·ŷ, T·ẑ, each `bands` long.
    t: Vec<f64>,
    t32: Vec<f32>,
    /// Rows of A, for the bounded solve.
    a: [Vec<f64>; 3],
}

impl Meng2015 {
    /// The method for colorimetry `a`, `bounded` adding 0 ≤ r ≤ 1 (`meng2015-bounded`). Needs at
    /// least 4 bands ([`Error::Grid`]).
    pub fn new(a: &Colorimetry, bounded: bool) -> Result<Meng2015, Error> {
        Meng2015::with_upper_bound(a, bounded, 1.0)
    }

    /// As `new`, with another upper bound for the bounded variant (+∞: only r ≥ 0, as
    /// colour-science's implementation).
    pub fn with_upper_bound(a: &Colorimetry, bounded: bool, upper: f64) -> Result<Meng2015, Error> {
        let n = a.bands();
        if n < 4 {
            return Err(Error::Grid(format!(
                "{}: meng2015 needs at least 4 bands to have a smoothest spectrum",
                a.grid
            )));
        }
        let mut k = DMatrix::<f64>::zeros(n + 3, n + 3);
        for i in 0..n {
            // DᵀD of first differences: the path-graph Laplacian.
            let deg = if i == 0 || i == n - 1 { 1.0 } else { 2.0 };
            k[(i, i)] = deg;
            if i + 1 < n {
                k[(i, i + 1)] = -1.0;
                k[(i + 1, i)] = -1.0;
            }
            for row in 0..3 {
                k[(n + row, i)] = a.weights[row][i];
                k[(i, n + row)] = a.weights[row][i];
            }
        }
        let mut rhs = DMatrix::<f64>::zeros(n + 3, 3);
        for col in 0..3 {
            rhs[(n + col, col)] = 1.0;
        }
        let sol = k.lu().solve(&rhs).ok_or_else(|| {
            Error::Grid(format!(
                "{}: the colour-matching functions on this grid do not fix a smoothest spectrum",
                a.grid
            ))
        })?;
        let mut t = vec![0.0; 3 * n];
        for col in 0..3 {
            for b in 0..n {
                t[col * n + b] = sol[(b, col)];
            }
        }
        Ok(Meng2015 {
            grid: a.grid,
            bands: n,
            bounded,
            upper,
            t32: t.iter().map(|&v| v as f32).collect(),
            t,
            a: a.weights.clone(),
        })
    }

    /// The unbounded solution r = T·c.
    #[inline]
    fn unbounded(&self, c: [f64; 3], r: &mut [f64]) {
        let n = self.bands;
        let (tx, rest) = self.t.split_at(n);
        let (ty, tz) = rest.split_at(n);
        for b in 0..n {
            r[b] = tx[b] * c[0] + ty[b] * c[1] + tz[b] * c[2];
        }
    }

    /// The bounded solution, or `false` (r untouched beyond scratch use) when the active-set
    /// iteration finds no solution inside [0, 1].
    fn bounded_into(&self, c: [f64; 3], r: &mut [f64], s: &mut Scratch) -> bool {
        let n = self.bands;
        // 0: free, 1: at 0, 2: at 1. Start from the unbounded solution's violations.
        s.state.clear();
        s.state.extend(r.iter().map(|&v| {
            if v < 0.0 {
                1u8
            } else if v > self.upper {
                2
            } else {
                0
            }
        }));
        for _ in 0..4 * n {
            if !self.solve_with_fixed(c, r, s) {
                return false;
            }
            // g = DᵀD·r + Aᵀ·λ: the bound multipliers are g (at 0) and −g (at 1).
            let mut changed = false;
            for i in 0..n {
                let lap = if n == 1 {
                    0.0
                } else if i == 0 {
                    r[0] - r[1]
                } else if i == n - 1 {
                    r[i] - r[i - 1]
                } else {
                    2.0 * r[i] - r[i - 1] - r[i + 1]
                };
                let g = lap + (0..3).map(|k| self.a[k][i] * s.lambda[k]).sum::<f64>();
                let eps = 1e-12;
                let next = match s.state[i] {
                    1 if g < -eps => 0,
                    2 if g > eps => 0,
                    0 if r[i] < -eps => 1,
                    0 if r[i] > self.upper + eps => 2,
                    st => st,
                };
                if next != s.state[i] {
                    s.state[i] = next;
                    changed = true;
                }
            }
            if !changed {
                return true;
            }
        }
        false
    }

    /// Solves min ½‖D·r‖² with the fixed bands at their bounds and A·r = c, by the Schur
    /// complement over the free bands' tridiagonal block H_FF: λ from
    /// (A_F·H_FF⁻¹·A_Fᵀ)·λ = A_F·H_FF⁻¹·b_F − c′, then r_F = H_FF⁻¹·(b_F − A_Fᵀ·λ).
    fn solve_with_fixed(&self, c: [f64; 3], r: &mut [f64], s: &mut Scratch) -> bool {
        let n = self.bands;
        s.free.clear();
        s.free.extend((0..n).filter(|&i| s.state[i] == 0));
        let m = s.free.len();
        if m < 3 || m == n {
            // Fewer free bands than constraints (or none fixed: the unbounded case, done already).
            return false;
        }
        for i in 0..n {
            match s.state[i] {
                1 => r[i] = 0.0,
                2 => r[i] = self.upper,
                _ => {}
            }
        }
        // c′ = c − A_fixed·r_fixed; b_F = −H_F,fixed·r_fixed (neighbours at 1 pull up).
        let mut cp = c;
        for i in 0..n {
            if s.state[i] == 2 {
                for k in 0..3 {
                    cp[k] -= self.a[k][i] * self.upper;
                }
            }
        }
        s.diag.clear();
        s.off.clear();
        s.rhs.clear();
        for (p, &i) in s.free.iter().enumerate() {
            let deg = if i == 0 || i == n - 1 { 1.0 } else { 2.0 };
            s.diag.push(deg);
            // Coupling to the previous free band only when they are neighbours.
            s.off.push(if p > 0 && s.free[p - 1] + 1 == i {
                -1.0
            } else {
                0.0
            });
            let mut b = 0.0;
            if i > 0 && s.state[i - 1] == 2 {
                b += self.upper;
            }
            if i + 1 < n && s.state[i + 1] == 2 {
                b += self.upper;
            }
            s.rhs.push(b);
        }
        // Four right-hand sides: b_F and the three columns A_Fᵀ.
        s.cols.clear();
        s.cols.extend_from_slice(&s.rhs);
        for k in 0..3 {
            s.cols.extend(s.free.iter().map(|&i| self.a[k][i]));
        }
        if !thomas(&s.diag, &s.off, &mut s.cols, m, &mut s.work) {
            return false;
        }
        let (hb, hat) = s.cols.split_at(m);
        // S = A_F·H⁻¹·A_Fᵀ (3×3), v = A_F·H⁻¹·b_F − c′.
        let mut sm = [[0.0; 3]; 3];
        let mut v = [0.0; 3];
        for k in 0..3 {
            for (p, &i) in s.free.iter().enumerate() {
                let ak = self.a[k][i];
                v[k] += ak * hb[p];
                for j in 0..3 {
                    sm[k][j] += ak * hat[j * m + p];
                }
            }
            v[k] -= cp[k];
        }
        let inv = specconv_colour::mat3::inverse(&sm);
        let lambda = specconv_colour::mat3::mul_vec(&inv, v);
        if !lambda.iter().all(|l| l.is_finite()) {
            return false;
        }
        s.lambda = lambda;
        for (p, &i) in s.free.iter().enumerate() {
            r[i] = hb[p] - (0..3).map(|j| hat[j * m + p] * lambda[j]).sum::<f64>();
        }
        true
    }
}

/// Solves a symmetric tridiagonal system (diagonal `d`, sub-diagonal `e` with e[0] unused) for
/// the `cols.len() / m` right-hand sides stored one after another in `cols`, in place.
fn thomas(d: &[f64], e: &[f64], cols: &mut [f64], m: usize, w: &mut Vec<f64>) -> bool {
    // Factor once: modified diagonal w.
    w.clear();
    w.push(d[0]);
    for p in 1..m {
        let prev = w[p - 1];
        if prev.abs() < 1e-300 {
            return false;
        }
        w.push(d[p] - e[p] * e[p] / prev);
    }
    if w[m - 1].abs() < 1e-12 {
        // A free run touching both ends with nothing fixed is singular (constants); guarded by
        // the caller, but a near-zero pivot is treated the same way.
        return false;
    }
    for col in cols.chunks_exact_mut(m) {
        for p in 1..m {
            col[p] -= e[p] / w[p - 1] * col[p - 1];
        }
        col[m - 1] /= w[m - 1];
        for p in (0..m - 1).rev() {
            col[p] = (col[p] - e[p + 1] * col[p + 1]) / w[p];
        }
    }
    true
}

/// Per-thread scratch space of the bounded solve.
#[derive(Debug, Default)]
struct Scratch {
    state: Vec<u8>,
    free: Vec<usize>,
    diag: Vec<f64>,
    off: Vec<f64>,
    rhs: Vec<f64>,
    cols: Vec<f64>,
    work: Vec<f64>,
    lambda: [f64; 3],
    keep: Vec<f64>,
}

impl Method for Meng2015 {
    fn name(&self) -> &str {
        if self.bounded {
            "meng2015-bounded"
        } else {
            "meng2015"
        }
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn model_bytes(&self) -> usize {
        // T, plus A for the bounded solve.
        let n = self.bands;
        (if self.bounded { 6 * n } else { 3 * n }) * std::mem::size_of::<f32>()
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let n = self.bands;
        let mut s = Scratch::default();
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            let c = [c[0], c[1], c[2]];
            self.unbounded(c, r);
            if self.bounded
                && c.iter().all(|v| v.is_finite())
                && r.iter().any(|v| !(0.0..=self.upper).contains(v))
            {
                s.keep.clear();
                s.keep.extend_from_slice(r);
                if !self.bounded_into(c, r, &mut s) {
                    r.copy_from_slice(&s.keep);
                }
            }
        }
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        let n = self.bands;
        if self.bounded {
            // The active-set solve runs in f64.
            let mut c64 = [0.0; 3];
            let mut r64 = vec![0.0; n];
            for (c, r) in crate::method::per_colour(xyz, out, n) {
                for k in 0..3 {
                    c64[k] = c[k] as f64;
                }
                self.uplift_f64(&c64, &mut r64);
                for (o, v) in r.iter_mut().zip(&r64) {
                    *o = *v as f32;
                }
            }
            return;
        }
        let (tx, rest) = self.t32.split_at(n);
        let (ty, tz) = rest.split_at(n);
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            for b in 0..n {
                r[b] = tx[b] * c[0] + ty[b] * c[1] + tz[b] * c[2];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Illuminant, Observer};

    fn setup() -> (Colorimetry, Meng2015, Meng2015) {
        let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
        let m = Meng2015::new(&a, false).unwrap();
        let b = Meng2015::new(&a, true).unwrap();
        (a, m, b)
    }

    #[test]
    fn unbounded_round_trips_and_white_is_flat() {
        let (a, m, _) = setup();
        let mut r = vec![0.0; a.bands()];
        m.uplift_f64(&a.white_xyz(), &mut r);
        // A flat spectrum has zero roughness and the white's colour: it is the minimiser.
        assert!(r.iter().all(|v| (v - 1.0).abs() < 1e-9), "{r:?}");
        let c = [0.2, 0.1, 0.6];
        m.uplift_f64(&c, &mut r);
        let back = a.xyz(&r);
        assert!((0..3).all(|k| (back[k] - c[k]).abs() < 1e-13), "{back:?}");
    }

    /// KKT conditions of the bounded problem: feasibility, the colour, and multipliers of the
    /// right sign on the bounds. For a convex QP they certify the optimum.
    #[test]
    fn bounded_satisfies_the_kkt_conditions() {
        let (a, m, b) = setup();
        let n = a.bands();
        let mut hits = 0;
        // Colours of smooth-ish spectra in [0, 1]: feasible by construction.
        for k in 0..200 {
            let f = k as f64 / 200.0;
            let s: Vec<f64> = (0..n)
                .map(|i| {
                    let x = i as f64 / (n - 1) as f64;
                    let v = 0.5 + 0.5 * ((7.0 * f + 1.0) * x * 6.0 + 13.0 * f).sin();
                    if (x - f).abs() < 0.15 {
                        v
                    } else {
                        v * 0.05
                    }
                })
                .collect();
            let c = a.xyz(&s);
            let mut ru = vec![0.0; n];
            m.uplift_f64(&c, &mut ru);
            let mut r = vec![0.0; n];
            b.uplift_f64(&c, &mut r);
            let back = a.xyz(&r);
            assert!(
                (0..3).all(|k| (back[k] - c[k]).abs() < 1e-10),
                "{back:?} {c:?}"
            );
            assert!(
                r.iter().all(|v| (-1e-12..=1.0 + 1e-12).contains(v)),
                "{r:?}"
            );
            if ru.iter().any(|v| !(0.0..=1.0).contains(v)) {
                hits += 1;
                let mut sc = Scratch::default();
                let mut r2 = ru.clone();
                assert!(b.bounded_into(c, &mut r2, &mut sc));
                for i in 0..n {
                    let lap = if i == 0 {
                        r2[0] - r2[1]
                    } else if i == n - 1 {
                        r2[i] - r2[i - 1]
                    } else {
                        2.0 * r2[i] - r2[i - 1] - r2[i + 1]
                    };
                    let g = lap + (0..3).map(|k| a.weights[k][i] * sc.lambda[k]).sum::<f64>();
                    match sc.state[i] {
                        0 => assert!(g.abs() < 1e-9, "stationarity {g}"),
                        1 => assert!(g >= -1e-12, "lower multiplier {g}"),
                        _ => assert!(g <= 1e-12, "upper multiplier {g}"),
                    }
                }
            }
        }
        assert!(hits > 20, "the test must exercise active bounds ({hits})");
    }

    #[test]
    fn impossible_colours_keep_the_exact_unbounded_solution() {
        let (a, m, b) = setup();
        let n = a.bands();
        // Twice the white: no reflectance in [0, 1] has it.
        let w = a.white_xyz().map(|v| 2.0 * v);
        let (mut r, mut ru) = (vec![0.0; n], vec![0.0; n]);
        b.uplift_f64(&w, &mut r);
        m.uplift_f64(&w, &mut ru);
        assert_eq!(r, ru);
    }
}
