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
//! outside. Then the result is r₀ projected onto the colour of the solid's surface nearest to
//! c in CIELAB ([`nearest`]), with the colour a penalty of weight [`REGULARISATION`] rather
//! than a constraint, so that the spectrum is continuous in c ([`Bounded::bound_dual`]).
//!
//! The perfect white is a vertex of the solid, and the only reflectance with its colour is
//! r ≡ 1. A colour within [`Bounded::white_tolerance`] of it, or a grey brighter than it at
//! that tolerance, is that vertex ([`Bounded::white`]): r ≡ 1 exactly, for a few compares,
//! before any other test. The tolerance is the colour's own rounding: float32's, and the gap
//! between the D65 white of the RGB spaces (xy 0.3127, 0.3290, OpenColorIO's) and the
//! tabulated D65's (3.7·10⁻⁴ in Z on the default grid), by which sRGB (1, 1, 1) lands a hair
//! outside the solid.

pub use specconv_colour::solid::{nearest, Solid, Solve, DUAL_STEPS};

use crate::error::Error;
use crate::method::Tally;
use crate::Method;
use specconv_colour::rgb::SRGB;
use specconv_colour::{Colorimetry, Grid};

/// What [`Bounded`] did with one colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// The method's spectrum was already in [0, 1]; returned unchanged.
    InRange,
    /// Projected: the nearest spectrum in [0, 1] with the input XYZ.
    Projected,
    /// No spectrum in [0, 1] has this colour: `certificate` u has u·c > h(u) (`None` when the
    /// solve ended on the solid's surface without a certificate). The spectrum returned is r₀
    /// projected onto the colour nearest to the input in CIELAB ([`nearest`]), the colour a
    /// penalty; `reached` is its colour.
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

/// The penalty weight of an outside colour's projection onto the colour reached
/// (`Bounded::onto_reached`), as a fraction of trace(A·Aᵀ): small enough that the spectrum's
/// colour stays near the colour reached (0.018 ΔE76 at most on the wide-gamut cubes' outside
/// colours, 0.27 on hostile ones), large enough that neighbouring colours get neighbouring
/// spectra (docs/hard-inputs.md, "Continuity near the
/// surface of the solid": 10⁻⁷ lets the step where the solid's surface is crossed jump, 10⁻¹⁰
/// leaves steps of 0.44 ΔE00 under F11 between neighbours).
pub const REGULARISATION: f64 = 1e-9;

/// Newton steps of an outside colour's regularised projection (it converges in far fewer).
pub const REGULARISED_STEPS: usize = 200;

/// Relative rounding of a colour converted to XYZ in float32 (a few units in the last place of
/// a 3×3 product), which [`Bounded::white_tolerance`] allows beside the gap between two D65s.
pub const WHITE_ROUNDING: f64 = 16.0 * f32::EPSILON as f64;

/// The largest relative gap between the RGB spaces' D65 white and the colorimetry's white that
/// counts as two definitions of one white (3.7·10⁻⁴ on the default grid); a white farther off
/// is another illuminant's, and no rounding of this one.
pub const SAME_WHITE: f64 = 1e-3;

/// A method whose spectra are kept in [0, 1] with their XYZ unchanged (see the module).
#[derive(Clone)]
pub struct Bounded<M> {
    inner: M,
    colorimetry: Colorimetry,
    solid: Solid,
    /// A·1, the perfect white's colour, and the relative distance that is still it.
    white: [f64; 3],
    white_tolerance: f64,
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
        let white = colorimetry.white_xyz();
        Ok(Bounded {
            inner,
            solid: Solid::new(&colorimetry.weights),
            white_tolerance: white_tolerance(white),
            white,
            colorimetry,
            name,
        })
    }

    /// The relative distance from the perfect white within which a colour is that white:
    /// [`WHITE_ROUNDING`] plus twice the gap between the RGB spaces' D65 white and A·1, where
    /// that gap is below [`SAME_WHITE`].
    pub fn white_tolerance(&self) -> f64 {
        self.white_tolerance
    }

    /// Whether `c` is the perfect white (see the module): with q = c ⊘ A·1 per component, the
    /// smallest q is at least 1 − τ and the spread of q at most τ times the largest, τ the
    /// [`Bounded::white_tolerance`]. A grey brighter than white is white by this rule too,
    /// which is the colour of the solid nearest to it.
    pub fn is_white(&self, c: [f64; 3]) -> bool {
        let q = [0, 1, 2].map(|k| c[k] / self.white[k]);
        let (lo, hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        lo >= 1.0 - self.white_tolerance && hi - lo <= self.white_tolerance * hi
    }

    /// The perfect white's spectrum in the texel form, r = clip(r₀ + Aᵀw, 0, 1) ≡ 1 into `r`,
    /// when `c` [`Bounded::is_white`]: w = (0, t, 0), t twice what lifts the band of least ȳ
    /// weight to 1, so that a decoder's r₀ of the stored colour reaches 1 too. Returns w, or
    /// `None` where c is not white (or a band has no ȳ weight to lift it by, on a grid past
    /// the observer's range; such a colour is bounded as any other).
    pub fn white(&self, c: [f64; 3], r0: &[f64], r: &mut [f64]) -> Option<[f64; 3]> {
        if !self.is_white(c) {
            return None;
        }
        let mut t = 0.0f64;
        for (col, &v) in self.solid.columns().iter().zip(r0) {
            if v < 1.0 {
                if col[1] <= 0.0 || col[1].is_nan() {
                    return None;
                }
                t = t.max((1.0 - v) / col[1]);
            }
        }
        let w = [0.0, f64::from((2.0 * t) as f32), 0.0];
        self.solid.texel_form(r0, w, r);
        r.iter().all(|&v| v == 1.0).then_some(w)
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
            let c64 = [c[0], c[1], c[2]].map(f64::from);
            if !finite {
                counts.not_finite += 1;
            } else if self.is_white(c64) {
                // White first: its spectrum may be in range and still not r ≡ 1.
                self.inner.uplift_f64(&c64, r);
                counts.add(&self.bound(c64, r));
                for (o, v) in o.iter_mut().zip(r.iter()) {
                    *o = *v as f32;
                }
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
        if c.iter().any(|v| !v.is_finite()) {
            return (Outcome::NotFinite, [0.0; 3]);
        }
        let in_range = r.iter().all(|v| (0.0..=1.0).contains(v));
        let white = self.is_white(c) && !r.iter().all(|&v| v == 1.0);
        if in_range && !white {
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
        if white {
            if let Some(w) = self.white(c, r0, r) {
                // Brighter than white beyond the tolerance: outside, and y certifies it.
                let outcome = if c[1] > self.white[1] * (1.0 + self.white_tolerance) {
                    Outcome::Outside {
                        certificate: Some([0.0, 1.0, 0.0]),
                        reached: self.white,
                    }
                } else {
                    Outcome::Projected
                };
                return (outcome, w);
            }
            r.copy_from_slice(r0);
            if in_range {
                return (Outcome::InRange, [0.0; 3]);
            }
        }
        match self.solid.project_dual(c, r0, r, DUAL_STEPS) {
            (Solve::Solved, w) => (Outcome::Projected, w),
            (solve, _) => {
                let near =
                    nearest::nearest_lab(&self.solid, self.colorimetry.white_xyz(), c, r0, r);
                let w = self.onto_reached(near, r0, r);
                let reached = self.solid.xyz(r);
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

    /// The spectrum of an outside colour in the form of every other, clip(r₀ + Aᵀw, 0, 1): `r0`
    /// projected onto the colour `near` reached ([`nearest`]) with the colour a penalty
    /// ([`Solid::project_regularised`], weight [`REGULARISATION`]), w rounded to float32 and
    /// the spectrum made from that w. A colour of the surface is reached exactly only as
    /// w → ∞, and an exact projection onto a colour a hair inside swings the bands of least
    /// colour weight with the depth: neighbouring colours got spectra 4 ΔE00 apart under F11.
    /// The penalty keeps w bounded and the spectrum continuous in the colour; float32 w is
    /// what a compact texel stores, so the texel is this spectrum to the bit. Returns w (0, and
    /// r₀ clipped, where the projection does not settle).
    fn onto_reached(&self, near: [f64; 3], r0: &[f64], r: &mut [f64]) -> [f64; 3] {
        // Unresolved (a huge r₀, an HDR colour's, projected onto a vertex stalls on Ψ's
        // rounding): its last w is still in the texel form, and nearer than r₀ clipped.
        let (_, w) = self
            .solid
            .project_regularised(near, r0, r, REGULARISATION, REGULARISED_STEPS);
        let w = if w.iter().all(|v| v.is_finite()) {
            w.map(|v| f64::from(v as f32))
        } else {
            [0.0; 3]
        };
        self.solid.texel_form(r0, w, r);
        w
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

/// [`Bounded::white_tolerance`] for the perfect white `white` (A·1).
fn white_tolerance(white: [f64; 3]) -> f64 {
    let d65 = SRGB.white_xyz();
    let gap = (0..3).fold(0.0f64, |m, k| m.max((d65[k] / white[k] - 1.0).abs()));
    WHITE_ROUNDING + if gap < SAME_WHITE { 2.0 * gap } else { 0.0 }
}

/// Boxed methods, as the command line builds them by name, are methods too, so that any of
/// them can be bounded.
/// min ½‖r − r0‖² subject to A·r = c and 0 ≤ r ≤ 1 for the rows `a` of A, into `r`: as
/// [`Solid::project`], for one-off calls (a [`Bounded`] keeps its [`Solid`]).
pub fn project(a: &[Vec<f64>; 3], c: [f64; 3], r0: &[f64], r: &mut [f64]) -> Solve {
    Solid::new(a).project(c, r0, r)
}
