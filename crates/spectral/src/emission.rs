//! Emission: radiance spectra of any brightness (HDR, light sources, emissive textures) from
//! their colour, through any reflectance uplift [`Method`], as the paper's Section 7 suggests:
//! scale the colour into range, uplift, scale back.
//!
//! The input c is the XYZ of emitted radiance on the scale of every input colour (OCIO's
//! CIE-XYZ-D65: a scene-linear (1, 1, 1) has Y = 1). The output L is a spectrum whose XYZ under
//! the observer alone, with no illuminant, is c, in one of the [`EmissionUnits`] conventions
//! ([`EmissionSetting`]; the reference one: XYZₑ(L) = Σ L·x̄ over the observer's 1 nm table,
//! L interpolated onto it, as the spectral EXR layout's reference implementation reads it).
//! [`Emissive::new`] keeps the model's own band sums instead, XYZₑ(L) = Σ L·x̄ / Σ ȳ.
//! Reflectances have A·r = XYZₑ(ℓ∘r) for a light ℓ proportional to the model's illuminant I
//! (A: the setting's reflectance colorimetry, whose white has Y = 1), and
//!
//!   m = 2·max(|X|/X_w, |Y|/Y_w, |Z|/Z_w)   (X_w, Y_w = 1, Z_w: the perfect reflector's colour)
//!   u = c / (m·2ᵏ),   L = m·2ᵏ · ℓ ∘ r(u)
//!
//! has XYZₑ(L) = c exactly wherever the method gives u its colour (A·r(u) = u). u fits half
//! the white's box, [0, X_w/2] × [0, 1/2] × [0, Z_w/2]: the paper's [0, 1]³ in units of the
//! white, halved to stay off the top of the object-colour solid, where only r = 1 has the
//! white's colour and the bounded spectra of nearby colours are forced into blocks; a grey
//! emission is the illuminant's spectrum times the method's reflectance of a mid grey. k = 0
//! unless the method misses u's colour — a bounded method cannot reach colours outside the
//! solid, which some bright saturated colours are — then u is halved until it is reached
//! (k ≤ [`HALVINGS`]): every chromaticity inside the spectral locus is inside the solid once
//! dark enough.
//!
//! Shape does not depend on brightness: m(t·c) = t·m(c) for t > 0, so u, k and r(u) are the
//! same for t·c as for c and L(t·c) = t·L(c), bit for bit when t is a power of two and to
//! rounding otherwise. L ≥ 0 wherever r(u) ≥ 0: for every colour with a bounded method.
//!
//! | input | outcome |
//! |---|---|
//! | NaN or ±Inf in any component | NaN in every band (callers count these) |
//! | black, (0, 0, 0) | the zero spectrum |
//! | any other finite colour the method reproduces at some k | L with XYZₑ(L) = c |
//! | no k reproduces it (xy outside the spectral locus, negative luminance) | L of the last k, counted as *unmatched*: its colour is the one the method reached (bounded: non-negative, the colour nearest in CIELAB that a reflectance can have, see [`crate::bounded`]); unbounded methods always match, with negative bands |
//! | components up to the largest finite value | u from c/m cannot overflow; L saturates at ± the output type's largest finite value |

use crate::error::Error;
use crate::method::Tally;
use crate::Method;
use specconv_colour::{Colorimetry, EmissionUnits, Grid, Illuminant, Integration};

/// Most halvings of a colour the method misses: down to 2⁻⁹ of the white's box (the bounded
/// uplift's error on colours at the spectral locus stops shrinking after about six).
pub const HALVINGS: u32 = 8;

/// Largest error of A·r(u) against u, relative to u's largest component, that counts as a
/// match: well above the f32 uplift's rounding, well below any colour a bounded method moves.
const MATCH: f64 = 2e-5;

/// XYZₑ of emission spectra in the model's band sums: the observer alone, normalised so that a
/// flat L = 1 has Y = 1 (illuminant E, whose spectrum is 1 in every band).
pub fn emission_colorimetry(
    grid: Grid,
    observer: specconv_colour::Observer,
) -> Result<Colorimetry, Error> {
    Ok(Colorimetry::new(grid, observer, Illuminant::E)?)
}

/// A reflectance method turned into an emission method (see the module).
pub struct Emissive<M> {
    inner: M,
    colorimetry: Colorimetry,
    /// Per band, (Σ ȳ / Σ I·ȳ)·I: the factor from reflectance to emission.
    light: Vec<f64>,
    /// The perfect reflector's XYZ: the box colours are scaled into.
    white: [f64; 3],
    name: String,
}

/// Emission in one of the [`EmissionUnits`] on a grid, and the reflectance setting whose
/// exact uplift gives it: with `reflectance` A and `light` ℓ, A·r = E·(ℓ∘r) for the emission's
/// weights E, so a method exact under A (wrap it in [`crate::resample::Resampled`] to make it
/// so) gives emission exact under E.
#[derive(Debug, Clone)]
pub struct EmissionSetting {
    /// The convention S0 values are written in.
    pub units: EmissionUnits,
    /// XYZ of S0 as every reader integrates it (the layout's reference, scaled by the units).
    pub emission: Integration,
    /// Per band, ℓ = I / Σ_b E_Y·I: the illuminant, scaled so that A's white has Y = 1.
    pub light: Vec<f64>,
    /// A = E·diag(ℓ): the colorimetry of reflectances lit by ℓ.
    pub reflectance: Colorimetry,
}

impl EmissionSetting {
    /// On `grid`, seen by `observer`, shaped by `illuminant` (the model's: a grey emits it).
    pub fn new(
        grid: Grid,
        observer: specconv_colour::Observer,
        illuminant: Illuminant,
        units: EmissionUnits,
    ) -> Result<EmissionSetting, Error> {
        let emission = units.integration(&grid.wavelengths(), observer)?;
        let spd = illuminant.spd(&grid)?;
        let lit: f64 = emission.weights[1]
            .iter()
            .zip(&spd)
            .map(|(e, i)| e * i)
            .sum();
        if lit <= 0.0 || !lit.is_finite() {
            return Err(Error::Grid(format!(
                "the grid {grid} sees no light of {illuminant} with {observer}"
            )));
        }
        let light: Vec<f64> = spd.iter().map(|i| i / lit).collect();
        let weights = emission
            .weights
            .each_ref()
            .map(|e| e.iter().zip(&light).map(|(e, l)| e * l).collect());
        Ok(EmissionSetting {
            units,
            emission,
            light,
            reflectance: Colorimetry {
                grid,
                observer,
                illuminant,
                weights,
            },
        })
    }
}

impl<M: Method> Emissive<M> {
    /// Wraps `inner`, whose spectra are reflectances with colour A·r in `colorimetry` (the
    /// model's), on the same grid; emission in the model's band sums, Σ L·x̄ / Σ ȳ.
    pub fn new(inner: M, colorimetry: Colorimetry) -> Result<Emissive<M>, Error> {
        let spd = colorimetry.illuminant.spd(&colorimetry.grid)?;
        let ybar = &colorimetry.observer.cmfs(&colorimetry.grid)?[1];
        let lit: f64 = spd.iter().zip(ybar).map(|(i, y)| i * y).sum();
        let seen: f64 = ybar.iter().sum();
        let light = spd.iter().map(|i| i * seen / lit).collect();
        Emissive::lit(inner, colorimetry, light)
    }

    /// Wraps `inner`, exact under `setting.reflectance`: emission exact in its units.
    pub fn in_setting(inner: M, setting: &EmissionSetting) -> Result<Emissive<M>, Error> {
        Emissive::lit(inner, setting.reflectance.clone(), setting.light.clone())
    }

    /// Emission L = m·2ᵏ·ℓ∘r(u), where A·r is the colour of r lit by ℓ.
    fn lit(inner: M, colorimetry: Colorimetry, light: Vec<f64>) -> Result<Emissive<M>, Error> {
        if inner.grid() != colorimetry.grid {
            return Err(Error::Grid(format!(
                "the method's grid {} is not the colorimetry's {}",
                inner.grid(),
                colorimetry.grid
            )));
        }
        let name = format!("{}+emissive", inner.name());
        Ok(Emissive {
            white: colorimetry.white_xyz(),
            inner,
            colorimetry,
            light,
            name,
        })
    }

    /// The wrapped reflectance method.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// As [`Method::uplift_f64`]; returns the number of unmatched colours.
    pub fn uplift_f64_counted(&self, xyz: &[f64], out: &mut [f64]) -> usize {
        self.run(xyz, out, |u, r| self.inner.uplift_f64(u, r))
    }

    /// As [`Method::uplift_f32`]; returns the number of unmatched colours.
    pub fn uplift_f32_counted(&self, xyz: &[f32], out: &mut [f32]) -> usize {
        self.run(xyz, out, |u, r| self.inner.uplift_f32(u, r))
    }

    /// The scale m of a finite colour (0 for black).
    fn scale(&self, c: [f64; 3]) -> f64 {
        2.0 * (0..3).fold(0.0f64, |m, k| m.max(c[k].abs() / self.white[k]))
    }

    /// Whether the spectrum r has the colour u (see [`MATCH`]).
    fn matches<T: Real>(&self, u: &[T], r: &[T]) -> bool {
        let size = u.iter().fold(0.0f64, |m, v| m.max(v.to_f64().abs()));
        self.colorimetry.weights.iter().zip(u).all(|(w, uk)| {
            let got: f64 = w.iter().zip(r).map(|(a, v)| a * v.to_f64()).sum();
            (got - uk.to_f64()).abs() <= MATCH * size
        })
    }

    fn run<T: Real>(&self, xyz: &[T], out: &mut [T], uplift: impl Fn(&[T], &mut [T])) -> usize {
        let n = self.colorimetry.bands();
        // Per colour: m·2ᵏ; NaN for non-finite colours, 0 for black.
        let mut scale: Vec<f64> = Vec::with_capacity(xyz.len() / 3);
        let mut u: Vec<T> = Vec::with_capacity(xyz.len());
        for c in xyz.chunks_exact(3) {
            let c = [c[0].to_f64(), c[1].to_f64(), c[2].to_f64()];
            let m = if c.iter().all(|v| v.is_finite()) {
                self.scale(c)
            } else {
                f64::NAN
            };
            scale.push(m);
            let ok = m > 0.0;
            u.extend(c.map(|v| T::from_f64(if ok { v / m } else { 0.0 })));
        }
        uplift(&u, out);
        let mut pending: Vec<usize> = (0..scale.len())
            .filter(|&i| {
                scale[i] > 0.0 && !self.matches(&u[3 * i..3 * i + 3], &out[n * i..n * (i + 1)])
            })
            .collect();
        let (mut ub, mut rb) = (Vec::new(), Vec::new());
        for _ in 0..HALVINGS {
            if pending.is_empty() {
                break;
            }
            ub.clear();
            for &i in &pending {
                scale[i] *= 2.0;
                ub.extend(
                    u[3 * i..3 * i + 3]
                        .iter()
                        .map(|v| T::from_f64(v.to_f64() * 0.5)),
                );
            }
            rb.resize(pending.len() * n, T::from_f64(0.0));
            uplift(&ub, &mut rb);
            for (j, &i) in pending.iter().enumerate() {
                u[3 * i..3 * i + 3].copy_from_slice(&ub[3 * j..3 * j + 3]);
                out[n * i..n * (i + 1)].copy_from_slice(&rb[n * j..n * (j + 1)]);
            }
            pending.retain(|&i| !self.matches(&u[3 * i..3 * i + 3], &out[n * i..n * (i + 1)]));
        }
        for (s, l) in scale.iter().zip(out.chunks_exact_mut(n)) {
            for (v, light) in l.iter_mut().zip(&self.light) {
                *v = T::from_f64(match *s {
                    s if s > 0.0 => v.to_f64() * light * s,
                    0.0 => 0.0,
                    _ => f64::NAN,
                });
            }
        }
        pending.len()
    }
}

/// f32 and f64 as the uplift sees them: into f64 exactly, back saturating (finite stays finite).
trait Real: Copy {
    fn to_f64(self) -> f64;
    fn from_f64(v: f64) -> Self;
}

impl Real for f32 {
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn from_f64(v: f64) -> f32 {
        v.clamp(-(f32::MAX as f64), f32::MAX as f64) as f32
    }
}

impl Real for f64 {
    fn to_f64(self) -> f64 {
        self
    }
    fn from_f64(v: f64) -> f64 {
        v.clamp(-f64::MAX, f64::MAX)
    }
}

impl<M: Method> Method for Emissive<M> {
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

    // The inner method's own counts are of scaled trial colours, not the caller's: dropped.
    fn uplift_f32_tallied(&self, xyz: &[f32], out: &mut [f32], tally: &mut Tally) {
        tally.unmatched += self.uplift_f32_counted(xyz, out) as u64;
    }

    fn model_bytes(&self) -> usize {
        self.inner.model_bytes()
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        let m = self.scale(xyz);
        (m > 0.0 && m.is_finite())
            .then(|| self.inner.cluster_of(xyz.map(|v| v / m)))
            .flatten()
    }
}
