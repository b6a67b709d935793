//! Issue 47: the C header makes texels from colours (include/specconv_spectrum.h's encoder,
//! through tests/c/encode_check.c) as the library makes them (`Compact::encode_f32`), for
//! 100,000 random colours of every kind a texture holds or a careless caller passes.

use crate::compact::compile_c;
use specconv_colour::rgb::{ACESCG, SRGB};
use specconv_spectral::compact::{Compact, TEXEL};
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::Description;
use specconv_spectral::Model;
use specconv_testkit::cmd::Scratch;

/// SplitMix64: the same colours every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [a, b).
    fn in_range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A record of the C program: a colour and its kind (0: XYZ, 1: RGB through the matrix).
type Record = [f32; 4];

/// `count` colours, a kind each in turn: sRGB texels and HDR ones (through the C header's RGB
/// entry), ACEScg colours outside sRGB and beyond the spectral locus, any XYZ in [−0.5, 1.5]³,
/// greys round the perfect white (a vertex of the solid), tiny colours down to subnormal
/// float32 (the dark rule), and the special values: black, −0, NaN and ±∞ in one component,
/// the largest float, negative sums.
fn colours(count: usize, seed: u64) -> Vec<Record> {
    let mut rng = Rng(seed);
    let acescg = ACESCG.to_xyz(SRGB.white_xyz());
    let special: [[f32; 3]; 12] = [
        [0.0, 0.0, 0.0],
        [-0.0, 0.0, -0.0],
        [f32::NAN, 0.2, 0.3],
        [0.2, f32::INFINITY, 0.3],
        [0.2, 0.3, f32::NEG_INFINITY],
        [f32::MAX, f32::MAX, f32::MAX],
        [f32::MAX, -f32::MAX, 1.0],
        [-0.1, -0.2, -0.05],
        [1e-45, 1e-45, 1e-45],
        [0.9505, 1.0, 1.089],
        [1e-30, 0.0, 0.0],
        [0.0, 0.0, 3e38],
    ];
    (0..count)
        .map(|i| {
            let r = |rng: &mut Rng, a, b| rng.in_range(a, b);
            match i % 8 {
                0 => [r(&mut rng, 0.0, 1.0), r(&mut rng, 0.0, 1.0), r(&mut rng, 0.0, 1.0)]
                    .map(|v| v as f32)
                    .into_iter()
                    .chain([1.0])
                    .collect::<Vec<_>>()
                    .try_into()
                    .unwrap(),
                1 => {
                    let k = 10f64.powf(r(&mut rng, 0.0, 4.0));
                    let c = [0; 3].map(|_| (k * r(&mut rng, 0.0, 1.0)) as f32);
                    [c[0], c[1], c[2], 1.0]
                }
                2 => {
                    let rgb = [0; 3].map(|_| r(&mut rng, -0.2, 1.2));
                    let x = acescg.map(|row| (0..3).map(|k| row[k] * rgb[k]).sum::<f64>() as f32);
                    [x[0], x[1], x[2], 0.0]
                }
                3 => {
                    let x = [0; 3].map(|_| r(&mut rng, -0.5, 1.5) as f32);
                    [x[0], x[1], x[2], 0.0]
                }
                4 => {
                    let w = SRGB.white_xyz();
                    let k = r(&mut rng, 0.9, 1.1);
                    let x = w.map(|v| (v * k * r(&mut rng, 0.999, 1.001)) as f32);
                    [x[0], x[1], x[2], 0.0]
                }
                5 => {
                    let k = 10f64.powf(r(&mut rng, -46.0, -1.5));
                    let x = [0; 3].map(|_| (k * r(&mut rng, -0.1, 1.0)) as f32);
                    [x[0], x[1], x[2], 0.0]
                }
                6 => {
                    let s = special[(rng.next() % special.len() as u64) as usize];
                    [s[0], s[1], s[2], 0.0]
                }
                _ => {
                    // Saturated sRGB near the gamut's edges, scaled up a little.
                    let k = r(&mut rng, 0.5, 1.3);
                    let c = [0; 3].map(|_| (k * (rng.next() % 2) as f64 * r(&mut rng, 0.9, 1.0)) as f32);
                    [c[0], c[1], c[2], 1.0]
                }
            }
        })
        .collect()
}

fn to_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

/// What the comparison found: (largest excess over the bound, the band and record of the
/// largest relative error, its ratio to the bound, outcomes that differ).
#[derive(Debug, Default)]
struct Found {
    worst_ratio: f64,
    worst: String,
    outcome_differs: usize,
    records: usize,
}

/// Encodes `records` with the library and with the C header (the program `exe`), and compares
/// the texels' colours (bit for bit) and their spectra, each decoded by the library: the C
/// texel's within the bound of [`bound`] of the library texel's; and the C header's own
/// decoding of its texel within the decoders' float32 bound of the library's spectrum.
fn compare(exe: &std::path::Path, compact: &Compact, matrix: [[f64; 3]; 3], records: &[Record], dir: &Scratch) -> Found {
    let n = compact.grid().len();
    let text = dir.write("model.txt", &compact.to_text());
    let input = dir.path("colours.f32");
    std::fs::write(&input, to_bytes(records.as_flattened())).unwrap();
    let out = dir.path("texels.f32");
    let m: Vec<String> = matrix.as_flattened().iter().map(|v| format!("{v:e}")).collect();
    let run = std::process::Command::new(exe)
        .arg(&text)
        .arg(&input)
        .arg(&out)
        .args(&m)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let bytes = std::fs::read(&out).unwrap();
    let from_c: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_ne_bytes(b.try_into().unwrap())).collect();
    assert_eq!(from_c.len(), records.len() * (7 + n), "a row per record");
    let a = compact.weights();
    let mut found = Found { records: records.len(), ..Found::default() };
    let (mut lib_r, mut c_r) = (vec![0.0f32; n], vec![0.0f32; n]);
    for (k, (rec, row)) in records.iter().zip(from_c.chunks_exact(7 + n)).enumerate() {
        // The library's texel of the colour the C header was given, XYZ as float32.
        let xyz: [f32; 3] = if rec[3] == 1.0 {
            matrix.map(|m| (m[0] * f64::from(rec[0]) + m[1] * f64::from(rec[1]) + m[2] * f64::from(rec[2])) as f32)
        } else {
            [rec[0], rec[1], rec[2]]
        };
        let mut lib = [0.0f32; TEXEL];
        let counts = compact.encode_f32(&xyz, &mut lib);
        let lib_outcome = [counts.in_range, counts.projected, counts.outside, counts.not_finite]
            .iter()
            .position(|&v| v == 1)
            .unwrap() as f32;
        let (outcome, texel, decoded) = (row[0], &row[1..7], &row[7..]);
        for i in 0..3 {
            assert!(
                texel[i].to_bits() == lib[i].to_bits() || (texel[i].is_nan() && lib[i].is_nan()),
                "record {k} {rec:?}: the texel's colour {texel:?}, not {lib:?}"
            );
        }
        found.outcome_differs += usize::from(outcome != lib_outcome);
        compact.decode_f32(&lib, &mut lib_r);
        compact.decode_f32(texel, &mut c_r);
        for b in 0..n {
            let (l, c, d) = (lib_r[b], c_r[b], decoded[b]);
            if l.is_nan() || c.is_nan() || d.is_nan() {
                assert!(l.is_nan() && c.is_nan() && d.is_nan(), "record {k} {rec:?} band {b}: {l} {c} {d}");
                continue;
            }
            let u = |t: &[f32]| (0..3).map(|i| a[i][b].abs() * f64::from(t[3 + i]).abs()).sum::<f64>();
            let tol = bound(f64::from(l), u(&lib) + u(texel));
            for (who, v) in [("encoder", c), ("encoder and decoder", d)] {
                let ratio = (f64::from(v) - f64::from(l)).abs() / tol;
                if ratio > found.worst_ratio {
                    found.worst_ratio = ratio;
                    found.worst = format!(
                        "{who}: record {k} {rec:?} band {b}: {v} against {l} (outcomes {outcome} {lib_outcome}, u {:?} {:?})",
                        &texel[3..],
                        &lib[3..]
                    );
                }
            }
        }
    }
    found
}

/// The float32 bound on a band of value `v` between two texels of one colour, `au` the sum of
/// |a_b,k|·|u_k| of both texels' u: the projection's spectrum is unique, and each encoder rounds
/// u to float32 once (|a|·|u|·2⁻²⁴ each), the decoder rounds the band once (2⁻²⁴·|v|), and an
/// outside colour's u need only keep its search's spectrum within 2⁻¹³ of each band's value
/// (at least 2⁻¹⁴: `DUAL_F32_TOLERANCE`), from each side.
fn bound(v: f64, au: f64) -> f64 {
    2f64.powi(-23) * (au + 1.0) + 2.0 * 2f64.powi(-13) * v.abs().max(2f64.powi(-14))
}

/// 100,000 colours under the default conversion; 10,000 on another grid with the paper's hard
/// switch and under `--unbounded` (u = 0, no clip).
#[test]
fn the_c_header_makes_the_librarys_texels_from_colours() {
    let dir = Scratch::new("compact-encode");
    let exe = compile_c(&dir, "encode_check");
    let srgb = SRGB.to_xyz(SRGB.white_xyz());
    let mut d = Description::convert_default(MethodName::Otsu2018);
    let compact = Compact::new(Model::builtin(), "test", &d).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(100_000, 47), &dir);
    eprintln!("default: {found:?}");
    assert!(found.worst_ratio <= 1.0, "{found:?}");

    d.grid = Some("400:700:5".parse().unwrap());
    d.blend = 0.0;
    let paper = Model::builtin_named("paper").unwrap();
    let compact = Compact::new(paper, "paper", &d).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(10_000, 48), &dir);
    eprintln!("paper 400:700:5 blend 0: {found:?}");
    assert!(found.worst_ratio <= 1.0, "{found:?}");

    let mut unbounded = Description::convert_default(MethodName::Otsu2018);
    unbounded.bounded = false;
    let compact = Compact::new(Model::builtin(), "test", &unbounded).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(10_000, 49), &dir);
    eprintln!("unbounded: {found:?}");
    assert!(found.worst_ratio <= 1.0, "{found:?}");
}
