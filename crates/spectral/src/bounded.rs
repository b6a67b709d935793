//! Physically valid reflectances: a [`Method`] wrapper that keeps every spectrum in [0, 1].
//!
//! Where the wrapped method's spectrum r₀ leaves [0, 1] (the paper's Section 6 names this as a
//! limitation of the clustered PCA), [`Bounded`] returns the solution of
//!
//!   min ½‖r − r₀‖²  subject to  A·r = c,  0 ≤ r ≤ 1
//!
//! (A: the colorimetry's 3×n map to XYZ): the in-range spectrum nearest to the reconstruction
//! with exactly the input colour, solved exactly through its dual in three unknowns
//! ([`solid`](specconv_colour::solid)). Spectra already in [0, 1] are returned untouched after
//! one pass of compares.
//!
//! When no spectrum in [0, 1] has colour c (c is outside the object-colour solid, the zonotope
//! {A·r : 0 ≤ r ≤ 1}), the dual is unbounded and the solve returns a direction u with
//! u·c > h(u) = Σᵢ max(0, (Aᵀu)ᵢ), the solid's support function: a certificate that c is
//! outside. Then the result is the in-range spectrum whose colour is nearest to c in CIELAB
//! ([`nearest`]), a point of the solid's surface; `Outcome::Outside` reports that colour.

pub use specconv_colour::solid::{nearest, Solid, Solve};

use crate::method::Tally;
use crate::{Error, Method};
use specconv_colour::mat3::{cross, dot};
use specconv_colour::{Colorimetry, Grid};

/// What [`Bounded`] did with one colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// The method's spectrum was already in [0, 1]; returned unchanged.
    InRange,
    /// Projected: the nearest spectrum in [0, 1] with the input XYZ.
    Projected,
    /// No spectrum in [0, 1] has this colour: `certificate` u has u·c > h(u) (`None` when the
    /// solve ended on the solid's surface without a certificate). The spectrum returned is the
    /// in-range one whose colour, `reached`, is nearest to the input in CIELAB ([`nearest`]).
    Outside {
        /// u with u·c > h(u), proof that c is outside the object-colour solid.
        certificate: Option<[f64; 3]>,
        /// XYZ of the spectrum returned.
        reached: [f64; 3],
    },
    /// NaN or ±Inf in the input: the method's spectrum (NaN) passes through.
    NotFinite,
}

pub use crate::method::Counts;

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

/// Colours per block of the f32 path.
const BLOCK: usize = 64;

/// How close clip(r₀ + Aᵀw, 0, 1) with w rounded to float32 must stay to the spectrum with w
/// itself, per band and relative to the band's value (at least 2⁻¹⁴, half's smallest normal),
/// for an outside colour's projection to be taken: 2⁻¹³, a quarter of the spacing of half
/// floats there.
pub const DUAL_F32_TOLERANCE: f64 = 1.0 / 8192.0;

/// The fractions by which an outside colour's projection is drawn towards grey, tried in turn
/// (`Bounded::onto_reached`): 0, then 10⁻⁸ doubled 27 times.
const PULLS: [f64; 29] = {
    let mut t = [0.0; 29];
    let mut k = 1;
    while k < 29 {
        t[k] = if k == 1 { 1e-8 } else { 2.0 * t[k - 1] };
        k += 1;
    }
    t
};

/// Bands strictly inside (0, 1).
fn free_bands(r: &[f64]) -> usize {
    r.iter().filter(|&&v| v > 0.0 && v < 1.0).count()
}

/// Dual Newton steps of a projection ([`Solid::project`]'s).
const MAX_DUAL_STEPS: usize = 60;

/// A method whose spectra are kept in [0, 1] with their XYZ unchanged (see the module).
#[derive(Clone)]
pub struct Bounded<M> {
    inner: M,
    colorimetry: Colorimetry,
    solid: Solid,
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
            solid: Solid::new(&colorimetry.weights),
            colorimetry,
            name,
        })
    }

    /// The wrapped method.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The object-colour solid of the colorimetry.
    pub fn solid(&self) -> &Solid {
        &self.solid
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
        let mut counts = Counts::default();
        let mut r = vec![0.0f64; n];
        // By blocks, so that the check reads spectra the uplift has just written (in L1).
        for (xyz, out) in xyz.chunks(3 * BLOCK).zip(out.chunks_mut(n * BLOCK)) {
            self.inner.uplift_f32(xyz, out);
            self.bound_f32(xyz, out, &mut r, &mut counts);
        }
        counts
    }

    /// Bounds the f32 spectra `out` of the colours `xyz` in place; `r` is scratch.
    fn bound_f32(&self, xyz: &[f32], out: &mut [f32], r: &mut [f64], counts: &mut Counts) {
        let n = r.len();
        for (c, o) in xyz.chunks_exact(3).zip(out.chunks_exact_mut(n)) {
            let finite = c.iter().all(|v| v.is_finite());
            if !finite {
                counts.not_finite += 1;
            } else if o.iter().fold(true, |ok, v| ok & (0.0..=1.0).contains(v)) {
                // The fast path, most of a texture: one pass of compares without early exit
                // (about 5 ns per pixel in the bench).
                counts.in_range += 1;
            } else {
                let c = [c[0] as f64, c[1] as f64, c[2] as f64];
                self.inner.uplift_f64(&c, r);
                counts.add(&self.bound(c, r));
                for (o, v) in o.iter_mut().zip(r.iter()) {
                    *o = *v as f32;
                }
            }
        }
    }

    /// Bounds one spectrum `r` (the inner method's for colour `c`) in place.
    pub fn bound(&self, c: [f64; 3], r: &mut [f64]) -> Outcome {
        self.bound_dual(c, r).0
    }

    /// [`Bounded::bound`], with the dual unknowns w of the result: r = clip(r₀ + Aᵀw, 0, 1)
    /// for every outcome (w = 0 in range and for NaN), the compact texel's u
    /// ([`crate::compact`]).
    pub fn bound_dual(&self, c: [f64; 3], r: &mut [f64]) -> (Outcome, [f64; 3]) {
        self.bound_dual_with(c, r, true)
    }

    /// [`Bounded::bound`] as it was before issue 45, kept as the reference that the tests and
    /// the `solid_cost` example measure the outside search against: no closed form on a face
    /// (`Bounded::on_the_face`), and each trial projection of an outside colour
    /// ([`Bounded::bound`]'s last step) starts from w = 0.
    pub fn bound_reference(&self, c: [f64; 3], r: &mut [f64]) -> Outcome {
        self.bound_dual_with(c, r, false).0
    }

    /// [`Bounded::bound_dual`]; `warm` (issue 45): the closed form on a face first, and each
    /// trial projection of an outside colour starts from the last solved trial's w.
    fn bound_dual_with(&self, c: [f64; 3], r: &mut [f64], warm: bool) -> (Outcome, [f64; 3]) {
        if c.iter().any(|v| !v.is_finite()) {
            return (Outcome::NotFinite, [0.0; 3]);
        }
        if r.iter().all(|v| (0.0..=1.0).contains(v)) {
            return (Outcome::InRange, [0.0; 3]);
        }
        let mut stack = [0.0; 128];
        let mut heap = Vec::new();
        let r0: &mut [f64] = if r.len() <= stack.len() {
            &mut stack[..r.len()]
        } else {
            heap.resize(r.len(), 0.0);
            &mut heap
        };
        r0.copy_from_slice(r);
        match self.solid.project_dual(c, r0, r, MAX_DUAL_STEPS) {
            (Solve::Solved, w) => (Outcome::Projected, w),
            (solve, _) => {
                let near =
                    nearest::nearest_lab(&self.solid, self.colorimetry.white_xyz(), c, r0, r);
                let mut trial = vec![0.0; r.len()];
                let (reached, w) = match self.along_normal(c, near, r0, r) {
                    Some(w) => (near, w),
                    None => match warm
                        .then(|| self.on_the_face(c, near, r0, r, &mut trial))
                        .flatten()
                    {
                        Some(w) => (self.solid.xyz(r), w),
                        None => self.onto_reached(near, r0, r, warm),
                    },
                };
                let certificate = match solve {
                    Solve::Outside(u) => Some(u),
                    _ => None,
                };
                (
                    Outcome::Outside {
                        certificate,
                        reached,
                    },
                    w,
                )
            }
        }
    }

    /// The search's own spectrum `r` in the texel form, when it is one: at a vertex or an
    /// edge of the solid (black, the perfect white, the most saturated colours) every band is
    /// 0 or 1 by the sign of aᵢ·n, n the outward normal there (the CIELAB descent direction
    /// from the reached colour `near` towards `c`), and w = t·n reproduces it for t large
    /// enough, float32 rounding included. `None` where a band is left free.
    fn along_normal(&self, c: [f64; 3], near: [f64; 3], r0: &[f64], r: &[f64]) -> Option<[f64; 3]> {
        let n = self.descent(c, near);
        let size = n.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !(size > 0.0 && size.is_finite()) || r.iter().any(|&v| v != 0.0 && v != 1.0) {
            return None;
        }
        // From a dual as large as a projection's to one that saturates the faintest band.
        (0..48)
            .map(|k| n.map(|v| v / size * 2f64.powi(k)))
            .find(|&w| self.keeps_in_f32(r0, w, r))
    }

    /// Jᵀ·(Lab(c) − Lab(near)), J the Jacobian of CIELAB at `near`: the direction in XYZ in
    /// which the distance to `c` falls fastest, an outward normal of the solid at the colour
    /// the search reached.
    fn descent(&self, c: [f64; 3], near: [f64; 3]) -> [f64; 3] {
        use specconv_colour::lab::{xyz_to_lab, xyz_to_lab_jacobian};
        let white = self.colorimetry.white_xyz();
        let (lab, j) = xyz_to_lab_jacobian(near, white);
        let target = xyz_to_lab(c, white);
        [0, 1, 2].map(|k| (0..3).map(|row| j[row][k] * (target[row] - lab[row])).sum())
    }

    /// The search's own spectrum `r` in the texel form on a face or an edge of the solid (two
    /// or one bands free, the others at 0 or 1), in closed form: w = w_F + λ·n, where w_F (in
    /// the span of the free bands' columns) gives the free bands their values, n is normal to
    /// those columns on the outward side ([`Bounded::descent`]), and λ a little above the
    /// least that keeps every other band at its bound (within the largest that does). The colour is
    /// the search's own, so nothing is given up to a pull (issue 45: one pass over the bands
    /// instead of dozens of trial projections). `r` becomes clip(r₀ + Aᵀw, 0, 1) (`trial`:
    /// scratch); `None`, `r` unchanged, where no λ keeps the bounds or float32 w does not keep
    /// the spectrum ([`Bounded::keeps_in_f32`]): then the pull decides ([`Bounded::onto_reached`]).
    fn on_the_face(
        &self,
        c: [f64; 3],
        near: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        trial: &mut [f64],
    ) -> Option<[f64; 3]> {
        let m = self.descent(c, near);
        let cols = self.solid.columns();
        let mut free = [0usize; 2];
        let mut count = 0;
        for (i, &v) in r.iter().enumerate() {
            if v > 0.0 && v < 1.0 {
                *free.get_mut(count)? = i;
                count += 1;
            }
        }
        let (n, wf) = match count {
            2 => {
                let (a, b) = (cols[free[0]], cols[free[1]]);
                let mut n = cross(a, b);
                if dot(n, m) < 0.0 {
                    n = n.map(|v| -v);
                }
                let (g00, g01, g11) = (dot(a, a), dot(a, b), dot(b, b));
                let (da, db) = (r[free[0]] - r0[free[0]], r[free[1]] - r0[free[1]]);
                let det = g00 * g11 - g01 * g01;
                if det.is_nan() || det <= 0.0 {
                    return None;
                }
                let (s, t) = ((da * g11 - db * g01) / det, (db * g00 - da * g01) / det);
                (n, [0, 1, 2].map(|k| s * a[k] + t * b[k]))
            }
            1 => {
                let a = cols[free[0]];
                let g = dot(a, a);
                if g.is_nan() || g <= 0.0 {
                    return None;
                }
                let (d, e) = (dot(m, a) / g, (r[free[0]] - r0[free[0]]) / g);
                (
                    [0, 1, 2].map(|k| m[k] - d * a[k]),
                    [0, 1, 2].map(|k| e * a[k]),
                )
            }
            _ => return None,
        };
        let (lo, hi) = Self::lambda_range(cols, r0, r, n, wf)?;
        // Float32 w moves the free bands by |aᵢ|·|w|·2⁻²⁴, so λ is kept small, and the bands
        // held at a bound by a margin: (1 + 4ᵏ·2⁻¹⁴)·λ_least, k = 0…8, the first that holds.
        let (mut last, mut margin) = (f64::NAN, 1.0 / 16384.0);
        for _ in 0..9 {
            let f = 1.0 + margin;
            margin *= 4.0;
            let lambda = if f * lo > hi { 0.5 * (lo + hi) } else { f * lo };
            if lambda == last {
                continue;
            }
            last = lambda;
            let w = [0, 1, 2].map(|k| wf[k] + lambda * n[k]);
            for ((v, a), &p) in trial.iter_mut().zip(cols).zip(r0) {
                *v = (p + a[0] * w[0] + a[1] * w[1] + a[2] * w[2]).clamp(0.0, 1.0);
            }
            if self.keeps_in_f32(r0, w, trial) {
                r.copy_from_slice(trial);
                return Some(w);
            }
        }
        None
    }

    /// The λ ≥ 0 for which w_F + λ·n keeps every band of `r` at 0 or 1 there ([`Bounded::on_the_face`]):
    /// band i at bound b stays there while λ·(aᵢ·n) is on b's side of b − (r₀ᵢ + aᵢ·w_F).
    fn lambda_range(
        cols: &[[f64; 3]],
        r0: &[f64],
        r: &[f64],
        n: [f64; 3],
        wf: [f64; 3],
    ) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
        for ((a, &p), &v) in cols.iter().zip(r0).zip(r) {
            if v > 0.0 && v < 1.0 {
                continue;
            }
            let z = p + a[0] * wf[0] + a[1] * wf[1] + a[2] * wf[2];
            let g = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
            let (held, need) = if v == 1.0 {
                (z >= 1.0, 1.0 - z)
            } else {
                (z <= 0.0, -z)
            };
            let outward = if v == 1.0 { g > 0.0 } else { g < 0.0 };
            if held {
                if !outward && g != 0.0 {
                    hi = hi.min(need / g);
                }
            } else if outward {
                lo = lo.max(need / g);
            } else {
                return None;
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// The spectrum of an outside colour in the form of every other, clip(r₀ + Aᵀw, 0, 1): `r0`
    /// projected onto the colour `near` reached ([`nearest`]), drawn towards the grey of its
    /// luminance by the least fraction of [`PULLS`] for which the projection is solved and w
    /// rounded to float32 (as a compact texel stores it) still gives its spectrum within
    /// [`DUAL_F32_TOLERANCE`]. A colour of the surface is reached only as w → ∞, and the bands
    /// the clip leaves free lose |aᵢ|·|w|·2⁻²⁴ to the rounding. Returns the colour and w (w = 0
    /// and r₀ clipped if no pull solves).
    ///
    /// `warm` (issue 45): each trial starts from the last solved trial's w, a few Newton steps
    /// instead of dozens for a colour a hair inside the surface (w large); a warm trial that
    /// fails unsolved, or where w is not unique (fewer than three free bands), is tried again
    /// from 0. Without `warm` every trial starts from 0, the method before
    /// ([`Bounded::bound_reference`]). The two answers differ where the cold trials' passes
    /// hang on rounding (tested within a stated tolerance: `warm_started_outside_search_…`).
    fn onto_reached(
        &self,
        near: [f64; 3],
        r0: &[f64],
        r: &mut [f64],
        warm: bool,
    ) -> ([f64; 3], [f64; 3]) {
        // The grey of the same luminance, inside the solid: only chroma is given up.
        let white = self.colorimetry.white_xyz();
        let grey = white.map(|v| v * (near[1] / white[1]).clamp(0.0, 1.0));
        let mut trial = vec![0.0; r.len()];
        let mut start = [0.0; 3];
        let mut found = None;
        for t in PULLS {
            let x = [0, 1, 2].map(|i| near[i] + t * (grey[i] - near[i]));
            let (mut solve, mut w) =
                self.solid
                    .project_dual_from(x, r0, &mut trial, MAX_DUAL_STEPS, start);
            let mut ok = solve == Solve::Solved && self.keeps_in_f32(r0, w, &trial);
            // A warm start that fails where w is not unique (fewer than three free bands) or
            // not reached: the cold start decides, as before.
            if !ok && start != [0.0; 3] && (solve != Solve::Solved || free_bands(&trial) < 3) {
                (solve, w) = self.solid.project_dual(x, r0, &mut trial, MAX_DUAL_STEPS);
                ok = solve == Solve::Solved && self.keeps_in_f32(r0, w, &trial);
            }
            if ok {
                r.copy_from_slice(&trial);
                found = Some(w);
                break;
            }
            if warm && solve == Solve::Solved {
                start = w;
            }
        }
        match found {
            Some(w) => (self.solid.xyz(r), w),
            None => {
                // The clipped spectrum keeps the texel form.
                r.iter_mut()
                    .zip(r0)
                    .for_each(|(v, &x)| *v = x.clamp(0.0, 1.0));
                (self.solid.xyz(r), [0.0; 3])
            }
        }
    }

    /// Whether clip(r₀ + Aᵀw, 0, 1) with w rounded to float32 is `r` within
    /// [`DUAL_F32_TOLERANCE`] of each band's value.
    fn keeps_in_f32(&self, r0: &[f64], w: [f64; 3], r: &[f64]) -> bool {
        let w32 = w.map(|v| f64::from(v as f32));
        let cols = self.solid.columns();
        r0.iter().zip(cols).zip(r).all(|((&p, a), &v)| {
            let z = p + a[0] * w32[0] + a[1] * w32[1] + a[2] * w32[2];
            (z.clamp(0.0, 1.0) - v).abs() <= DUAL_F32_TOLERANCE * v.max(1.0 / 16384.0)
        })
    }

    /// The policy before the CIELAB search, kept as the reference it is measured against: the
    /// farthest colour on g → c inside the solid (g: the grey of c's luminance, clamped to
    /// [0, 1]; bisection on the segment, 16 steps) and its projection of `r0` into `r`.
    pub fn towards_grey(&self, c: [f64; 3], r0: &[f64], r: &mut [f64]) -> [f64; 3] {
        let luminance = c[1].clamp(0.0, 1.0);
        let g = self.colorimetry.white_xyz().map(|w| w * luminance);
        let at = |t: f64| [0, 1, 2].map(|k| g[k] + t * (c[k] - g[k]));
        // t = 0 is the grey spectrum itself, in range with colour g.
        r.iter_mut().for_each(|v| *v = luminance);
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut trial = vec![0.0; r.len()];
        for _ in 0..16 {
            let t = 0.5 * (lo + hi);
            // Few dual steps: a trial that does not settle counts as outside (t only shrinks).
            match self.solid.project_within(at(t), r0, &mut trial, 12) {
                Solve::Solved => {
                    lo = t;
                    r.copy_from_slice(&trial);
                }
                Solve::Outside(_) | Solve::Unresolved => hi = t,
            }
        }
        at(lo)
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

    fn uplift_f32_tallied(&self, xyz: &[f32], out: &mut [f32], tally: &mut Tally) {
        tally.bounded += self.uplift_f32_counted(xyz, out);
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
/// min ½‖r − r0‖² subject to A·r = c and 0 ≤ r ≤ 1 for the rows `a` of A, into `r`: as
/// [`Solid::project`], for one-off calls (a [`Bounded`] keeps its [`Solid`]).
pub fn project(a: &[Vec<f64>; 3], c: [f64; 3], r0: &[f64], r: &mut [f64]) -> Solve {
    Solid::new(a).project(c, r0, r)
}
