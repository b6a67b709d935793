//! Item 47.4: one decoding rule, one set of reference texels. testdata/compact/reference holds
//! texels and the spectra the library decodes them to, written here from the library's own
//! encoder and decoder: hostile colours (black, NaN, ±∞, HDR beyond half, outside the
//! object-colour solid, negative, dark, in the tree's blend bands), texels with u set by hand
//! (half and float u, infinite and NaN u), under both `clip` headers and both texel
//! precisions. The other decoders (numpy, the C header, Dr.Jit) are held to these files
//! (tests/it/compact.rs, python/tests/test_compact.py, python/tests/test_mitsuba_compact.py).
//!
//! The test fails when the files are not what the library writes now; to rewrite them:
//! `SPECCONV_UPDATE_GENERATED=1 cargo test -p specconv-spectral --test spectral reference_texels`.

use specconv_spectral::compact::{Compact, Precision, STORED, TEXEL};
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::StackSpec;
use specconv_spectral::Model;
use std::fmt::Write;
use std::path::PathBuf;

fn here() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../testdata/compact/reference")
}

/// XYZ colours of every kind a texture may hold (Y = 1 white).
fn colours() -> Vec<[f32; 3]> {
    let (inf, nan) = (f32::INFINITY, f32::NAN);
    let mut v = vec![
        [0.0, 0.0, 0.0],
        [0.9505, 1.0, 1.089],
        [0.1711, 0.18, 0.196],
        [nan, 0.2, 0.3],
        [0.2, inf, 0.3],
        [0.2, 0.3, -inf],
        [12.0, 10.0, 8.0],
        [300.0, 20.0, 1.0],
        [1e5, 9e4, 8e4],
        [3e38, 1e38, 1e38],
        [0.6, 0.1, 0.02],
        [0.05, 0.3, 0.9],
        [0.45, 0.7, 0.02],
        [-0.1, 0.05, 0.2],
        [-0.2, -0.1, 0.05],
        [2e-4, 1e-4, 3e-4],
        [1e-9, 2e-9, 1e-9],
        [0.31, 0.33, 0.36],
        [0.3127, 0.329, 0.3583],
    ];
    // Ordinary and saturated colours, spread (a fixed sequence: the files stay the same).
    let mut s = 0x2545_f491_u32;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        f64::from(s) / f64::from(u32::MAX)
    };
    for i in 0..40 {
        let scale = [1.0, 0.05, 3.0, 1.0][i % 4];
        v.push([next(), next(), next()].map(|x| (x * scale) as f32));
    }
    v
}

/// Stored texels with u set by hand (half u, float u, infinite and NaN u), colour 0.1875 0.3125 0.25.
fn by_hand() -> Vec<[f32; STORED]> {
    let c = [0.1875, 0.3125, 0.25]; // halves: valid in both precisions
    let row = |u: [f32; 3], uf: [f32; 3]| {
        let mut t = [0.0; STORED];
        t[..3].copy_from_slice(&c);
        t[3..6].copy_from_slice(&u);
        t[6..].copy_from_slice(&uf);
        t
    };
    vec![
        row([0.5, -0.25, 0.125], [0.0; 3]),
        row([0.0; 3], [1000.5, 0.0, -200.25]),
        row([f32::INFINITY, 0.0, 0.0], [0.0; 3]),
        row([0.0; 3], [0.0, f32::NAN, 0.0]),
    ]
}

fn compact(bounded: bool) -> Compact {
    let mut d = StackSpec::convert_default(MethodName::Otsu2018);
    d.bounded = bounded;
    Compact::new(Model::builtin(), "builtin", &d).unwrap()
}

fn join(v: &[f32]) -> String {
    v.iter().map(f32::to_string).collect::<Vec<_>>().join(" ")
}

/// The table of one header and precision: a line a texel, `STORED = TEXEL = BANDS`.
fn table(c: &Compact, precision: Precision, header: &str) -> String {
    let n = c.grid().len();
    let mut rgb: Vec<f32> = colours().concat();
    c.xyz_to_rgb(&mut rgb);
    let mut stored: Vec<f32> = rgb
        .chunks_exact(3)
        .flat_map(|v| [v[0], v[1], v[2], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .collect();
    c.store(&mut stored, precision);
    stored.extend(by_hand().concat());
    let count = stored.len() / STORED;
    let mut texels = vec![0.0f32; count * TEXEL];
    c.unstore(&stored, &mut texels);
    let mut bands = vec![0.0f32; count * n];
    c.decode_f32(&texels, &mut bands);
    let mut t = format!(
        "# specconv compact reference texels, written by the library (crates/spectral/tests/spectral/reference_texels.rs)\n\
         header {header}\nprecision {}\nbands {n}\n",
        match precision {
            Precision::Half => "half",
            Precision::Float => "float",
        }
    );
    let rows = stored
        .chunks_exact(STORED)
        .zip(texels.chunks_exact(TEXEL))
        .zip(bands.chunks_exact(n));
    for ((s, x), r) in rows {
        let _ = writeln!(t, "{} = {} = {}", join(s), join(x), join(r));
    }
    t
}

/// Every file as the library writes it now, by name.
fn files() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (clip, bounded) in [("clip1", true), ("clip0", false)] {
        let c = compact(bounded);
        let header = format!("{clip}.header");
        out.push((header.clone(), c.to_text()));
        for (p, precision) in [("half", Precision::Half), ("float", Precision::Float)] {
            out.push((format!("{clip}-{p}.txt"), table(&c, precision, &header)));
        }
    }
    out
}

#[test]
fn reference_texels_are_current() {
    let update = std::env::var_os("SPECCONV_UPDATE_GENERATED").is_some();
    if update {
        std::fs::create_dir_all(here()).unwrap();
    }
    for (name, text) in files() {
        let path = here().join(&name);
        if update {
            std::fs::write(&path, &text).unwrap();
            continue;
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            on_disk == text,
            "{} is not what the library writes now: SPECCONV_UPDATE_GENERATED=1 cargo test -p specconv-spectral --test spectral reference_texels",
            path.display()
        );
    }
}

/// The files hold what they claim: every kind of texel is there (u as half and as float32,
/// NaN texels, clipped and unclipped), and the header's text reads back to the same decoder.
#[test]
fn reference_texels_cover_the_hostile_cases() {
    for (name, text) in files() {
        if name.ends_with(".header") {
            let c = Compact::from_text(&text).unwrap();
            assert_eq!(c.to_text(), text, "{name}");
            continue;
        }
        let rows: Vec<Vec<f32>> = text
            .lines()
            .filter(|l| l.contains(" = "))
            .map(|l| l.split(" = ").next().unwrap())
            .map(|s| s.split(' ').map(|v| v.parse().unwrap()).collect())
            .collect();
        let half_u = rows.iter().filter(|r| r[3..6] != [0.0; 3]).count();
        let float_u = rows.iter().filter(|r| r[6..9] != [0.0; 3]).count();
        let nan = rows
            .iter()
            .filter(|r| r.iter().any(|v| !v.is_finite()))
            .count();
        assert!(
            half_u >= 2 && float_u >= 2 && nan >= 5,
            "{name}: {half_u} {float_u} {nan}"
        );
        if name.contains("half") {
            assert!(rows.iter().all(|r| r[..3]
                .iter()
                .all(|&v| !v.is_finite() || half::f16::from_f32(v).to_f32() == v)));
        }
    }
}
