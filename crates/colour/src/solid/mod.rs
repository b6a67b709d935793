//! The object-colour solid Z = {A·r : 0 ≤ r ≤ 1} of a colorimetry (a zonotope whose generators
//! are A's columns, one per band), and the exact solver that both of [`Bounded`]'s problems
//! reduce to.
//!
//! Both problems are min over 0 ≤ r ≤ 1 of ½‖B·r − s‖² + (μ/2)‖r − p‖² with B 3×n, or its
//! limit μ = 0 with the constraint B·r = s (the projection). Their dual lives in w ∈ R³: the
//! minimiser for given w is r(w) = clip(p + Bᵀw, 0, 1), and w minimises the convex
//!
//!   Ψ(w) = Σᵢ ψ(pᵢ + bᵢ·w) − s·w + (μ/2)‖w‖²,   ψ(z) = ∫₀ᶻ clip(t, 0, 1) dt,
//!
//! whose gradient B·r(w) − s + μw is the constraint residual. Ψ is piecewise quadratic: on the
//! set of w with the same active bands (rᵢ at 0 or 1) it is a quadratic with Hessian
//! B_F·B_Fᵀ + μI over the free bands F, so a Newton step (three unknowns) lands on the solution
//! once the active set is the right one, and a backtracking line search on Ψ gets it there
//! (a semismooth Newton method, which is an active-set method in three dual unknowns). The
//! result satisfies the KKT conditions to rounding: r is in [0, 1] and clip-optimal by
//! construction, and the residual is below 1e-13 relative.
//!
//! [`Bounded`]: ../../specconv_spectral/bounded/struct.Bounded.html

use crate::mat3::{self, dot};

pub mod nearest;

/// The solid's generators and what is precomputed of them.
#[derive(Debug, Clone)]
pub struct Solid {
    /// A's columns: the XYZ of a unit reflectance in each band.
    cols: Vec<[f64; 3]>,
    /// h(+eₖ) and h(−eₖ), the support of Z along the axes: certificates for free.
    axis_support: [[f64; 3]; 2],
    /// trace(A·Aᵀ): the scale of the dual Hessian, for its regularisation.
    trace: f64,
}

/// The result of [`Solid::project`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solve {
    /// `r` holds the solution; A·r = c to rounding.
    Solved,
    /// No r in [0, 1] has A·r = c: u with u·c > Σᵢ max(0, (Aᵀu)ᵢ).
    Outside([f64; 3]),
    /// Neither within the iterations allowed: c lies on the solid's surface to rounding.
    Unresolved,
}

/// Dual iterations before a colour is declared unresolved (on the solid's surface).
pub const DUAL_STEPS: usize = 60;

/// The dual solves' numbers, which the C header's encoder shares (it is generated from them,
/// `specconv_spectral::c_header`): the residual that is converged, relative to the largest
/// component of the target colour…
pub const RESIDUAL: f64 = 1e-13;
/// …and the residual a stalled solve may still end with and count as solved.
pub const STALLED_RESIDUAL: f64 = 1e-9;
/// The Hessian's regularisation, relative to trace(A·Aᵀ), of a projection's step where fewer
/// than three bands are free.
pub const HESSIAN_FLOOR: f64 = 1e-12;
/// A line search halves while the step still moves w by more than this, relative to w.
pub const STEP_FLOOR: f64 = 1e-15;
/// The rounding allowed in Ψ's comparison, relative to |Ψ| (a sum of n terms).
pub const PSI_ROUNDING: f64 = 1e-15;
/// The sufficient decrease (Armijo) a step must make, of its slope.
pub const ARMIJO: f64 = 1e-4;
/// The halvings of a polishing step's length before it gives up.
pub const POLISH_HALVINGS: usize = 40;
/// The stronger penalties a stalled regularised solve restarts from: 10^k times as strong, k
/// from this down to 1.
pub const STRONGER_PENALTIES: i32 = 8;

/// Bands up to which scratch spectra live on the stack.
const STACK_BANDS: usize = 128;

impl Solid {
    /// The solid of the colorimetry whose rows of A are `a`.
    pub fn new(a: &[Vec<f64>; 3]) -> Solid {
        let cols: Vec<[f64; 3]> = (0..a[0].len())
            .map(|i| [a[0][i], a[1][i], a[2][i]])
            .collect();
        let mut axis_support = [[0.0; 3]; 2];
        for col in &cols {
            for k in 0..3 {
                axis_support[0][k] += col[k].max(0.0);
                axis_support[1][k] += (-col[k]).max(0.0);
            }
        }
        let trace = cols.iter().map(|c| dot(*c, *c)).sum();
        Solid {
            cols,
            axis_support,
            trace,
        }
    }

    /// The number of bands: A's columns, the length of a reflectance.
    pub fn bands(&self) -> usize {
        self.cols.len()
    }

    /// A's columns.
    pub fn columns(&self) -> &[[f64; 3]] {
        &self.cols
    }

    /// XYZ of a reflectance: A·r.
    pub fn xyz(&self, r: &[f64]) -> [f64; 3] {
        let mut x = [0.0; 3];
        for (col, v) in self.cols.iter().zip(r) {
            for k in 0..3 {
                x[k] += col[k] * v;
            }
        }
        x
    }

    /// The support function h(u) = max over the solid of u·x = Σᵢ max(0, aᵢ·u).
    pub fn support(&self, u: [f64; 3]) -> f64 {
        self.cols.iter().map(|c| dot(*c, u).max(0.0)).sum()
    }

    /// Whether u certifies that c is outside the solid: u·c > h(u) + tol, u scaled to ‖u‖₁ = 1.
    pub fn certifies(&self, c: [f64; 3], u: [f64; 3], tol: f64) -> bool {
        let norm = u[0].abs() + u[1].abs() + u[2].abs();
        if !(norm > 0.0 && norm.is_finite()) {
            return false;
        }
        let u = u.map(|v| v / norm);
        dot(u, c) > self.support(u) + tol
    }

    /// min ½‖r − r0‖² subject to A·r = c and 0 ≤ r ≤ 1, into `r` (see the module).
    pub fn project(&self, c: [f64; 3], r0: &[f64], r: &mut [f64]) -> Solve {
        self.project_within(c, r0, r, DUAL_STEPS)
    }

    /// [`Solid::project`] with at most `iterations` Newton steps.
    pub fn project_within(
        &self,
        c: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        iterations: usize,
    ) -> Solve {
        self.project_dual(c, r0, r, iterations).0
    }

    /// min ½‖r − r0‖² + ‖A·r − c‖²/(2μ) over 0 ≤ r ≤ 1, μ = `mu`·trace(A·Aᵀ), into `r`, with
    /// its dual w = (c − A·r)/μ: the projection with the colour's constraint made a penalty.
    /// Every c has a solution, unique and Lipschitz in c and r0 (the dual's Hessian is at
    /// least μ), where the exact projection's w grows without bound as c nears the surface and
    /// its spectrum with it (docs/hard-inputs.md, "Continuity near the surface of the solid").
    pub fn project_regularised(
        &self,
        c: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        mu: f64,
        iterations: usize,
    ) -> (Solve, [f64; 3]) {
        let scale = c[0]
            .abs()
            .max(c[1].abs())
            .max(c[2].abs())
            .max(f64::MIN_POSITIVE);
        let tol = RESIDUAL * scale;
        let solve = |mu: f64, w: &mut [f64; 3], r: &mut [f64]| {
            let problem = Dual {
                cols: &self.cols,
                p: r0,
                s: c,
                mu: mu * self.trace,
                eps: 0.0,
            };
            match problem.minimise(w, r, tol, iterations, |_, _, _, _| false) {
                End::Converged => 0.0,
                // Ψ's terms grow with w, and its rounding can stop the line search short of
                // the tolerance: Newton steps that lower the residual then go on.
                _ => problem.polish(w, r, tol, iterations),
            }
        };
        let mut w = [0.0; 3];
        let mut residual = solve(mu, &mut w, r);
        // A large w (an HDR colour's r₀ is large) can stall far from the solution: then from
        // a penalty 10⁸ times as strong, weakened tenfold a step, each from the last one's w.
        if residual > STALLED_RESIDUAL * scale {
            w = [0.0; 3];
            for k in (1..=STRONGER_PENALTIES).rev() {
                solve(mu * 10f64.powi(k), &mut w, r);
            }
            residual = solve(mu, &mut w, r);
        }
        let solve = if residual <= STALLED_RESIDUAL * scale {
            Solve::Solved
        } else {
            Solve::Unresolved
        };
        (solve, w)
    }

    /// clip(r0 + Aᵀw, 0, 1) into `r` by the dual's own pass (whose sum every decoder of a
    /// compact texel keeps), so that a w given is the spectrum's to the bit.
    pub fn texel_form(&self, r0: &[f64], w: [f64; 3], r: &mut [f64]) {
        let pass = Dual {
            cols: &self.cols,
            p: r0,
            s: [0.0; 3],
            mu: 0.0,
            eps: 0.0,
        };
        pass.at(&w, r);
    }

    /// [`Solid::project_within`], with the dual unknowns w where it ended: when solved,
    /// r = clip(r0 + Aᵀw, 0, 1) (the compact texel's u, `specconv_spectral::compact`).
    pub fn project_dual(
        &self,
        c: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        iterations: usize,
    ) -> (Solve, [f64; 3]) {
        self.project_dual_from(c, r0, r, iterations, [0.0; 3])
    }

    /// [`Solid::project_dual`] with the Newton iteration started at `w0` instead of 0: the
    /// dual of a nearby problem's solution, which saves most of the steps of a colour near the
    /// solid's surface (large w). r is unique, so where both converge they agree to the
    /// tolerance of the residual; a `w0` that is not finite starts at 0.
    pub fn project_dual_from(
        &self,
        c: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        iterations: usize,
        w0: [f64; 3],
    ) -> (Solve, [f64; 3]) {
        let scale = c[0].abs().max(c[1].abs()).max(c[2].abs());
        let tol = RESIDUAL * scale.max(f64::MIN_POSITIVE);
        // Each axis bounds the solid: c beyond one is outside, at the cost of six compares.
        for k in 0..3 {
            for (sign, support) in [
                (1.0, self.axis_support[0][k]),
                (-1.0, self.axis_support[1][k]),
            ] {
                if sign * c[k] > support + tol {
                    let mut u = [0.0; 3];
                    u[k] = sign;
                    return (Solve::Outside(u), [0.0; 3]);
                }
            }
        }
        let problem = Dual {
            cols: &self.cols,
            p: r0,
            s: c,
            mu: 0.0,
            eps: HESSIAN_FLOOR * self.trace,
        };
        let mut w = if w0.iter().all(|v| v.is_finite()) {
            w0
        } else {
            [0.0; 3]
        };
        let mut certificate = None;
        // An unbounded dual: w, or a step that the free bands cannot resist, points out of Z.
        let watch = |w: &[f64; 3], delta: &[f64; 3], free: usize, step: usize| {
            // In-solid colours settle within a few steps; after those, look every step.
            if free >= 3 && step < 4 {
                return false;
            }
            for u in [*w, *delta] {
                if self.certifies(c, u, tol) {
                    certificate = Some(u);
                    return true;
                }
            }
            false
        };
        let solve = match problem.minimise(&mut w, r, tol, iterations, watch) {
            End::Converged => Solve::Solved,
            End::Watched => Solve::Outside(certificate.expect("set by the watch")),
            End::Stalled(residual)
                if residual <= STALLED_RESIDUAL * scale.max(f64::MIN_POSITIVE) =>
            {
                Solve::Solved
            }
            End::Stalled(_) => Solve::Unresolved,
        };
        (solve, w)
    }
}

/// min Ψ(w) of the module, for columns bᵢ of B, proximal centre p, target s, damping μ ≥ 0 and
/// a regularisation eps of the Hessian when μ = 0 and fewer than three bands are free.
pub(crate) struct Dual<'a> {
    pub cols: &'a [[f64; 3]],
    pub p: &'a [f64],
    pub s: [f64; 3],
    pub mu: f64,
    pub eps: f64,
}

/// How [`Dual::minimise`] ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum End {
    /// The residual is within the tolerance: `r` is the solution.
    Converged,
    /// The watch asked to stop.
    Watched,
    /// No further progress; the largest residual component left.
    Stalled(f64),
}

/// Ψ, its gradient and its (generalised) Hessian at one w: one pass over the bands.
struct Point {
    psi: f64,
    grad: [f64; 3],
    /// Upper triangle of B_F·B_Fᵀ: 00, 01, 02, 11, 12, 22.
    hess: [f64; 6],
    free: usize,
}

impl Dual<'_> {
    /// r(w) into `r`, with Ψ(w) and its derivatives.
    fn at(&self, w: &[f64; 3], r: &mut [f64]) -> Point {
        let mut psi = 0.0;
        let mut f = [0.0; 3];
        let mut h = [0.0; 6];
        let mut free = 0;
        for ((b, &p), ri) in self.cols.iter().zip(self.p).zip(r.iter_mut()) {
            let z = p + b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
            // A band at 0 adds nothing to A·r: skipping its +0 keeps every sum bit for bit (f
            // starts at +0 and never becomes −0) and shortens the sums' chains of additions.
            if z <= 0.0 {
                *ri = 0.0;
            } else if z < 1.0 {
                psi += 0.5 * z * z;
                h[0] += b[0] * b[0];
                h[1] += b[0] * b[1];
                h[2] += b[0] * b[2];
                h[3] += b[1] * b[1];
                h[4] += b[1] * b[2];
                h[5] += b[2] * b[2];
                free += 1;
                *ri = z;
                f[0] += b[0] * z;
                f[1] += b[1] * z;
                f[2] += b[2] * z;
            } else {
                psi += z - 0.5;
                *ri = 1.0;
                f[0] += b[0];
                f[1] += b[1];
                f[2] += b[2];
            }
        }
        let s = self.s;
        let mu = self.mu;
        psi += 0.5 * mu * dot(*w, *w) - dot(s, *w);
        let grad = [0, 1, 2].map(|k| f[k] - s[k] + mu * w[k]);
        Point {
            psi,
            grad,
            hess: h,
            free,
        }
    }

    /// The Newton step at `point`: −(H + reg·I)⁻¹·∇Ψ, reg = μ, plus eps where fewer than three
    /// bands are free; `None` where that matrix is singular.
    fn newton(&self, point: &Point) -> Option<[f64; 3]> {
        let reg = self.mu + if point.free < 3 { self.eps } else { 0.0 };
        let h = point.hess;
        let j = [
            [h[0] + reg, h[1], h[2]],
            [h[1], h[3] + reg, h[4]],
            [h[2], h[4], h[5] + reg],
        ];
        mat3::solve(&j, point.grad.map(|v| -v))
    }

    /// Full Newton steps from `w` while each lowers the largest residual component, at most
    /// `iterations`; `r` ends as r(w). Returns the residual left.
    pub fn polish(&self, w: &mut [f64; 3], r: &mut [f64], tol: f64, iterations: usize) -> f64 {
        let mut stack = [0.0; STACK_BANDS];
        let mut heap = Vec::new();
        let trial_r: &mut [f64] = if r.len() <= STACK_BANDS {
            &mut stack[..r.len()]
        } else {
            heap.resize(r.len(), 0.0);
            &mut heap
        };
        let mut point = self.at(w, r);
        let mut residual = point.grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for _ in 0..iterations {
            if residual <= tol {
                break;
            }
            let Some(delta) = self.newton(&point) else {
                break;
            };
            // The first of t = 1, ½, ¼, … that lowers the residual (Ψ's own decrease is below
            // its rounding here).
            let mut step = None;
            let mut t = 1.0;
            for _ in 0..POLISH_HALVINGS {
                let trial = [0, 1, 2].map(|k| w[k] + t * delta[k]);
                let next = self.at(&trial, trial_r);
                let left = next.grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                if left < residual {
                    step = Some((trial, next, left));
                    break;
                }
                t *= 0.5;
            }
            let Some((trial, next, left)) = step else {
                break;
            };
            *w = trial;
            r.copy_from_slice(trial_r);
            (point, residual) = (next, left);
        }
        residual
    }

    /// Minimises Ψ from `w` by Newton steps with backtracking; `r` ends as r(w). `watch(w, δ,
    /// free bands, step)` is asked before each step and stops the iteration when it says so.
    pub fn minimise(
        &self,
        w: &mut [f64; 3],
        r: &mut [f64],
        tol: f64,
        iterations: usize,
        mut watch: impl FnMut(&[f64; 3], &[f64; 3], usize, usize) -> bool,
    ) -> End {
        let n = r.len();
        let mut stack = [0.0; STACK_BANDS];
        let mut heap = Vec::new();
        let scratch: &mut [f64] = if n <= STACK_BANDS {
            &mut stack[..n]
        } else {
            heap.resize(n, 0.0);
            &mut heap
        };
        // The current r lives in `cur`, trials in `other`; they swap on acceptance.
        let (mut cur, mut other): (&mut [f64], &mut [f64]) = (r, scratch);
        let mut in_scratch = false;
        let mut point = self.at(w, cur);
        let mut end = End::Stalled(f64::INFINITY);
        for step in 0..iterations {
            let residual = point.grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if residual <= tol {
                end = End::Converged;
                break;
            }
            end = End::Stalled(residual);
            let Some(delta) = self.newton(&point) else {
                break;
            };
            if watch(w, &delta, point.free, step) {
                end = End::Watched;
                break;
            }
            let slope = dot(point.grad, delta);
            let mut t = 1.0;
            let mut accepted = false;
            let size = delta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let reach = w.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            // Halve while the step still moves w.
            while t * size > STEP_FLOOR * reach {
                let trial = [0, 1, 2].map(|k| w[k] + t * delta[k]);
                let next = self.at(&trial, other);
                // Slack for rounding in Ψ, a sum of n terms.
                let slack = PSI_ROUNDING * (point.psi.abs() + next.psi.abs());
                if next.psi <= point.psi + ARMIJO * t * slope + slack {
                    *w = trial;
                    point = next;
                    std::mem::swap(&mut cur, &mut other);
                    in_scratch = !in_scratch;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        if end != End::Converged {
            let residual = point.grad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if residual <= tol {
                end = End::Converged;
            } else if let End::Stalled(_) = end {
                end = End::Stalled(residual);
            }
        }
        if in_scratch {
            other.copy_from_slice(cur);
        }
        end
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 45: the pass over the bands adds nothing for a band at 0 and b (not b·1) for one
    /// at 1; its results must stay bit for bit those of adding clip(z, 0, 1)·b for every band,
    /// which the C header, the reference texels and the tests' answers were made with.
    #[test]
    fn the_dual_pass_keeps_every_sum_bit_for_bit() {
        let mut state = 45u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let cols: Vec<[f64; 3]> = (0..40).map(|_| [next(), next(), next()]).collect();
        let p: Vec<f64> = (0..40).map(|_| 3.0 * next()).collect();
        let dual = Dual {
            cols: &cols,
            p: &p,
            s: [next(), next(), next()],
            mu: 0.25,
            eps: 0.0,
        };
        let mut r = vec![0.0; cols.len()];
        let mut kinds = [0usize; 3];
        for _ in 0..50 {
            let w = [4.0 * next(), 4.0 * next(), 4.0 * next()];
            let point = dual.at(&w, &mut r);
            let (mut psi, mut f, mut h, mut free) = (0.0, [0.0; 3], [0.0; 6], 0);
            for (i, (b, &q)) in cols.iter().zip(&p).enumerate() {
                let z = q + b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
                let v = z.clamp(0.0, 1.0);
                kinds[usize::from(v > 0.0) + usize::from(v == 1.0)] += 1;
                if v > 0.0 && v < 1.0 {
                    psi += 0.5 * z * z;
                    let pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
                    for (hk, (j, l)) in h.iter_mut().zip(pairs) {
                        *hk += b[j] * b[l];
                    }
                    free += 1;
                } else if v == 1.0 {
                    psi += z - 0.5;
                }
                f.iter_mut().zip(b).for_each(|(fk, bk)| *fk += bk * v);
                assert_eq!(r[i].to_bits(), v.to_bits(), "band {i}");
            }
            psi += 0.5 * dual.mu * dot(w, w) - dot(dual.s, w);
            let grad = [0, 1, 2].map(|k| f[k] - dual.s[k] + dual.mu * w[k]);
            assert_eq!(point.psi.to_bits(), psi.to_bits());
            assert_eq!(point.grad.map(f64::to_bits), grad.map(f64::to_bits));
            assert_eq!(point.hess.map(f64::to_bits), h.map(f64::to_bits));
            assert_eq!(point.free, free);
        }
        // Every kind of band was met: at 0, free, at 1.
        assert!(kinds.iter().all(|&k| k > 100), "{kinds:?}");
    }
}
