//! Jakob and Hanika, "A Low-Dimensional Function Space for Efficient Spectral Upsampling"
//! (CGF 38(2), 2019): a reflectance is a sigmoid of a quadratic in wavelength,
//!
//! ```text
//! r(λ) = S(c₀·λ'² + c₁·λ' + c₂),  S(x) = ½ + x / (2·√(1 + x²))          (their Eq. 3–4)
//! ```
//!
//! with λ' the wavelength mapped to [0, 1] over the grid. The three coefficients of a colour are
//! precomputed on a 3-D table over linear RGB of the working space and looked up trilinearly
//! (their Sec. 4): for each of the three components that can be the largest, a res³ block over
//! (z = that component on a smoothstep-of-smoothstep scale that is dense near 0 and 1, x and y =
//! the other two divided by z). Each cell is fitted by Gauss–Newton on the CIELAB difference,
//! starting from its neighbour along z (their Sec. 4.1, and Hanika's rgb2spec_opt).
//!
//! Building the table is pure computation, split into independent columns so that a caller may
//! solve them in parallel; [`super::jakob_cache`] keeps tables in files ([`Table::to_bytes`]).

// Band and coefficient loops index several arrays in step.
#![allow(clippy::needless_range_loop)]

use crate::error::Error;

use crate::Method;
use specconv_colour::{lab::xyz_to_lab, lab::xyz_to_lab_jacobian};
use specconv_colour::{Colorimetry, Grid};

/// The default table resolution, Jakob and Hanika's 64.
pub const DEFAULT_RESOLUTION: usize = 64;
/// Gauss–Newton steps after the lookup: one leaves ΔE₀₀ up to 0.02, two reach the 0.01 goal.
const POLISH_STEPS: usize = 2;
const FORMAT: &[u8] = b"specconv-jakob2019 1\n";

/// Sigmoid of Eq. 3–4.
#[inline(always)]
fn sigmoid(x: f64) -> f64 {
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

#[inline(always)]
fn sigmoid32(x: f32) -> f32 {
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

/// Smoothstep applied twice: the lightness scale of the table's z axis.
fn scale(res: usize) -> Vec<f64> {
    let s = |x: f64| x * x * (3.0 - 2.0 * x);
    (0..res)
        .map(|k| s(s(k as f64 / (res - 1) as f64)))
        .collect()
}

/// XYZ of the spectrum S(c₀λ′² + c₁λ′ + c₂) (λ′ the normalised wavelengths) under the XYZ rows
/// `weights`, and its derivatives by c₀, c₁, c₂: what both the fit and the runtime polish need.
fn sigmoid_xyz_and_jacobian(
    c: [f64; 3],
    lambda: impl Iterator<Item = f64>,
    weights: &[Vec<f64>; 3],
) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut xyz = [0.0; 3];
    let mut jac = [[0.0; 3]; 3];
    for (i, l) in lambda.enumerate() {
        let u = (c[0] * l + c[1]) * l + c[2];
        let t = (1.0 + u * u).sqrt();
        let r = 0.5 + u / (2.0 * t);
        // dS/du = 1 / (2·(1 + u²)^{3/2})
        let ds = 0.5 / (t * t * t);
        let du = [l * l, l, 1.0];
        for k in 0..3 {
            let w = weights[k][i];
            xyz[k] += w * r;
            for j in 0..3 {
                jac[k][j] += w * ds * du[j];
            }
        }
    }
    (xyz, jac)
}

/// The fitting problem: a colorimetry, its λ', the working space and the Lab white.
pub struct Fitter {
    lambda: Vec<f64>,
    weights: [Vec<f64>; 3],
    white: [f64; 3],
    space: specconv_colour::rgb::Linear,
}

impl Fitter {
    /// The fitting problem of colorimetry `a`; needs at least 3 bands ([`Error::Grid`]).
    pub fn new(a: &Colorimetry) -> Result<Fitter, Error> {
        let n = a.bands();
        if n < 3 {
            return Err(Error::Grid(format!(
                "{}: jakob2019 needs at least 3 bands to fit three coefficients",
                a.grid
            )));
        }
        Ok(Fitter {
            lambda: (0..n).map(|i| i as f64 / (n - 1) as f64).collect(),
            weights: a.weights.clone(),
            white: a.white_xyz(),
            space: specconv_colour::rgb::SRGB.with_white(a.white_xyz()),
        })
    }

    /// XYZ of the model spectrum and its derivatives by c₀, c₁, c₂.
    fn xyz_and_jacobian(&self, c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        sigmoid_xyz_and_jacobian(c, self.lambda.iter().copied(), &self.weights)
    }

    /// Lab and its Jacobian by the coefficients (chain rule through CIE 15 Eq. 8.1–8.3).
    fn lab_and_jacobian(&self, c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let (xyz, jx) = self.xyz_and_jacobian(c);
        let (lab, jl) = xyz_to_lab_jacobian(xyz, self.white);
        let j = [0, 1, 2].map(|row| [0, 1, 2].map(|p| (0..3).map(|k| jl[row][k] * jx[k][p]).sum()));
        (lab, j)
    }

    /// Gauss–Newton on Lab(c) = target from `c`, halving steps that do not reduce the error.
    /// Returns the coefficients and the remaining CIE 1976 ΔE.
    pub fn fit_lab(&self, target: [f64; 3], mut c: [f64; 3]) -> ([f64; 3], f64) {
        let resid = |lab: [f64; 3]| [0, 1, 2].map(|k| lab[k] - target[k]);
        let norm = |r: [f64; 3]| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        let (mut lab, mut j) = self.lab_and_jacobian(c);
        let mut err = norm(resid(lab));
        for _ in 0..50 {
            if err < 1e-6 {
                break;
            }
            let inv = specconv_colour::mat3::inverse(&j);
            let step = specconv_colour::mat3::mul_vec(&inv, resid(lab));
            if !step.iter().all(|s| s.is_finite()) {
                break;
            }
            let mut f = 1.0;
            let mut improved = false;
            while f > 1e-4 {
                let trial = [0, 1, 2].map(|k| c[k] - f * step[k]);
                let (tl, tj) = self.lab_and_jacobian(trial);
                let te = norm(resid(tl));
                if te < err && trial.iter().all(|v| v.is_finite()) {
                    (c, lab, j, err) = (trial, tl, tj, te);
                    improved = true;
                    break;
                }
                f *= 0.5;
            }
            if !improved {
                break;
            }
        }
        (c, err)
    }

    /// Fits a colour given in XYZ, starting from flat grey (for tests and comparisons).
    pub fn fit_xyz(&self, xyz: [f64; 3]) -> ([f64; 3], f64) {
        self.fit_lab(xyz_to_lab(xyz, self.white), [0.0; 3])
    }

    /// The model spectrum of coefficients `c` on the grid.
    pub fn spectrum(&self, c: [f64; 3]) -> Vec<f64> {
        self.lambda
            .iter()
            .map(|&l| sigmoid((c[0] * l + c[1]) * l + c[2]))
            .collect()
    }

    /// One column of the table: block `l` (the largest component), y index `j`; all z and x
    /// cells, as `[k][i]` → coefficients. Each x walks z up from res/5 and down from there,
    /// every fit starting from the previous one, as rgb2spec_opt does.
    pub fn solve_column(&self, res: usize, l: usize, j: usize) -> Vec<[f32; 3]> {
        let sc = scale(res);
        let mut out = vec![[0f32; 3]; res * res];
        let y = j as f64 / (res - 1) as f64;
        let start = res / 5;
        for i in 0..res {
            let x = i as f64 / (res - 1) as f64;
            let mut solve = |ks: &mut dyn Iterator<Item = usize>| {
                let mut c = [0.0; 3];
                for k in ks {
                    let z = sc[k];
                    let mut rgb = [0.0; 3];
                    rgb[l] = z;
                    rgb[(l + 1) % 3] = x * z;
                    rgb[(l + 2) % 3] = y * z;
                    let target = xyz_to_lab(self.space.xyz(rgb), self.white);
                    c = self.fit_lab(target, c).0;
                    out[k * res + i] = c.map(|v| v as f32);
                }
            };
            solve(&mut (start..res));
            solve(&mut (0..start).rev());
        }
        out
    }

    /// Text that identifies everything the table depends on: a table built for another key
    /// must not be used. It covers the format, the resolution and the colorimetry itself (the
    /// weights bit for bit, so changed tables or code change it too).
    pub fn key(&self, a: &Colorimetry, res: usize) -> String {
        let mut h = Fnv::new();
        for w in &self.weights {
            for v in w {
                h.write(&v.to_bits().to_le_bytes());
            }
        }
        format!(
            "grid={} observer={} illuminant={} resolution={} weights={:016x}",
            a.grid,
            a.observer,
            a.illuminant,
            res,
            h.finish()
        )
    }
}

/// The coefficient table: 3 blocks of res³ cells, `[l][k][j][i]`.
#[derive(Debug, Clone)]
pub struct Table {
    /// Cells per axis of each block (4–256; 64 the paper's).
    pub res: usize,
    /// What the table was built for ([`Fitter::key`]); a table is used only for its own key.
    pub key: String,
    /// The sigmoid's three polynomial coefficients per cell, 3·res³ of them.
    pub coefficients: Vec<[f32; 3]>,
}

impl Table {
    /// Assembles the table from the `3·res` columns of [`Fitter::solve_column`], in the order
    /// (l, j) = (0, 0), (0, 1), ….
    pub fn from_columns(res: usize, key: String, columns: Vec<Vec<[f32; 3]>>) -> Table {
        assert_eq!(columns.len(), 3 * res);
        let mut coefficients = vec![[0f32; 3]; 3 * res * res * res];
        for (col, cells) in columns.into_iter().enumerate() {
            let (l, j) = (col / res, col % res);
            for k in 0..res {
                for i in 0..res {
                    coefficients[((l * res + k) * res + j) * res + i] = cells[k * res + i];
                }
            }
        }
        Table {
            res,
            key,
            coefficients,
        }
    }

    /// Builds the table on one thread.
    pub fn build(a: &Colorimetry, res: usize) -> Result<Table, Error> {
        let f = Fitter::new(a)?;
        check_resolution(res)?;
        let cols = solve_in_turn(&f, res);
        Ok(Table::from_columns(res, f.key(a, res), cols))
    }

    /// The file form: a format line, the key line, then the coefficients as little-endian f32
    /// and an FNV-1a checksum of everything before it.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(64 + self.coefficients.len() * 12);
        b.extend_from_slice(FORMAT);
        b.extend_from_slice(self.key.as_bytes());
        b.push(b'\n');
        for c in &self.coefficients {
            for v in c {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        let mut h = Fnv::new();
        h.write(&b);
        b.extend_from_slice(&h.finish().to_le_bytes());
        b
    }

    /// Reads the file form back, if it is intact and was built for `key` at `res`; `None`
    /// otherwise (the caller rebuilds).
    pub fn from_bytes(bytes: &[u8], key: &str, res: usize) -> Option<Table> {
        let (body, sum) = bytes.split_at_checked(bytes.len().checked_sub(8)?)?;
        let mut h = Fnv::new();
        h.write(body);
        if h.finish().to_le_bytes() != sum {
            return None;
        }
        let rest = body.strip_prefix(FORMAT)?;
        let rest = rest.strip_prefix(key.as_bytes())?.strip_prefix(b"\n")?;
        if rest.len() != 3 * res * res * res * 12 {
            return None;
        }
        let coefficients = rest
            .chunks_exact(12)
            .map(|c| [0, 1, 2].map(|k| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap())))
            .collect::<Vec<_>>();
        coefficients
            .iter()
            .all(|c| c.iter().all(|v| v.is_finite()))
            .then(|| Table {
                res,
                key: key.to_string(),
                coefficients,
            })
    }
}

/// The `3·res` columns of a table one after another, on this thread, in the order of
/// [`Table::from_columns`].
pub fn solve_in_turn(fitter: &Fitter, res: usize) -> Vec<Vec<[f32; 3]>> {
    (0..3 * res)
        .map(|c| fitter.solve_column(res, c / res, c % res))
        .collect()
}

/// Refuses a table resolution outside 4–256 ([`Error::Grid`]).
pub fn check_resolution(res: usize) -> Result<(), Error> {
    if !(4..=256).contains(&res) {
        return Err(Error::Grid(format!(
            "jakob2019 table resolution {res}: choose 4 to 256 (64 is the paper's)"
        )));
    }
    Ok(())
}

/// Jakob & Hanika 2019 at runtime: RGB of the working space, table lookup, sigmoid per band.
///
/// RGB outside [0, 1] (colours outside the working space's gamut, or brighter than its white)
/// is clamped to it before the lookup, as the table covers only [0, 1]³: such colours do not
/// round-trip. Black and non-finite colours take the coefficients of black.
///
/// Trilinear interpolation of the 64³ table alone leaves errors up to CIEDE2000 ≈ 0.3 in dark
/// and saturated colours (the coefficients curve between cells). So the looked-up coefficients
/// are polished by two Gauss–Newton steps on XYZ (J·δ = c − A·r, J = A·diag(S′)·[λ′², λ′, 1]),
/// which from that close a start brings in-gamut colours below ΔE₀₀ 0.01; `lookup_only`
/// skips it.
#[derive(Debug, Clone)]
pub struct Jakob2019 {
    grid: Grid,
    res: usize,
    scale: Vec<f32>,
    table: Vec<[f32; 3]>,
    lambda: Vec<f32>,
    to_rgb: [[f32; 3]; 3],
    to_xyz: [[f64; 3]; 3],
    weights: [Vec<f64>; 3],
    refine: bool,
}

impl Jakob2019 {
    /// Without the Gauss–Newton polish: the table lookup alone.
    pub fn lookup_only(mut self) -> Jakob2019 {
        self.refine = false;
        self
    }

    /// Coefficients for `xyz`: lookup, then (unless `lookup_only`) Gauss–Newton steps
    /// towards the colour of the clamped RGB.
    #[inline]
    fn solve(&self, xyz: [f32; 3]) -> [f64; 3] {
        let (c, rgb) = self.lookup(xyz);
        let c = c.map(f64::from);
        if !self.refine {
            return c;
        }
        let target = specconv_colour::mat3::mul_vec(&self.to_xyz, rgb.map(f64::from));
        let mut c = c;
        for _ in 0..POLISH_STEPS {
            let (got, jac) =
                sigmoid_xyz_and_jacobian(c, self.lambda.iter().map(|&l| l as f64), &self.weights);
            let inv = specconv_colour::mat3::inverse(&jac);
            let step = specconv_colour::mat3::mul_vec(&inv, [0, 1, 2].map(|k| target[k] - got[k]));
            let next = [0, 1, 2].map(|k| c[k] + step[k]);
            if !next.iter().all(|v| v.is_finite()) {
                break;
            }
            c = next;
        }
        c
    }

    /// The method for colorimetry `a` with `table`, which must have been built for it (the same
    /// [`Fitter::key`], else [`Error::Model`]).
    pub fn new(a: &Colorimetry, table: Table) -> Result<Jakob2019, Error> {
        let f = Fitter::new(a)?;
        let key = f.key(a, table.res);
        if table.key != key {
            return Err(Error::Model {
                file: "jakob2019 table".into(),
                msg: format!("built for `{}`, needed for `{key}`", table.key),
            });
        }
        Ok(Jakob2019 {
            grid: a.grid,
            res: table.res,
            scale: scale(table.res).iter().map(|&v| v as f32).collect(),
            table: table.coefficients,
            lambda: f.lambda.iter().map(|&v| v as f32).collect(),
            to_rgb: f.space.to_rgb.map(|r| r.map(|v| v as f32)),
            to_xyz: f.space.to_xyz,
            weights: a.weights.clone(),
            refine: true,
        })
    }

    /// Coefficients of a colour by trilinear interpolation (rgb2spec_fetch).
    pub fn coefficients(&self, xyz: [f32; 3]) -> [f32; 3] {
        self.lookup(xyz).0
    }

    /// Interpolated coefficients and the clamped RGB they are for.
    #[inline]
    fn lookup(&self, xyz: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        let m = &self.to_rgb;
        let rgb = m.map(|row| {
            let v = row[0] * xyz[0] + row[1] * xyz[1] + row[2] * xyz[2];
            // NaN fails the comparison and becomes 0.
            if v >= 0.0 {
                v.min(1.0)
            } else {
                0.0
            }
        });
        let l = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
            0
        } else if rgb[1] >= rgb[2] {
            1
        } else {
            2
        };
        let res = self.res;
        let z = rgb[l];
        let s = if z > 0.0 { (res - 1) as f32 / z } else { 0.0 };
        let x = rgb[(l + 1) % 3] * s;
        let y = rgb[(l + 2) % 3] * s;
        let xi = (x as usize).min(res - 2);
        let yi = (y as usize).min(res - 2);
        let zi = (self.scale.partition_point(|&v| v <= z).max(1) - 1).min(res - 2);
        let x1 = x - xi as f32;
        let y1 = y - yi as f32;
        let z1 = (z - self.scale[zi]) / (self.scale[zi + 1] - self.scale[zi]);
        let at = |k: usize, j: usize, i: usize| self.table[((l * res + k) * res + j) * res + i];
        let mut c = [0f32; 3];
        for q in 0..3 {
            let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
            let face = |k| {
                lerp(
                    lerp(at(k, yi, xi)[q], at(k, yi, xi + 1)[q], x1),
                    lerp(at(k, yi + 1, xi)[q], at(k, yi + 1, xi + 1)[q], x1),
                    y1,
                )
            };
            c[q] = lerp(face(zi), face(zi + 1), z1);
        }
        (c, rgb)
    }
}

impl Method for Jakob2019 {
    fn name(&self) -> &str {
        "jakob2019"
    }

    fn grid(&self) -> Grid {
        self.grid
    }

    fn model_bytes(&self) -> usize {
        self.table.len() * 12 + self.scale.len() * 4
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        let n = self.lambda.len();
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            let k = self.solve([c[0] as f32, c[1] as f32, c[2] as f32]);
            for (o, &l) in r.iter_mut().zip(&self.lambda) {
                let l = l as f64;
                *o = sigmoid((k[0] * l + k[1]) * l + k[2]);
            }
        }
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        let n = self.lambda.len();
        for (c, r) in crate::method::per_colour(xyz, out, n) {
            let k = self.solve([c[0], c[1], c[2]]).map(|v| v as f32);
            for (o, &l) in r.iter_mut().zip(&self.lambda) {
                *o = sigmoid32((k[0] * l + k[1]) * l + k[2]);
            }
        }
    }
}

/// FNV-1a, 64 bit: a stable hash for cache keys and checksums (not for security).
pub struct Fnv(u64);

impl Fnv {
    /// The hash of no bytes (the FNV-1a offset basis).
    pub fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    /// Hashes `bytes` in.
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }

    /// The hash of every byte written so far.
    pub fn finish(&self) -> u64 {
        self.0
    }
}

impl Default for Fnv {
    fn default() -> Fnv {
        Fnv::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::lab::ciede2000;
    use specconv_colour::{Illuminant, Observer};

    fn colorimetry() -> Colorimetry {
        Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap()
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let f = Fitter::new(&colorimetry()).unwrap();
        let c = [3.0, -2.5, 0.4];
        let (_, j) = f.lab_and_jacobian(c);
        for p in 0..3 {
            let h = 1e-6;
            let mut cp = c;
            cp[p] += h;
            let mut cm = c;
            cm[p] -= h;
            let (lp, _) = f.lab_and_jacobian(cp);
            let (lm, _) = f.lab_and_jacobian(cm);
            for k in 0..3 {
                let fd = (lp[k] - lm[k]) / (2.0 * h);
                assert!((fd - j[k][p]).abs() < 1e-5 * (1.0 + fd.abs()), "{k} {p}");
            }
        }
    }

    #[test]
    fn direct_fit_reaches_the_colour() {
        let a = colorimetry();
        let f = Fitter::new(&a).unwrap();
        for rgb in [
            [0.8, 0.2, 0.1],
            [0.1, 0.5, 0.9],
            [0.5, 0.5, 0.5],
            [0.05, 0.3, 0.02],
        ] {
            let xyz = f.space.xyz(rgb);
            let (c, err) = f.fit_xyz(xyz);
            assert!(err < 1e-6, "{rgb:?}: {err}");
            let back = a.xyz(&f.spectrum(c));
            let de = ciede2000(xyz_to_lab(xyz, f.white), xyz_to_lab(back, f.white));
            assert!(de < 1e-5, "{de}");
        }
    }

    #[test]
    fn table_file_round_trips_and_refuses_damage_or_another_key() {
        let a = colorimetry();
        let t = Table::build(&a, 6).unwrap();
        let bytes = t.to_bytes();
        let back = Table::from_bytes(&bytes, &t.key, 6).unwrap();
        assert_eq!(back.coefficients, t.coefficients);
        let mut bad = bytes.clone();
        bad[100] ^= 1;
        assert!(Table::from_bytes(&bad, &t.key, 6).is_none());
        assert!(Table::from_bytes(&bytes[..bytes.len() - 1], &t.key, 6).is_none());
        assert!(Table::from_bytes(&bytes, "another", 6).is_none());
        assert!(Table::from_bytes(&bytes, &t.key, 7).is_none());
        let e = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::E).unwrap();
        assert!(Jakob2019::new(&e, t).is_err());
    }
}
