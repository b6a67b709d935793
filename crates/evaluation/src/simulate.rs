//! Colour shift through interreflection: spectral radiosity of small scenes, once per uplift
//! method and once with measured spectra, compared in CIEDE2000 (the paper's Fig. 1, 11, 12).
//!
//! Every patch is Lambertian with one reflectance ρ_i(λ). Per wavelength the radiosity solves
//! B = E + ρ·F·B, with E the light emitted by each patch and F the form factors (row i: the
//! share of light leaving patch i that reaches each patch j). The simulator computes only what
//! the scene asks for:
//!
//! - `Effect::Bounces(K)`: the series truncated after K reflections, B_K = Σ_{k=0..K} (ρF)^k E,
//!   evaluated as B_k = E + ρ·F·B_{k−1} (Jacobi), so every count 0..=K comes for free;
//! - `Effect::Converged`: (I − ρF)⁻¹·E, when the series converges (spectral radius below 1).
//!
//! Materials enter as a texture would store them: the tristimulus colour (in the model's
//! colorimetry, white Y = 1) of a measured spectrum or of a colour in an RGB space. Each method
//! uplifts that colour; the reference renders the measured spectrum itself, and "plain RGB
//! multiplication" renders the same colours in linear Rec.709 with three bands, as an RGB
//! renderer does. Radiance becomes XYZ with the observer's colour-matching functions alone (the
//! light's spectrum is the light), and CIELAB takes as white what a perfectly white scene gives at
//! the same patch and bounce count: a white wall reads L* = 100 in the light of the scene.

use crate::error::Error;
use nalgebra::{DMatrix, DVector};
use specconv_colour::Colorimetry;
use specconv_colour::{lab::ciede2000, lab::xyz_to_lab};
use specconv_colour::{mat3::mul_vec as apply, rgb::srgb_encode, rgb::SRGB};
use specconv_spectral::Method;

/// What the simulation computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// The bounce series up to K reflections (K = 0: emitted light only, K = 1: direct light).
    Bounces(usize),
    /// The converged solution (I − ρF)⁻¹·E.
    Converged,
}

/// A patch's material as the texture would store it.
#[derive(Debug, Clone, PartialEq)]
pub enum Material {
    /// A colour: XYZ in the model's colorimetry (white Y = 1). No measured reference.
    Colour([f64; 3]),
    /// A measured reflectance on the grid; its colour is what the methods uplift.
    Measured(Vec<f64>),
}

/// A light: a relative spectral power distribution on the grid, scaled by `power`, emitted by
/// the patches it names.
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    /// The light's name in reports.
    pub name: String,
    /// Relative spectral power on the grid, one value per band (finite, ≥ 0).
    pub spd: Vec<f64>,
    /// The factor on `spd` (finite, ≥ 0).
    pub power: f64,
    /// Indices of the patches that emit it.
    pub patches: Vec<usize>,
}

/// A scene: patches, the form factors between them, lights, and the effect wanted.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The patches' names, one per material.
    pub names: Vec<String>,
    /// One material per patch.
    pub materials: Vec<Material>,
    /// n×n, row-major by patch: `form_factors[i][j]` is F_ij.
    pub form_factors: Vec<Vec<f64>>,
    /// The lights; at least one.
    pub lights: Vec<Light>,
    /// Bounce counts or the converged solution.
    pub effect: Effect,
}

/// The most memory the bounce snapshots of one simulation may take.
pub const MEMORY_LIMIT: usize = 1 << 30;

/// The largest scene solved by `Effect::Converged` with coupled patches (an n³ solve per band).
pub const CONVERGED_MAX_PATCHES: usize = 512;

/// Form factors of the `furnace` preset: every patch a closed sphere of its own material, so it
/// sees only itself (F = I) and the series per patch is E·Σ ρ^k.
pub fn furnace(patches: usize) -> Vec<Vec<f64>> {
    (0..patches)
        .map(|i| (0..patches).map(|j| f64::from(u8::from(i == j))).collect())
        .collect()
}

/// The walls of the `box` preset, in the order of [`room`]'s rows.
pub const BOX_WALLS: [&str; 5] = ["floor", "ceiling", "back", "left", "right"];

/// Form factors of the `box` preset: a unit cube with its front face open (floor, ceiling,
/// back, left and right walls). Adjacent walls exchange [`perpendicular`]`(1, 1, 1)`, opposite
/// walls [`parallel`]`(1, 1, 1)`; the open front takes the rest of each row.
pub fn room() -> Vec<Vec<f64>> {
    let adj = perpendicular(1.0, 1.0, 1.0);
    let opp = parallel(1.0, 1.0, 1.0);
    // floor–ceiling and left–right face each other; the back wall faces the open front.
    let opposite = |a: usize, b: usize| matches!((a.min(b), a.max(b)), (0, 1) | (3, 4));
    (0..5)
        .map(|i| {
            (0..5)
                .map(|j| match () {
                    _ if i == j => 0.0,
                    _ if opposite(i, j) => opp,
                    _ => adj,
                })
                .collect()
        })
        .collect()
}

/// Form factor between two directly opposed, parallel a×b rectangles at distance c (Howell,
/// "A Catalog of Radiation Heat Transfer Configuration Factors", case C-11).
pub fn parallel(a: f64, b: f64, c: f64) -> f64 {
    use std::f64::consts::PI;
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Form factor from a rectangle of width w to a perpendicular rectangle of height h sharing an
/// edge of length l (Howell, case C-14).
pub fn perpendicular(w: f64, h: f64, l: f64) -> f64 {
    use std::f64::consts::PI;
    let (w, h) = (w / l, h / l);
    let (w2, h2) = (w * w, h * h);
    let s = w2 + h2;
    let log = ((1.0 + w2) * (1.0 + h2) / (1.0 + s)).ln()
        + w2 * (w2 * (1.0 + s) / ((1.0 + w2) * s)).ln()
        + h2 * (h2 * (1.0 + s) / ((1.0 + h2) * s)).ln();
    (w * (1.0 / w).atan() + h * (1.0 / h).atan() - s.sqrt() * (1.0 / s.sqrt()).atan() + 0.25 * log)
        / (PI * w)
}

/// Per-wavelength radiosity of patches with reflectances `rho` (n × bands), emission `e`
/// (n × bands) and form factors `f` (n × n). For `Bounces(K)` the result has K + 1 entries, the
/// radiosity after 0, 1, …, K reflections; for `Converged`, one. Each entry is indexed
/// `[patch][band]`.
///
/// ```
/// use specconv_evaluation::simulate::{furnace, radiosity, Effect};
///
/// // One grey patch (ρ = 0.5, one band) in a furnace, emitting 1: B_K = Σ_{k≤K} 0.5^k.
/// let (rho, e, f) = (vec![vec![0.5]], vec![vec![1.0]], furnace(1));
/// let b = radiosity(&rho, &e, &f, Effect::Bounces(2))?;
/// assert_eq!(b, [[[1.0]], [[1.5]], [[1.75]]]);
/// let b = radiosity(&rho, &e, &f, Effect::Converged)?;
/// assert!((b[0][0][0] - 2.0).abs() < 1e-12);
/// # Ok::<(), specconv_evaluation::Error>(())
/// ```
pub fn radiosity(
    rho: &[Vec<f64>],
    e: &[Vec<f64>],
    f: &[Vec<f64>],
    effect: Effect,
) -> Result<Vec<Vec<Vec<f64>>>, Error> {
    let n = rho.len();
    let bands = e.first().map_or(0, Vec::len);
    // Only the non-zero form factors: the furnace of a thousand chips is diagonal.
    let sparse: Vec<Vec<(usize, f64)>> = f
        .iter()
        .map(|row| {
            row.iter()
                .enumerate()
                .filter(|(_, &v)| v != 0.0)
                .map(|(j, &v)| (j, v))
                .collect()
        })
        .collect();
    match effect {
        Effect::Bounces(k) => {
            let mut out = Vec::with_capacity(k + 1);
            out.push(e.to_vec());
            for _ in 0..k {
                let prev = out.last().expect("starts with E");
                let next: Vec<Vec<f64>> = (0..n)
                    .map(|i| {
                        let mut gathered = vec![0.0; bands];
                        for &(j, fij) in &sparse[i] {
                            for (g, b) in gathered.iter_mut().zip(&prev[j]) {
                                *g += fij * b;
                            }
                        }
                        (0..bands)
                            .map(|l| e[i][l] + rho[i][l] * gathered[l])
                            .collect()
                    })
                    .collect();
                out.push(next);
            }
            Ok(out)
        }
        Effect::Converged => {
            let diagonal = sparse
                .iter()
                .enumerate()
                .all(|(i, row)| row.iter().all(|&(j, _)| j == i));
            if !diagonal && n > CONVERGED_MAX_PATCHES {
                return Err(Error::Scene(format!(
                    "the converged solution of {n} coupled patches needs an {n}×{n} solve per band; \
                     the limit is {CONVERGED_MAX_PATCHES} patches: ask for `bounces = K` instead"
                )));
            }
            let mut b = vec![vec![0.0; bands]; n];
            for l in 0..bands {
                let m = DMatrix::from_fn(n, n, |i, j| rho[i][l] * f[i][j]);
                check_convergence(&m, l)?;
                let a = DMatrix::identity(n, n) - &m;
                let rhs = DVector::from_fn(n, |i, _| e[i][l]);
                let x = if diagonal {
                    DVector::from_fn(n, |i, _| rhs[i] / a[(i, i)])
                } else {
                    a.lu()
                        .solve(&rhs)
                        .ok_or_else(|| Error::Scene(format!("I − ρF is singular in band {l}")))?
                };
                for i in 0..n {
                    b[i][l] = x[i];
                }
            }
            Ok(vec![b])
        }
    }
}

/// The series Σ (ρF)^k converges iff the spectral radius of ρF is below 1. Cheap bound first:
/// the radius is at most max_i Σ_j |ρ_i F_ij|; only when that fails are eigenvalues computed.
fn check_convergence(m: &DMatrix<f64>, band: usize) -> Result<(), Error> {
    let bound = m
        .row_iter()
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if bound < 1.0 {
        return Ok(());
    }
    let radius = m
        .clone()
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    if radius < 1.0 - 1e-12 {
        Ok(())
    } else {
        Err(Error::Scene(format!(
            "the bounce series does not converge in band {band}: the spectral radius of ρ·F is \
             {radius:.6} (a closed scene with reflectance near or above 1); ask for `bounces = K` \
             instead of `converged`"
        )))
    }
}

/// One rendering of the scene: a method's (or the reference's) colour of every patch at every
/// bounce count.
#[derive(Debug, Clone)]
pub struct Rendering {
    /// `otsu2018`, …, `measured` for the reference, `rgb` for plain RGB multiplication.
    pub method: String,
    /// `xyz[count][patch]`: radiance integrated with the observer (not normalised).
    pub xyz: Vec<Vec<[f64; 3]>>,
}

/// Everything a simulation found.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The bounce counts reported: `Some(k)` per count, `None` for the converged solution.
    pub counts: Vec<Option<usize>>,
    /// `white[count][patch]`: XYZ of the same patch in a perfectly white scene, CIELAB's white.
    pub white: Vec<Vec<[f64; 3]>>,
    /// The reference (when every patch is measured), then one per method, then `rgb`.
    pub renderings: Vec<Rendering>,
    /// Whether `renderings[0]` is the measured reference.
    pub has_reference: bool,
}

impl Outcome {
    /// The rendering named `method` (`measured`, `rgb` or a method's name), if there is one.
    pub fn rendering(&self, method: &str) -> Option<&Rendering> {
        self.renderings.iter().find(|r| r.method == method)
    }

    /// CIELAB of `r` at `count` and `patch`, relative to the white scene.
    /// Where no light has reached the patch yet (a wall lit only by bounces, at count 0), the
    /// white scene is black there too, and so is every rendering: L*a*b* = 0.
    pub fn lab(&self, r: &Rendering, count: usize, patch: usize) -> [f64; 3] {
        let white = self.white[count][patch];
        if white[1] > 0.0 {
            xyz_to_lab(r.xyz[count][patch], white)
        } else {
            [0.0; 3]
        }
    }

    /// CIEDE2000 between two renderings at `count` and `patch`.
    pub fn delta_e(&self, a: &Rendering, b: &Rendering, count: usize, patch: usize) -> f64 {
        ciede2000(self.lab(a, count, patch), self.lab(b, count, patch))
    }

    /// Mean CIEDE2000 of `method` from `reference` over all patches, per bounce count.
    pub fn mean_delta_e(&self, method: &str, reference: &str) -> Option<Vec<f64>> {
        let (a, b) = (self.rendering(method)?, self.rendering(reference)?);
        let patches = self.white.first().map_or(0, Vec::len);
        Some(
            (0..self.counts.len())
                .map(|c| {
                    (0..patches).map(|p| self.delta_e(a, b, c, p)).sum::<f64>() / patches as f64
                })
                .collect(),
        )
    }

    /// Display RGB (sRGB-encoded, clipped to [0, 1]) with the white scene's Y as 1: what the
    /// patch looks like on an sRGB display without adaptation to the light.
    pub fn display_rgb(
        &self,
        r: &Rendering,
        count: usize,
        patch: usize,
        a: &Colorimetry,
    ) -> [f64; 3] {
        let to_rgb = SRGB.from_xyz(a.white_xyz());
        let y = self.white[count][patch][1];
        let xyz = r.xyz[count][patch].map(|v| if y > 0.0 { v / y } else { 0.0 });
        apply(&to_rgb, xyz).map(|v| srgb_encode(v.clamp(0.0, 1.0)))
    }
}

/// A surface seen after K interreflections with itself, the preview of a texture: light that
/// has met reflectance r K + 1 times, r^(K+1), under a light; and the same as an RGB renderer
/// computes it. Both are XYZ normalised as [`Colorimetry::xyz`] under the light, so a white
/// surface stays the light's white (Y = 1) for every K.
#[derive(Debug, Clone)]
pub struct SelfBounce {
    texture: Colorimetry,
    light: Colorimetry,
    power: i32,
    to_rgb: [[f64; 3]; 3],
    from_rgb: [[f64; 3]; 3],
    light_rgb: [f64; 3],
}

impl SelfBounce {
    /// `texture` is the colorimetry the texture's colours are defined in (its illuminant:
    /// the RGB renderer's albedo is the colour of r there); `light` the same grid and observer
    /// under the light of the preview.
    pub fn new(
        texture: &Colorimetry,
        light: &Colorimetry,
        bounces: u32,
    ) -> Result<SelfBounce, Error> {
        if texture.grid != light.grid || texture.observer != light.observer {
            return Err(Error::Scene(format!(
                "the texture ({}, {}) and the light ({}, {}) need one grid and observer",
                texture.grid, texture.observer, light.grid, light.observer
            )));
        }
        let power = i32::try_from(bounces)
            .ok()
            .and_then(|k| k.checked_add(1))
            .ok_or_else(|| Error::Scene(format!("{bounces} bounces are too many")))?;
        // Linear Rec.709 whose (1, 1, 1) is the texture's white: a white albedo is 1.
        let white = texture.white_xyz();
        let (to_rgb, from_rgb) = (SRGB.from_xyz(white), SRGB.to_xyz(white));
        Ok(SelfBounce {
            texture: texture.clone(),
            light: light.clone(),
            power,
            to_rgb,
            from_rgb,
            light_rgb: apply(&to_rgb, light.white_xyz()),
        })
    }

    /// XYZ of r^(K+1) under the light.
    pub fn spectral(&self, r: &[f32]) -> [f64; 3] {
        self.light.weights.each_ref().map(|w| {
            w.iter()
                .zip(r)
                .map(|(w, &v)| w * f64::from(v).powi(self.power))
                .sum()
        })
    }

    /// The RGB renderer's answer: per linear Rec.709 channel, the light's colour times the
    /// albedo (the colour of r under the texture's illuminant) to the power K + 1.
    pub fn rgb(&self, r: &[f32]) -> [f64; 3] {
        let albedo = self
            .texture
            .weights
            .each_ref()
            .map(|w| w.iter().zip(r).map(|(w, &v)| w * f64::from(v)).sum::<f64>());
        let a = apply(&self.to_rgb, albedo);
        let lit: [f64; 3] = [0, 1, 2].map(|c| self.light_rgb[c] * a[c].powi(self.power));
        apply(&self.from_rgb, lit)
    }

    /// CIELAB's white: the perfect reflector under the light.
    pub fn white(&self) -> [f64; 3] {
        self.light.white_xyz()
    }
}

impl Scene {
    /// Checks the scene against `bands` and says what is wrong and what to do.
    pub fn validate(&self, bands: usize) -> Result<(), Error> {
        let n = self.materials.len();
        let bad = |m: String| Err(Error::Scene(m));
        if n == 0 {
            return bad("the scene has no patches; add at least one `[[patches]]`".into());
        }
        if self.names.len() != n {
            return bad(format!("{} names for {n} patches", self.names.len()));
        }
        if self.form_factors.len() != n || self.form_factors.iter().any(|r| r.len() != n) {
            return bad(format!(
                "the form factors must be a {n}×{n} matrix, one row and one column per patch"
            ));
        }
        for (i, row) in self.form_factors.iter().enumerate() {
            if let Some(v) = row.iter().find(|v| !v.is_finite() || **v < 0.0) {
                return bad(format!(
                    "form factor row {} ({}) has {v}: form factors are shares of light, finite and \
                     not negative",
                    i + 1,
                    self.names[i]
                ));
            }
            let sum: f64 = row.iter().sum();
            if sum > 1.0 + 1e-9 {
                return bad(format!(
                    "form factor row {} ({}) sums to {sum}: a patch cannot send more than all its \
                     light to the others; the rows must sum to at most 1",
                    i + 1,
                    self.names[i]
                ));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            let ok = match m {
                Material::Colour(c) => c.iter().all(|v| v.is_finite()),
                Material::Measured(s) => s.len() == bands && s.iter().all(|v| v.is_finite()),
            };
            if !ok {
                return bad(format!(
                    "patch {} has a non-finite colour or a spectrum not on the {bands}-band grid",
                    self.names[i]
                ));
            }
        }
        if self.lights.is_empty() {
            return bad(
                "the scene has no lights; add a `[[lights]]` with a spectrum and a power".into(),
            );
        }
        for l in &self.lights {
            if !l.power.is_finite() || l.power < 0.0 {
                return bad(format!(
                    "light {} has power {}: the power must be a finite number ≥ 0",
                    l.name, l.power
                ));
            }
            if l.spd.len() != bands || l.spd.iter().any(|v| !v.is_finite() || *v < 0.0) {
                return bad(format!(
                    "light {}: its spectrum must have {bands} finite, non-negative values",
                    l.name
                ));
            }
            if let Some(p) = l.patches.iter().find(|&&p| p >= n) {
                return bad(format!(
                    "light {} names patch {p}, but there are {n}",
                    l.name
                ));
            }
        }
        Ok(())
    }

    /// Bytes of the bounce snapshots for `renderings` renderings of `bands` bands, or an error
    /// when they exceed [`MEMORY_LIMIT`].
    pub fn memory(&self, bands: usize, renderings: usize) -> Result<usize, Error> {
        let counts = match self.effect {
            Effect::Bounces(k) => k.checked_add(1),
            Effect::Converged => Some(1),
        };
        let bytes = counts
            .and_then(|c| c.checked_mul(self.materials.len()))
            .and_then(|c| c.checked_mul(bands + 3 * renderings))
            .and_then(|c| c.checked_mul(std::mem::size_of::<f64>()));
        match bytes {
            Some(b) if b <= MEMORY_LIMIT => Ok(b),
            _ => {
                let Effect::Bounces(k) = self.effect else {
                    unreachable!("one count always fits")
                };
                let per = self.materials.len() * (bands + 3 * renderings) * 8;
                Err(Error::Scene(format!(
                    "{k} bounces of {} patches would need {:.1} GiB (limit {} GiB); ask for at \
                     most {} bounces, or `converged`",
                    self.materials.len(),
                    (k as f64 + 1.0) * per as f64 / f64::from(1 << 30),
                    MEMORY_LIMIT >> 30,
                    (MEMORY_LIMIT / per.max(1)).saturating_sub(1)
                )))
            }
        }
    }
}

/// Simulates `scene` in colorimetry `a` (the model's: grid, observer, and the illuminant that
/// defines the texture colours) for each method, the measured reference (when every patch is
/// measured) and plain RGB multiplication. Each method comes with the name its rendering has.
pub fn simulate(
    scene: &Scene,
    a: &Colorimetry,
    methods: &[(&str, &dyn Method)],
) -> Result<Outcome, Error> {
    let bands = a.bands();
    scene.validate(bands)?;
    for (_, m) in methods {
        if m.grid() != a.grid {
            return Err(Error::Scene(format!(
                "method {} makes spectra on {}, the scene is on {}",
                m.name(),
                m.grid(),
                a.grid
            )));
        }
    }
    let n = scene.materials.len();
    let has_reference = scene
        .materials
        .iter()
        .all(|m| matches!(m, Material::Measured(_)));
    scene.memory(bands, methods.len() + 3)?;

    let cmfs = a.observer.cmfs(&a.grid)?;
    let to_xyz = |b: &[f64]| -> [f64; 3] {
        cmfs.each_ref()
            .map(|c| c.iter().zip(b).map(|(w, v)| w * v).sum::<f64>() * a.grid.step)
    };
    let render = |rho: &[Vec<f64>]| -> Result<Vec<Vec<[f64; 3]>>, Error> {
        Ok(radiosity(
            rho,
            &emission(scene, bands),
            &scene.form_factors,
            scene.effect,
        )?
        .iter()
        .map(|b| b.iter().map(|p| to_xyz(p)).collect())
        .collect())
    };

    let colours: Vec<[f64; 3]> = scene
        .materials
        .iter()
        .map(|m| match m {
            Material::Colour(c) => *c,
            Material::Measured(s) => a.xyz(s),
        })
        .collect();
    let white = render(&vec![vec![1.0; bands]; n])?;
    let mut renderings = Vec::new();
    if has_reference {
        let rho: Vec<Vec<f64>> = scene
            .materials
            .iter()
            .map(|m| match m {
                Material::Measured(s) => s.clone(),
                Material::Colour(_) => unreachable!("checked above"),
            })
            .collect();
        renderings.push(Rendering {
            method: "measured".into(),
            xyz: render(&rho)?,
        });
    }
    for (name, m) in methods {
        let mut rho = vec![vec![0.0; bands]; n];
        for (r, c) in rho.iter_mut().zip(&colours) {
            m.uplift_f64(c, r);
        }
        let xyz = render(&rho).map_err(|e| Error::Scene(format!("{name}: {e}")))?;
        renderings.push(Rendering {
            method: name.to_string(),
            xyz,
        });
    }
    renderings.push(Rendering {
        method: "rgb".into(),
        xyz: rgb_multiplication(scene, a, &colours, &to_xyz)?,
    });
    let counts = match scene.effect {
        Effect::Bounces(k) => (0..=k).map(Some).collect(),
        Effect::Converged => vec![None],
    };
    Ok(Outcome {
        counts,
        white,
        renderings,
        has_reference,
    })
}

/// Emitted radiosity per patch: the sum of the lights that name it.
fn emission(scene: &Scene, bands: usize) -> Vec<Vec<f64>> {
    let mut e = vec![vec![0.0; bands]; scene.materials.len()];
    for l in &scene.lights {
        for &p in &l.patches {
            for (v, s) in e[p].iter_mut().zip(&l.spd) {
                *v += l.power * s;
            }
        }
    }
    e
}

/// The RGB renderer's answer: the same radiosity in three bands, linear Rec.709, with each
/// material's RGB from its colour and each light's RGB from its XYZ.
fn rgb_multiplication(
    scene: &Scene,
    a: &Colorimetry,
    colours: &[[f64; 3]],
    to_xyz: &dyn Fn(&[f64]) -> [f64; 3],
) -> Result<Vec<Vec<[f64; 3]>>, Error> {
    let white = a.white_xyz();
    let (to_rgb, from_rgb) = (SRGB.from_xyz(white), SRGB.to_xyz(white));
    let rho: Vec<Vec<f64>> = colours
        .iter()
        .map(|c| apply(&to_rgb, *c).to_vec())
        .collect();
    let e: Vec<Vec<f64>> = emission(scene, a.bands())
        .iter()
        .map(|s| apply(&to_rgb, to_xyz(s)).to_vec())
        .collect();
    Ok(radiosity(&rho, &e, &scene.form_factors, scene.effect)?
        .iter()
        .map(|b| {
            b.iter()
                .map(|p| apply(&from_rgb, [p[0], p[1], p[2]]))
                .collect()
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_cube_sends_all_its_light_somewhere() {
        // Four adjacent faces and one opposite: the six faces of a cube close the room.
        let sum = 4.0 * perpendicular(1.0, 1.0, 1.0) + parallel(1.0, 1.0, 1.0);
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
        // Published values for the unit cube (Howell C-11, C-14): 0.19982 and 0.20004.
        assert!((parallel(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-5);
        assert!((perpendicular(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-5);
        // Reciprocity for unequal rectangles: A1·F12 = A2·F21.
        let (w, h) = (2.0, 0.5);
        assert!((w * perpendicular(w, h, 1.0) - h * perpendicular(h, w, 1.0)).abs() < 1e-12);
        for row in room() {
            let s: f64 = row.iter().sum();
            assert!(s < 1.0 && s > 0.79, "{s}");
        }
    }

    #[test]
    fn truncated_series_is_the_sum_of_powers_per_wavelength() {
        // Three coupled patches, four bands, reflectances and emission of every sort.
        let rho = vec![
            vec![0.9, 0.1, 0.5, 1.0],
            vec![0.2, 0.8, 0.3, 0.6],
            vec![0.7, 0.4, 0.95, 0.05],
        ];
        let e = vec![
            vec![1.0, 2.0, 0.5, 0.0],
            vec![0.0; 4],
            vec![0.3, 0.0, 1.0, 2.0],
        ];
        let f = vec![
            vec![0.0, 0.5, 0.4],
            vec![0.3, 0.2, 0.45],
            vec![0.6, 0.25, 0.1],
        ];
        let k = 12;
        let got = radiosity(&rho, &e, &f, Effect::Bounces(k)).unwrap();
        for l in 0..4 {
            let m = DMatrix::from_fn(3, 3, |i, j| rho[i][l] * f[i][j]);
            let e_l = DVector::from_fn(3, |i, _| e[i][l]);
            let mut term = e_l.clone();
            let mut sum = e_l.clone();
            assert_eq!(got.len(), k + 1);
            for (count, b) in got.iter().enumerate() {
                if count > 0 {
                    term = &m * term;
                    sum += &term;
                }
                for i in 0..3 {
                    assert!((b[i][l] - sum[i]).abs() < 1e-9, "{count} {i} {l}");
                }
            }
            // And the converged solution is the limit of the series.
            let conv = radiosity(&rho, &e, &f, Effect::Converged).unwrap();
            let mut term = e_l.clone();
            let mut sum = e_l.clone();
            for _ in 0..2000 {
                term = &m * term;
                sum += &term;
            }
            for i in 0..3 {
                assert!((conv[0][i][l] - sum[i]).abs() < 1e-9, "{i} {l}");
            }
        }
    }

    #[test]
    fn self_bounce_keeps_white_and_grey_and_drifts_for_saturated_colours() {
        let model = specconv_spectral::Model::builtin();
        let d65 = model.colorimetry().unwrap();
        let n = d65.bands();
        for k in [0, 1, 4] {
            let b = SelfBounce::new(&d65, &d65, k).unwrap();
            let white = b.spectral(&vec![1.0; n]);
            assert!((0..3).all(|c| (white[c] - d65.white_xyz()[c]).abs() < 1e-12));
            // A flat grey: the same for the spectrum and the RGB renderer, 0.5^(K+1) of white.
            let (s, r) = (b.spectral(&vec![0.5; n]), b.rgb(&vec![0.5; n]));
            let expect = 0.5f64.powi(k as i32 + 1);
            assert!(
                (s[1] - expect).abs() < 1e-12 && (r[1] - expect).abs() < 1e-12,
                "{s:?} {r:?}"
            );
            // A saturated red (high above 600 nm): K = 0 is its colour for both; after bounces
            // the spectrum is more saturated than the RGB renderer thinks, and darker.
            let red: Vec<f32> = d65
                .grid
                .wavelengths()
                .iter()
                .map(|&l| if l > 600.0 { 0.8 } else { 0.05 })
                .collect();
            let lab = |x| xyz_to_lab(x, b.white());
            let d = ciede2000(lab(b.spectral(&red)), lab(b.rgb(&red)));
            if k == 0 {
                let red64: Vec<f64> = red.iter().map(|&v| f64::from(v)).collect();
                let xyz = d65.xyz(&red64);
                assert!((0..3).all(|c| (b.spectral(&red)[c] - xyz[c]).abs() < 1e-12));
                assert!(d < 1e-9, "{d}");
            } else {
                assert!(d > 1.0, "K={k}: {d}");
            }
        }
        let a = Colorimetry::new(d65.grid, d65.observer, specconv_colour::Illuminant::A).unwrap();
        // Under another light a white surface is that light's white, in both renderings.
        let b = SelfBounce::new(&d65, &a, 2).unwrap();
        let (s, r) = (b.spectral(&vec![1.0; n]), b.rgb(&vec![1.0; n]));
        assert!(
            (0..3).all(|c| (s[c] - a.white_xyz()[c]).abs() < 1e-12 && (r[c] - s[c]).abs() < 1e-9)
        );
        let other = Colorimetry::new(
            specconv_colour::Grid::new(400.0, 700.0, 10.0).unwrap(),
            d65.observer,
            d65.illuminant,
        )
        .unwrap();
        assert!(SelfBounce::new(&d65, &other, 1).is_err());
    }

    #[test]
    fn a_white_furnace_gives_back_e_times_k_plus_1() {
        let e = vec![vec![0.25, 1.0, 3.0]];
        let got = radiosity(&[vec![1.0; 3]], &e, &furnace(1), Effect::Bounces(20)).unwrap();
        for (k, b) in got.iter().enumerate() {
            for l in 0..3 {
                assert!((b[0][l] - e[0][l] * (k as f64 + 1.0)).abs() < 1e-12);
            }
        }
        // Converged in a white furnace: infinite light, refused with a reason.
        let err = radiosity(&[vec![1.0; 3]], &e, &furnace(1), Effect::Converged).unwrap_err();
        assert!(err.to_string().contains("does not converge"), "{err}");
        // Grey 0.5: E·(2 − 2^-K) after K bounces, 2E converged.
        let grey = radiosity(&[vec![0.5; 3]], &e, &furnace(1), Effect::Converged).unwrap();
        assert!((grey[0][0][2] - 6.0).abs() < 1e-12);
    }

    fn scene(materials: Vec<Material>, f: Vec<Vec<f64>>, effect: Effect) -> Scene {
        let n = materials.len();
        Scene {
            names: (0..n).map(|i| format!("p{i}")).collect(),
            materials,
            form_factors: f,
            lights: vec![Light {
                name: "sun".into(),
                spd: vec![1.0; 36],
                power: 1.0,
                patches: (0..n).collect(),
            }],
            effect,
        }
    }

    #[test]
    fn malformed_scenes_say_what_is_wrong() {
        let a = specconv_spectral::Model::builtin().colorimetry().unwrap();
        let grey = || Material::Measured(vec![0.5; 36]);
        let err = |s: Scene| simulate(&s, &a, &[]).unwrap_err().to_string();
        let s = scene(
            vec![grey(), grey()],
            vec![vec![0.6, 0.5], vec![0.0, 0.1]],
            Effect::Bounces(2),
        );
        let e = err(s);
        assert!(
            e.contains("row 1 (p0) sums to 1.1") && e.contains("at most 1"),
            "{e}"
        );
        let mut s = scene(vec![grey()], furnace(1), Effect::Bounces(2));
        s.lights[0].power = -1.0;
        assert!(err(s).contains("light sun has power -1"));
        let s = scene(vec![grey()], vec![vec![-0.1]], Effect::Bounces(2));
        assert!(err(s).contains("not negative"));
        let s = scene(vec![grey()], furnace(1), Effect::Bounces(usize::MAX));
        let e = err(s);
        assert!(e.contains("GiB") && e.contains("ask for at most"), "{e}");
        let s = scene(vec![grey()], furnace(1), Effect::Bounces(10_000_000));
        assert!(err(s).contains("GiB"));
        let s = scene(vec![grey(), grey()], furnace(1), Effect::Bounces(2));
        assert!(err(s).contains("2×2"));
        let s = scene(
            vec![Material::Measured(vec![0.5; 10])],
            furnace(1),
            Effect::Bounces(2),
        );
        assert!(err(s).contains("36-band"));
    }

    #[test]
    fn grey_furnace_agrees_for_every_method_and_rgb() {
        // A flat grey is its own uplift for no method in particular, but its colour is neutral:
        // the reference, the RGB renderer and the methods all stay near the white scene's hue.
        let model = specconv_spectral::Model::builtin();
        let a = model.colorimetry().unwrap();
        let up = specconv_spectral::Uplifter::new(model).unwrap();
        let s = scene(
            vec![Material::Measured(vec![0.5; 36])],
            furnace(1),
            Effect::Bounces(4),
        );
        let out = simulate(&s, &a, &[("otsu2018", &up)]).unwrap();
        assert!(out.has_reference);
        assert_eq!(out.counts.len(), 5);
        let reference = out.rendering("measured").unwrap();
        // Zero bounces: the light itself, identical for all.
        for r in &out.renderings {
            assert!(out.delta_e(r, reference, 0, 0) < 1e-9, "{}", r.method);
        }
        // The reference after K bounces: Σ 0.5^k / (K + 1) of the white scene's Y.
        for k in 0..5usize {
            let expect: f64 =
                (0..=k as i32).map(|j| 0.5f64.powi(j)).sum::<f64>() / (k as f64 + 1.0);
            let ratio = reference.xyz[k][0][1] / out.white[k][0][1];
            assert!((ratio - expect).abs() < 1e-12);
        }
        let rgb = out.rendering("rgb").unwrap();
        assert!(out.delta_e(rgb, reference, 4, 0) < 0.05);
    }

    #[test]
    fn walls_lit_only_by_bounces_are_black_at_first_not_nan() {
        let a = specconv_spectral::Model::builtin().colorimetry().unwrap();
        let up = specconv_spectral::Uplifter::new(specconv_spectral::Model::builtin()).unwrap();
        let mut s = scene(
            (0..5)
                .map(|i| Material::Measured(vec![0.2 + 0.15 * i as f64; 36]))
                .collect(),
            room(),
            Effect::Bounces(3),
        );
        s.lights[0].patches = vec![1];
        let out = simulate(&s, &a, &[("otsu2018", &up)]).unwrap();
        let reference = &out.renderings[0];
        for r in &out.renderings {
            for c in 0..4 {
                for p in 0..5 {
                    let d = out.delta_e(r, reference, c, p);
                    assert!(d.is_finite(), "{} {c} {p}", r.method);
                    if c == 0 && p != 1 {
                        assert_eq!(out.lab(r, c, p), [0.0; 3]);
                    }
                }
            }
        }
        // The floor is lit after one bounce: white scene Y = F(floor, ceiling)·E.
        assert!(out.white[1][0][1] > 0.0);
        let conv = simulate(
            &Scene {
                effect: Effect::Converged,
                ..s
            },
            &a,
            &[("otsu2018", &up)],
        )
        .unwrap();
        assert_eq!(conv.counts, vec![None]);
        // The converged white scene exceeds any truncation of it.
        assert!(conv.white[0][0][1] > out.white[3][0][1]);
    }
}
