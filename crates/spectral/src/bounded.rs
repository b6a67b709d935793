//! Physically valid reflectances: a [`Method`] wrapper that keeps every spectrum in [0, 1].
//!
//! Where the wrapped method's spectrum r₀ leaves [0, 1] (the paper's Section 6 names this as a
//! limitation of the clustered PCA), [`Bounded`] returns the solution of
//!
//!   min ½‖r − r₀‖²  subject to  A·r = c,  0 ≤ r ≤ 1
//!
//! (A: the colorimetry's 3×n map to XYZ): the in-range spectrum nearest to the reconstruction
//! with exactly the input colour. It is solved per pixel through its dual in λ ∈ R³: the
//! minimiser for given λ is r(λ) = clip(r₀ + Aᵀλ, 0, 1), and the problem is solved when
//! A·r(λ) = c. Each iteration fixes the active set (bands clipped at 0 or 1) of the current λ
//! and takes the exact solve on it, a Newton step with the 3×3 system A_F·A_Fᵀ over the free
//! bands, with a backtracking line search on the concave dual; once the active set is the
//! right one the step lands on the solution, so the iteration ends with the KKT conditions
//! met to rounding (an active-set method working in the three dual unknowns).
//!
//! When no spectrum in [0, 1] has colour c (c is outside the object-colour solid, the zonotope
//! {A·r : 0 ≤ r ≤ 1}), the dual is unbounded and λ/‖λ‖ tends to a direction u with
//! u·c > h(u) = Σᵢ max(0, (Aᵀu)ᵢ), the solid's support function: a certificate that c is
//! outside. Then the colour is moved towards the grey of its luminance (Y clamped to [0, 1]),
//! c(t) = g + t·(c − g), as far as the solid allows (bisection on t, 16 steps, each a
//! solve of at most 12 dual steps; a trial that does not settle counts as outside), and the spectrum of that colour is returned: a documented simplification of "the
//! in-range colour closest in CIELAB"; it keeps the luminance when 0 ≤ Y ≤ 1 and the dominant
//! wavelength, and gives up chroma.

use crate::{Colorimetry, Error, Grid, Method};

/// What [`Bounded`] did with one colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// The method's spectrum was already in [0, 1]; returned unchanged.
    InRange,
    /// Projected: the nearest spectrum in [0, 1] with the input XYZ.
    Projected,
    /// No spectrum in [0, 1] has this colour: `certificate` u has u·c > h(u) (`None` when the
    /// solve ended on the solid's edge without a certificate). The spectrum returned is the
    /// projection for `reached`, the colour towards grey that the solid allows.
    Outside {
        certificate: Option<[f64; 3]>,
        reached: [f64; 3],
    },
    /// NaN or ±Inf in the input: the method's spectrum (NaN) passes through.
    NotFinite,
}

/// How many colours of a call had each outcome.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    pub in_range: usize,
    pub projected: usize,
    pub outside: usize,
    pub not_finite: usize,
}

impl Counts {
    fn add(&mut self, o: &Outcome) {
        match o {
            Outcome::InRange => self.in_range += 1,
            Outcome::Projected => self.projected += 1,
            Outcome::Outside { .. } => self.outside += 1,
            Outcome::NotFinite => self.not_finite += 1,
        }
    }
}

/// A method whose spectra are kept in [0, 1] with their XYZ unchanged (see the module).
pub struct Bounded<M> {
    inner: M,
    colorimetry: Colorimetry,
    name: String,
}

impl<M: Method> Bounded<M> {
    /// Wraps `inner`; `colorimetry` is the XYZ the inner method's spectra are uplifted for (the
    /// model's), on the same grid.
    pub fn new(inner: M, colorimetry: Colorimetry) -> Result<Bounded<M>, Error> {
        if inner.grid() != colorimetry.grid {
            return Err(Error::Grid(format!(
                "the method's grid {} is not the colorimetry's {}",
                inner.grid(),
                colorimetry.grid
            )));
        }
        let name = format!("{}+bounded", inner.name());
        Ok(Bounded {
            inner,
            colorimetry,
            name,
        })
    }

    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// As [`Method::uplift_f64`], counting the outcomes.
    pub fn uplift_f64_counted(&self, xyz: &[f64], out: &mut [f64]) -> Counts {
        let n = self.colorimetry.bands();
        self.inner.uplift_f64(xyz, out);
        let mut counts = Counts::default();
        for (c, r) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            counts.add(&self.bound([c[0], c[1], c[2]], r));
        }
        counts
    }

    /// As [`Method::uplift_f32`], counting the outcomes. Spectra that need the projection are
    /// uplifted and projected again in f64.
    pub fn uplift_f32_counted(&self, xyz: &[f32], out: &mut [f32]) -> Counts {
        let n = self.colorimetry.bands();
        self.inner.uplift_f32(xyz, out);
        let mut counts = Counts::default();
        let mut r = vec![0.0f64; n];
        for (c, o) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let finite = c.iter().all(|v| v.is_finite());
            if !finite {
                counts.not_finite += 1;
            } else if o.iter().all(|v| (0.0..=1.0).contains(v)) {
                counts.in_range += 1;
            } else {
                let c = [c[0] as f64, c[1] as f64, c[2] as f64];
                self.inner.uplift_f64(&c, &mut r);
                counts.add(&self.bound(c, &mut r));
                for (o, v) in o.iter_mut().zip(&r) {
                    *o = *v as f32;
                }
            }
        }
        counts
    }

    /// Bounds one spectrum `r` (the inner method's for colour `c`) in place.
    pub fn bound(&self, c: [f64; 3], r: &mut [f64]) -> Outcome {
        if c.iter().any(|v| !v.is_finite()) {
            return Outcome::NotFinite;
        }
        if r.iter().all(|v| (0.0..=1.0).contains(v)) {
            return Outcome::InRange;
        }
        let a = &self.colorimetry.weights;
        let r0 = r.to_vec();
        match project(a, c, &r0, r) {
            Solve::Solved => Outcome::Projected,
            solve => {
                let (reached, _) = self.towards_grey(c, &r0, r);
                Outcome::Outside {
                    certificate: match solve {
                        Solve::Outside(u) => Some(u),
                        _ => None,
                    },
                    reached,
                }
            }
        }
    }

    /// The farthest colour on g → c inside the solid (g: grey of c's luminance, clamped to
    /// [0, 1]) and its projection of `r0` into `r`; also the fraction t reached.
    fn towards_grey(&self, c: [f64; 3], r0: &[f64], r: &mut [f64]) -> ([f64; 3], f64) {
        let a = &self.colorimetry.weights;
        let luminance = c[1].clamp(0.0, 1.0);
        let white = self.colorimetry.white_xyz();
        let g = white.map(|w| w * luminance);
        let at = |t: f64| [0, 1, 2].map(|k| g[k] + t * (c[k] - g[k]));
        // t = 0 is the grey spectrum itself, in range with colour g.
        r.iter_mut().for_each(|v| *v = luminance);
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut trial = vec![0.0; r.len()];
        for _ in 0..BISECTIONS {
            let t = 0.5 * (lo + hi);
            // Few dual steps: a trial that does not settle counts as outside (t only shrinks).
            match project_within(a, at(t), r0, &mut trial, 12) {
                Solve::Solved => {
                    lo = t;
                    r.copy_from_slice(&trial);
                }
                Solve::Outside(_) | Solve::Unresolved => hi = t,
            }
        }
        (at(lo), lo)
    }
}

impl<M: Method> Method for Bounded<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn grid(&self) -> Grid {
        self.inner.grid()
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        self.uplift_f64_counted(xyz, out);
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        self.uplift_f32_counted(xyz, out);
    }

    fn model_bytes(&self) -> usize {
        self.inner.model_bytes()
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        self.inner.cluster_of(xyz)
    }
}

/// Boxed methods, as the command line builds them by name, are methods too, so that any of
/// them can be bounded.
impl Method for Box<dyn Method> {
    fn name(&self) -> &str {
        (**self).name()
    }

    fn grid(&self) -> Grid {
        (**self).grid()
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        (**self).uplift_f64(xyz, out)
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        (**self).uplift_f32(xyz, out)
    }

    fn model_bytes(&self) -> usize {
        (**self).model_bytes()
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        (**self).cluster_of(xyz)
    }
}

/// The result of [`project`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solve {
    /// `r` holds the solution; A·r = c to rounding.
    Solved,
    /// No r in [0, 1] has A·r = c: u with u·c > Σᵢ max(0, (Aᵀu)ᵢ).
    Outside([f64; 3]),
    /// Neither within `MAX_ITERATIONS`: c lies on the solid's surface to rounding.
    Unresolved,
}

/// Steps of the bisection towards grey: t to 2⁻¹⁶.
const BISECTIONS: usize = 16;

/// Dual iterations before a colour is declared unresolved (on the solid's surface).
const MAX_ITERATIONS: usize = 60;

/// min ½‖r − r0‖² subject to A·r = c and 0 ≤ r ≤ 1, into `r` (see the module).
pub fn project(a: &[Vec<f64>; 3], c: [f64; 3], r0: &[f64], r: &mut [f64]) -> Solve {
    project_within(a, c, r0, r, MAX_ITERATIONS)
}

/// [`project`] with at most `iterations` dual steps.
fn project_within(
    a: &[Vec<f64>; 3],
    c: [f64; 3],
    r0: &[f64],
    r: &mut [f64],
    iterations: usize,
) -> Solve {
    let n = r0.len();
    let scale = c[0].abs().max(c[1].abs()).max(c[2].abs());
    let tol = 1e-13 * scale.max(f64::MIN_POSITIVE);
    // Regularisation of A_F·A_Fᵀ when fewer than three bands are free.
    let trace: f64 = a
        .iter()
        .map(|row| row.iter().map(|v| v * v).sum::<f64>())
        .sum();
    let eps = 1e-12 * trace;
    // Cheap certificates first: each of ±X, ±Y, ±Z bounds the solid (A ≥ 0).
    for k in 0..3 {
        let mut u = [0.0; 3];
        u[k] = 1.0;
        if outside(a, c, u, tol) {
            return Solve::Outside(u);
        }
        u[k] = -1.0;
        if outside(a, c, u, tol) {
            return Solve::Outside(u);
        }
    }
    let mut lambda = [0.0f64; 3];
    let dual = |lambda: &[f64; 3], r: &mut [f64]| -> (f64, [f64; 3]) {
        // g(λ) = λ·c + Σᵢ ½(rᵢ − r0ᵢ)² − (Aᵀλ)ᵢ·rᵢ at r = clip(r0 + Aᵀλ); returns g and A·r − c.
        let mut g = lambda[0] * c[0] + lambda[1] * c[1] + lambda[2] * c[2];
        let mut f = [-c[0], -c[1], -c[2]];
        for i in 0..n {
            let q = a[0][i] * lambda[0] + a[1][i] * lambda[1] + a[2][i] * lambda[2];
            let v = (r0[i] + q).clamp(0.0, 1.0);
            r[i] = v;
            g += 0.5 * (v - r0[i]) * (v - r0[i]) - q * v;
            for k in 0..3 {
                f[k] += a[k][i] * v;
            }
        }
        (g, f)
    };
    let (mut g, mut f) = dual(&lambda, r);
    let mut trial = vec![0.0; n];
    for _ in 0..iterations {
        if f.iter().all(|v| v.abs() <= tol) {
            return Solve::Solved;
        }
        // J = A_F·A_Fᵀ over the free bands of the current λ.
        let mut j = [[0.0f64; 3]; 3];
        for i in 0..n {
            if r[i] > 0.0 && r[i] < 1.0 {
                for p in 0..3 {
                    for q in 0..3 {
                        j[p][q] += a[p][i] * a[q][i];
                    }
                }
            }
        }
        (0..3).for_each(|k| j[k][k] += eps);
        let Some(delta) = solve3(j, f.map(|v| -v)) else {
            break;
        };
        let slope = -(f[0] * delta[0] + f[1] * delta[1] + f[2] * delta[2]);
        let mut step = 1.0;
        let mut moved = false;
        for _ in 0..40 {
            let l = [0, 1, 2].map(|k| lambda[k] + step * delta[k]);
            let (gt, ft) = dual(&l, &mut trial);
            if gt >= g + 1e-4 * step * slope {
                lambda = l;
                g = gt;
                f = ft;
                r.copy_from_slice(&trial);
                moved = true;
                break;
            }
            step *= 0.5;
        }
        // An unbounded dual: λ (or the step) points out of the solid.
        for u in [lambda, delta] {
            if outside(a, c, u, tol) {
                return Solve::Outside(u);
            }
        }
        if !moved {
            break;
        }
    }
    if f.iter()
        .all(|v| v.abs() <= 1e-9 * scale.max(f64::MIN_POSITIVE))
    {
        return Solve::Solved;
    }
    Solve::Unresolved
}

/// Whether u certifies that c is outside the solid: u·c > h(u) + tol·‖u‖₁.
fn outside(a: &[Vec<f64>; 3], c: [f64; 3], u: [f64; 3], tol: f64) -> bool {
    let norm = u[0].abs() + u[1].abs() + u[2].abs();
    if !(norm > 0.0 && norm.is_finite()) {
        return false;
    }
    let u = u.map(|v| v / norm);
    let support: f64 = (0..a[0].len())
        .map(|i| (a[0][i] * u[0] + a[1][i] * u[1] + a[2][i] * u[2]).max(0.0))
        .sum();
    u[0] * c[0] + u[1] * c[1] + u[2] * c[2] > support + tol
}

/// Solves the symmetric 3×3 system j·x = b by Cramer's rule.
fn solve3(j: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(j);
    if !(d.abs() > 0.0 && d.is_finite()) {
        return None;
    }
    let x = [0, 1, 2].map(|k| {
        let mut m = j;
        (0..3).for_each(|row| m[row][k] = b[row]);
        det(m) / d
    });
    x.iter().all(|v| v.is_finite()).then_some(x)
}
