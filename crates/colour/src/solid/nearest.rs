//! Colours outside the object-colour solid: the in-range spectrum whose colour is nearest to
//! the input in CIELAB.
//!
//! min over 0 ≤ r ≤ 1 of φ(r) = ½‖Lab(A·r) − Lab(c)‖², by Gauss–Newton with a proximal
//! (Levenberg–Marquardt) term: at x = A·r_k, with J the Jacobian of Lab at x, each step solves
//!
//!   min over 0 ≤ r ≤ 1 of ½‖J·(A·r − x) + Lab(x) − Lab(c)‖² + (μ/2)‖r − r_k‖²
//!
//! exactly, through its dual in three unknowns ([`crate::solid`]). A step that lowers φ is taken
//! and μ shrinks; one that does not is retried with a larger μ. At a fixed point r_k the
//! proximal term's gradient vanishes, so the limit meets the KKT conditions of the unregularised
//! problem: its colour is a point of the solid's surface whose outward normal is
//! Jᵀ·(Lab(c) − Lab(A·r)), every band at 0 or 1 but those (at most two, in general) whose
//! column is orthogonal to that normal. The spectrum of a surface colour is thereby unique up to
//! such bands, and the proximal terms keep those near the start, clip(r₀, 0, 1).
//!
//! Lab is taken as its formula for every XYZ, above the white (Y > 1: L* > 100, the cube root
//! continues) and below zero (the linear segment continues), so bright and negative colours
//! have a nearest colour too: a grey brighter than white reaches the perfect white.

use super::{Dual, End, Solid};
use crate::lab::{xyz_to_lab, xyz_to_lab_jacobian};
use crate::mat3::dot;

/// Proximal Gauss–Newton steps at most.
pub const STEPS: usize = 80;
/// Dual Newton steps per subproblem at most (each converges in a few).
pub const SUB_STEPS: usize = 50;
/// Tries of one step, each with a stronger proximal term, at most: the weight passes
/// [`MU_CAP`] within about 30 (the bound holds where a hostile A makes the weight NaN).
pub const TRIES: usize = 64;
/// The first proximal weight, relative to trace(B·Bᵀ)/n…
pub const MU_START: f64 = 1e-3;
/// …scaled by this after a step taken…
pub const MU_SHRINK: f64 = 0.25;
/// …never below this (relative, the same way), which keeps the subproblem well conditioned…
pub const MU_FLOOR: f64 = 1e-9;
/// …and by this after a try refused, until it passes this, relative to trace(B·Bᵀ).
pub const MU_GROW: f64 = 8.0;
/// See [`MU_GROW`].
pub const MU_CAP: f64 = 1e12;
/// A subproblem's tolerance, relative to its target's largest component (the outer iteration
/// corrects what the inner one leaves).
pub const SUB_TOLERANCE: f64 = 1e-10;
/// Settled: a step changes φ by at most this, relative…
pub const SETTLED_PHI: f64 = 1e-10;
/// …or no band by more than this.
pub const SETTLED_MOVE: f64 = 1e-12;

/// The in-range spectrum nearest to `c` in CIELAB (reference white `white`), into `r`,
/// starting from the method's spectrum `r0`; returns its colour A·r.
pub fn nearest_lab(
    solid: &Solid,
    white: [f64; 3],
    c: [f64; 3],
    r0: &[f64],
    r: &mut [f64],
) -> [f64; 3] {
    let n = solid.bands();
    let target = xyz_to_lab(c, white);
    for (v, &s) in r.iter_mut().zip(r0) {
        *v = if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.5
        };
    }
    let mut x = solid.xyz(r);
    let (mut lab, mut jac) = xyz_to_lab_jacobian(x, white);
    let mut phi = distance2(lab, target);
    let mut b = vec![[0.0; 3]; n];
    let mut trial = vec![0.0; n];
    let mut mu = f64::NAN;
    for _ in 0..STEPS {
        if phi == 0.0 {
            break;
        }
        for (bi, a) in b.iter_mut().zip(solid.columns()) {
            *bi = [0, 1, 2].map(|row| dot(jac[row], *a));
        }
        let trace: f64 = b.iter().map(|v| dot(*v, *v)).sum();
        if mu.is_nan() {
            mu = MU_START * trace / n as f64;
        }
        let jx = [0, 1, 2].map(|row| dot(jac[row], x));
        let s = [0, 1, 2].map(|k| jx[k] - (lab[k] - target[k]));
        let mut improved = false;
        for _ in 0..TRIES {
            if improved {
                break;
            }
            let sub = Dual {
                cols: &b,
                p: r,
                s,
                mu,
                eps: 0.0,
            };
            let tol = SUB_TOLERANCE * s.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            let mut w = [0.0; 3];
            let end = sub.minimise(&mut w, &mut trial, tol, SUB_STEPS, |_, _, _, _| false);
            let xt = solid.xyz(&trial);
            let (lab_t, jac_t) = xyz_to_lab_jacobian(xt, white);
            let phi_t = distance2(lab_t, target);
            let moved = r
                .iter()
                .zip(&trial)
                .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            let settled = (phi - phi_t).abs() <= SETTLED_PHI * phi || moved <= SETTLED_MOVE;
            if end != End::Watched && phi_t < phi {
                r.copy_from_slice(&trial);
                (x, lab, jac, phi) = (xt, lab_t, jac_t, phi_t);
                // The floor keeps the subproblem's Hessian well conditioned.
                mu = (mu * MU_SHRINK).max(MU_FLOOR * trace / n as f64);
                improved = true;
            } else {
                mu *= MU_GROW;
            }
            // A step that changes nothing, or no step of any length that lowers φ: stationary.
            if settled || mu > MU_CAP * trace.max(f64::MIN_POSITIVE) {
                return x;
            }
        }
    }
    x
}

fn distance2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum()
}
