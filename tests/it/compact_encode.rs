//! Issue 47: the C header makes texels from colours (include/specconv_spectrum.h's encoder,
//! through tests/c/encode_check.c) as the library makes them (`Compact::encode_f32`), for
//! 100,000 random colours of every kind a texture holds or a careless caller passes.

use crate::compact::{compile_c, compile_with};
use specconv_colour::rgb::{ACESCG, SRGB};
use specconv_spectral::compact::{Compact, TEXEL};
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::StackSpec;
use specconv_spectral::Model;
use specconv_testkit::cmd::Scratch;
use specconv_testkit::SplitMix;

/// A record of the C program: a colour and its kind (0: XYZ, 1: RGB through the matrix).
type Record = [f32; 4];

/// `count` colours, a kind each in turn: sRGB texels and HDR ones (through the C header's RGB
/// entry), ACEScg colours outside sRGB and beyond the spectral locus, any XYZ in [−0.5, 1.5]³,
/// greys round the perfect white (a vertex of the solid), tiny colours down to subnormal
/// float32 (the dark rule), and the special values: black, −0, NaN and ±∞ in one component,
/// the largest float, negative sums.
fn colours(count: usize, seed: u64) -> Vec<Record> {
    let mut rng = SplitMix(seed);
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
            let r = |rng: &mut SplitMix, a, b| rng.in_range(a, b);
            match i % 8 {
                0 => [
                    r(&mut rng, 0.0, 1.0),
                    r(&mut rng, 0.0, 1.0),
                    r(&mut rng, 0.0, 1.0),
                ]
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
                    let s = special[(rng.next_u64() % special.len() as u64) as usize];
                    [s[0], s[1], s[2], 0.0]
                }
                _ => {
                    // Saturated sRGB near the gamut's edges, scaled up a little.
                    let k = r(&mut rng, 0.5, 1.3);
                    let c = [0; 3]
                        .map(|_| (k * (rng.next_u64() % 2) as f64 * r(&mut rng, 0.9, 1.0)) as f32);
                    [c[0], c[1], c[2], 1.0]
                }
            }
        })
        .collect()
}

fn to_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

/// What the comparison found.
#[derive(Debug, Default)]
struct Found {
    /// The largest band difference over the float32 bound, colours not outside the solid.
    worst_ratio: f64,
    worst: String,
    /// The C header's decoding of its texel against the library's, over the bound.
    decoder_ratio: f64,
    /// Outside the solid (either side): all, those within the float32 bound, and the largest
    /// ΔE76 from the input beyond the library's (and 1 % of it) of the others.
    outside: usize,
    outside_alike: usize,
    outside_worst: f64,
    outcome_differs: usize,
}

/// ΔE76 between the colour `c` and that of spectrum `r` (the model's A, D65 white).
fn delta_e(a: &[Vec<f64>; 3], c: [f64; 3], r: &[f32]) -> f64 {
    use specconv_colour::lab::xyz_to_lab;
    let white = a.each_ref().map(|w| w.iter().sum::<f64>());
    let x = a
        .each_ref()
        .map(|w| w.iter().zip(r).map(|(w, &v)| w * f64::from(v)).sum::<f64>());
    let (p, q) = (xyz_to_lab(c, white), xyz_to_lab(x, white));
    (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt()
}

/// Runs the C encoder (the program `exe`) on `records` under `compact`'s text: a row per record,
/// the outcome, the texel and its spectrum as the header decodes it.
fn run_encoder(
    exe: &std::path::Path,
    compact: &Compact,
    matrix: [[f64; 3]; 3],
    records: &[Record],
    dir: &Scratch,
) -> Vec<f32> {
    let n = compact.grid().len();
    let text = dir.write("model.txt", &compact.to_text());
    let input = dir.path("colours.f32");
    std::fs::write(&input, to_bytes(records.as_flattened())).unwrap();
    let out = dir.path("texels.f32");
    let m: Vec<String> = matrix
        .as_flattened()
        .iter()
        .map(|v| format!("{v:e}"))
        .collect();
    let run = std::process::Command::new(exe)
        .arg(&text)
        .arg(&input)
        .arg(&out)
        .args(&m)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let bytes = std::fs::read(&out).unwrap();
    let from_c: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_ne_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(from_c.len(), records.len() * (7 + n), "a row per record");
    from_c
}

/// Encodes `records` with the library and with the C header (the program `exe`), and compares
/// the texels' colours (bit for bit) and their spectra, each decoded by the library: within
/// the float32 bound of [`bound`] for every colour not outside the object-colour solid; for
/// those outside, within it or, where the search ended elsewhere, as near the input in CIELAB
/// (the ΔE76 beyond the library's + 1 % is `outside_worst`, bounded by [`holds`]). The C
/// header's own decoding of its texel: within the bound of the library's decoding of it.
fn compare(
    exe: &std::path::Path,
    compact: &Compact,
    matrix: [[f64; 3]; 3],
    records: &[Record],
    dir: &Scratch,
) -> Found {
    let n = compact.grid().len();
    let from_c = run_encoder(exe, compact, matrix, records, dir);
    let a = compact.weights();
    let mut found = Found::default();
    let (mut lib_r, mut c_r) = (vec![0.0f32; n], vec![0.0f32; n]);
    for (k, (rec, row)) in records.iter().zip(from_c.chunks_exact(7 + n)).enumerate() {
        // The library's texel of the colour the C header was given, XYZ as float32.
        let xyz: [f32; 3] = if rec[3] == 1.0 {
            matrix.map(|m| {
                (m[0] * f64::from(rec[0]) + m[1] * f64::from(rec[1]) + m[2] * f64::from(rec[2]))
                    as f32
            })
        } else {
            [rec[0], rec[1], rec[2]]
        };
        let mut lib = [0.0f32; TEXEL];
        let counts = compact.encode_f32(&xyz, &mut lib);
        let lib_outcome = [
            counts.in_range,
            counts.projected,
            counts.outside,
            counts.not_finite,
        ]
        .iter()
        .position(|&v| v == 1)
        .unwrap_or(0) as f32; // unbounded: nothing counted, u = 0
        let (outcome, texel, decoded) = (row[0], &row[1..7], &row[7..]);
        let same = |x: &f32, y: &f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
        assert!(
            texel[..3].iter().zip(&lib[..3]).all(|(x, y)| same(x, y)),
            "record {k} {rec:?}: the texel's colour {texel:?}, not {lib:?}"
        );
        found.outcome_differs += usize::from(outcome != lib_outcome);
        compact.decode_f32(&lib, &mut lib_r);
        compact.decode_f32(texel, &mut c_r);
        let u = |t: &[f32], b: usize| {
            (0..3)
                .map(|i| a[i][b].abs() * f64::from(t[3 + i]).abs())
                .sum::<f64>()
        };
        let mut ratio = 0.0f64;
        for b in 0..n {
            let (l, c, d) = (lib_r[b], c_r[b], decoded[b]);
            if l.is_nan() || c.is_nan() || d.is_nan() {
                assert!(
                    l.is_nan() && c.is_nan() && d.is_nan(),
                    "record {k} {rec:?} band {b}: {l} {c} {d}"
                );
                continue;
            }
            let tol = texel_bound(f64::from(l), u(&lib, b) + u(texel, b));
            ratio = ratio.max((f64::from(c) - f64::from(l)).abs() / tol);
            // The library decodes u = 0 texels in float32 (maps and sums), the header in double:
            // float32's rounding of terms up to 16 times the colour's size.
            let size = 1.0 + xyz.iter().map(|v| f64::from(v.abs())).sum::<f64>();
            let dtol = bound(f64::from(c), 2.0 * u(texel, b)) + 2f64.powi(-20) * size;
            found.decoder_ratio = found
                .decoder_ratio
                .max((f64::from(d) - f64::from(c)).abs() / dtol);
        }
        let outside = outcome == 2.0 || lib_outcome == 2.0;
        if !outside {
            if ratio > found.worst_ratio {
                found.worst_ratio = ratio;
                found.worst = format!("record {k} {rec:?}: texels {texel:?} {lib:?}, outcomes {outcome} {lib_outcome}");
            }
            continue;
        }
        found.outside += 1;
        if ratio <= 1.0 {
            found.outside_alike += 1;
            continue;
        }
        let c64 = xyz.map(f64::from);
        let (de_c, de_lib) = (delta_e(a, c64, &c_r), delta_e(a, c64, &lib_r));
        found.outside_worst = found.outside_worst.max(de_c - 1.01 * de_lib);
    }
    found
}

/// The float32 bound on a band of value `v` between two texels of one colour, `au` the sum of
/// |a_b,k|·|u_k| of both texels' u: the projection's spectrum is unique, each encoder rounds u
/// to float32 once (|a|·|u|·2⁻²⁴ each), and the decoder rounds the band once (2⁻²⁴·|v|). An
/// outside colour's spectrum is made from its float32 u, so it needs nothing more (before the
/// regularised projection, 2·2⁻¹³·max(|v|, 2⁻¹⁴) more: the tolerance of a pull).
fn texel_bound(v: f64, au: f64) -> f64 {
    2f64.powi(-23) * (au + 1.0 + v.abs())
}

/// [`texel_bound`] with a relative term for decodings that round more than once (2·2⁻¹³ of the
/// value, at least of 2⁻¹⁴): the header's decoding against the library's float32 one, and the
/// example program's interpolated values.
fn bound(v: f64, au: f64) -> f64 {
    2f64.powi(-23) * (au + 1.0) + 2.0 * 2f64.powi(-13) * v.abs().max(2f64.powi(-14))
}

/// The bounds of [`compare`]: every texel within the float32 bound, outside the solid too, and
/// the C header's decoding within it. An outside colour's u is the end of the CIELAB search and
/// a projection, so this holds only while the port computes r₀, the search and the projection
/// bit for bit as the library does (before issue 45, 453 of 56,801 outside texels were not;
/// the ΔE76 beyond the library's + 1 % of those, `outside_worst`, shows how far apart a
/// failure is).
fn holds(found: &Found) {
    assert!(found.worst_ratio <= 1.0, "{found:?}");
    assert!(found.decoder_ratio <= 1.0, "{found:?}");
    assert_eq!(found.outside_alike, found.outside, "{found:?}");
}

/// 100,000 colours under the default conversion; 10,000 on another grid with the paper's hard
/// switch and under `--unbounded` (u = 0, no clip).
#[test]
fn the_c_header_makes_the_librarys_texels_from_colours() {
    let dir = Scratch::new("compact-encode");
    let exe = compile_c(&dir, "encode_check");
    let srgb = SRGB.to_xyz(SRGB.white_xyz());
    let mut d = StackSpec::convert_default(MethodName::Otsu2018);
    let compact = Compact::new(Model::builtin(), "test", &d).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(100_000, 47), &dir);
    eprintln!("default: {found:?}");
    holds(&found);

    d.grid = Some("400:700:5".parse().unwrap());
    d.blend = 0.0;
    let paper = Model::builtin_named("paper").unwrap();
    let compact = Compact::new(paper, "paper", &d).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(10_000, 48), &dir);
    eprintln!("paper 400:700:5 blend 0: {found:?}");
    holds(&found);

    let mut unbounded = StackSpec::convert_default(MethodName::Otsu2018);
    unbounded.bounded = false;
    let compact = Compact::new(Model::builtin(), "test", &unbounded).unwrap();
    let found = compare(&exe, &compact, srgb, &colours(10_000, 49), &dir);
    eprintln!("unbounded: {found:?}");
    holds(&found);
}

/// examples/c/texels_from_exr.c, compiled with OpenEXR's C API (pkg-config's OpenEXR, Debian's
/// libopenexr-dev) as docs/compact.md shows.
fn compile_example(dir: &Scratch) -> std::path::PathBuf {
    let flags = std::process::Command::new("pkg-config")
        .args(["--cflags", "--libs", "OpenEXR"])
        .output()
        .expect("pkg-config on PATH");
    assert!(
        flags.status.success(),
        "OpenEXR's development files are missing (Debian: apt-get install libopenexr-dev): {}",
        String::from_utf8_lossy(&flags.stderr)
    );
    let flags = String::from_utf8(flags.stdout).unwrap();
    let flags: Vec<&str> = flags.split_whitespace().collect();
    compile_with(dir, "examples/c/texels_from_exr.c", &flags)
}

/// The pixels of an RGB OpenEXR as the `exr` crate reads them (not OpenEXR's C API, which
/// the example uses), row after row.
fn exr_pixels(path: &std::path::Path) -> Vec<[f32; 3]> {
    exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .unwrap()
    .layer_data
    .channel_data
    .pixels
    .1
}

/// One pixel's line of the example ("x y R G B X Y Z u0 u1 u2 r"): the pixel `px` the `exr`
/// crate reads, the library's texel colour bit for bit, and r the library's spectrum at the
/// wavelength (`hi`: the band above, `f`: the fraction from the one below) within the float32
/// bound, or for a colour outside the solid, a texel as near the input in CIELAB (as
/// [`compare`] holds them). Returns 1 for a colour outside the solid or not finite.
fn example_line(
    compact: &Compact,
    matrix: [[f64; 3]; 3],
    (hi, f): (usize, f64),
    name: &str,
    line: &str,
    px: [f32; 3],
) -> usize {
    let (n, a) = (compact.grid().len(), compact.weights());
    let v: Vec<f32> = line.split(' ').map(|w| w.parse().unwrap()).collect();
    let same = |x: f32, y: f32| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
    assert!(
        (0..3).all(|k| same(v[2 + k], px[k])),
        "{name}: read {line}, not {px:?}"
    );
    let xyz = matrix.map(|m| (0..3).map(|k| m[k] * f64::from(px[k])).sum::<f64>() as f32);
    let mut lib = [0.0f32; TEXEL];
    let counts = compact.encode_f32(&xyz, &mut lib);
    assert!(
        (0..3).all(|k| same(v[5 + k], lib[k])),
        "{name}: {line}: texel {lib:?}"
    );
    let mut r = vec![0.0f32; n];
    compact.decode_f32(&lib, &mut r);
    let want = (1.0 - f) * f64::from(r[hi - 1]) + f * f64::from(r[hi]);
    let got = f64::from(v[11]);
    let odd = counts.outside + counts.not_finite;
    if want.is_nan() {
        assert!(got.is_nan(), "{name}: {line}");
        return odd;
    }
    let au = |b: usize| {
        (0..3)
            .map(|i| a[i][b].abs() * (f64::from(v[8 + i]).abs() + f64::from(lib[3 + i]).abs()))
            .sum::<f64>()
    };
    let tol = bound(
        want.abs().max(f64::from(r[hi - 1].max(r[hi]))),
        au(hi - 1).max(au(hi)),
    );
    if (got - want).abs() > tol {
        // Outside the solid the search may end elsewhere, as near the input.
        let mut mine = vec![0.0f32; n];
        compact.decode_f32(&v[5..11], &mut mine);
        let c64 = xyz.map(f64::from);
        let (de_c, de_lib) = (delta_e(a, c64, &mine), delta_e(a, c64, &r));
        assert!(
            counts.outside == 1 && de_c <= 1.01 * de_lib + 2.5,
            "{name}: {line}: {got} against {want} (±{tol}), ΔE76 {de_c} against {de_lib}"
        );
    }
    odd
}

/// The C example reads a float scanline chart (out of gamut, HDR, black, NaN) and a half
/// tiled photograph through OpenEXR's C API, makes texels and decodes them at 532 nm: the
/// pixels the `exr` crate reads, the library's texels of their colours and the library's
/// spectrum at 532 nm (its bands' linear interpolation), within the encoder's bound.
#[test]
fn the_c_example_makes_the_librarys_texels_of_an_exr() {
    use specconv_testkit::cmd::script;
    let dir = Scratch::new("compact-encode-example");
    let exe = compile_example(&dir);
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let chart = dir.path("chart.exr");
    script("compact_check.py", ["chart", chart.to_str().unwrap()]);
    let photo = dir.path("photo.exr");
    let oiio = std::process::Command::new("oiiotool")
        .arg(root.join("testdata/images/photo.jpg"))
        .args([
            "--colorconvert",
            "sRGB",
            "linear",
            "-d",
            "half",
            "--tile",
            "16",
            "16",
            "-o",
        ])
        .arg(&photo)
        .output()
        .expect("oiiotool on PATH");
    assert!(
        oiio.status.success(),
        "{}",
        String::from_utf8_lossy(&oiio.stderr)
    );

    let d = StackSpec::convert_default(MethodName::Otsu2018);
    let compact = Compact::new(Model::builtin(), "test", &d).unwrap();
    let text = dir.write("model.txt", &compact.to_text());
    let matrix = SRGB.to_xyz(SRGB.white_xyz());
    let nm = 532.0;
    let grid = compact.grid().wavelengths();
    let hi = grid.iter().position(|&w| w > nm).unwrap();
    let f = (nm - grid[hi - 1]) / (grid[hi] - grid[hi - 1]);
    for (name, image, least) in [("chart", &chart, 2), ("photo", &photo, 0)] {
        let out = std::process::Command::new(&exe)
            .arg(&text)
            .arg(image)
            .arg(nm.to_string())
            .args(matrix.as_flattened().iter().map(|v| format!("{v:e}")))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = String::from_utf8(out.stdout).unwrap();
        let pixels = exr_pixels(image);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(
            lines.len(),
            pixels.len() + 1,
            "{name}: a line per pixel and a summary"
        );
        let outside_or_nan: usize = lines
            .iter()
            .zip(&pixels)
            .map(|(line, px)| example_line(&compact, matrix, (hi, f), name, line, *px))
            .sum();
        let summary = lines.last().unwrap();
        assert!(
            summary.starts_with(&format!("texels={} ", pixels.len())),
            "{summary}"
        );
        assert!(
            outside_or_nan >= least,
            "{name}: {outside_or_nan} outside or NaN: the case is covered"
        );
    }
}
