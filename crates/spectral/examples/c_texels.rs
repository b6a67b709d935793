//! Texels per second: the C header's encoder (include/specconv_spectrum.h, `scs_encode_rgb`)
//! against the library's (`Compact::encode_f32`), one thread each, in one run (issue 47,
//! docs/compact.md). Two sets of N colours (a seeded stream, the same every run): linear sRGB
//! uniform in [0, 1)³ (a texture's colours: most in range, some projected), and saturated or
//! HDR sRGB (most outside the object-colour solid). The C side is tests/c/encode_check.c
//! compiled with `cc -O2`, timed as a process: its run on the colours repeated R times, less its
//! run on none (start-up and parsing). Best of 3 for both.
//!
//!     cargo run -j 1 -p specconv-spectral --example c_texels [N]   # the dev profile optimises the library

use specconv_colour::rgb::SRGB;
use specconv_spectral::compact::{Compact, TEXEL};
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::StackSpec;
use specconv_spectral::Model;
use specconv_testkit::SplitMix;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

fn main() {
    let count: usize = std::env::args()
        .nth(1)
        .map_or(200_000, |v| v.parse().expect("N: a count"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = std::env::temp_dir().join(format!("specconv-c-texels-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exe = dir.join("encode_check");
    let cc = Command::new("cc")
        .args(["-std=c99", "-O2", "-I"])
        .arg(root.join("include"))
        .arg(root.join("tests/c/encode_check.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-lm")
        .status()
        .expect("cc on PATH");
    assert!(cc.success(), "cc failed");

    let d = StackSpec::convert_default(MethodName::Otsu2018);
    let compact = Compact::new(Model::builtin(), "bench", &d).unwrap();
    let text = dir.join("model.txt");
    std::fs::write(&text, compact.to_text()).unwrap();
    let matrix = SRGB.to_xyz(SRGB.white_xyz());
    let mut rng = SplitMix(47);
    let texture: Vec<[f32; 3]> = (0..count)
        .map(|_| [0; 3].map(|_| rng.uniform() as f32))
        .collect();
    let saturated: Vec<[f32; 3]> = (0..count / 10)
        .map(|_| {
            let k = 10f64.powf(2.0 * rng.uniform() - 0.5);
            [0; 3].map(|_| (k * (rng.uniform() * rng.uniform()).powi(2)) as f32)
        })
        .collect();
    println!(
        "C header against the library, one thread, {} bands",
        compact.grid().len()
    );
    for (name, rgb) in [("sRGB [0, 1)", &texture), ("saturated or HDR", &saturated)] {
        let xyz: Vec<f32> = rgb
            .iter()
            .flat_map(|c| {
                matrix.map(|m| (0..3).map(|k| m[k] * f64::from(c[k])).sum::<f64>() as f32)
            })
            .collect();
        let mut texels = vec![0.0f32; rgb.len() * TEXEL];
        let lib = best_of_3(|| {
            let counts = compact.encode_f32(&xyz, &mut texels);
            std::hint::black_box(counts);
        });
        let records: Vec<u8> = rgb
            .iter()
            .flat_map(|c| [c[0], c[1], c[2], 1.0])
            .flat_map(f32::to_ne_bytes)
            .collect();
        let colours = dir.join("colours.f32");
        std::fs::write(&colours, records).unwrap();
        let repeat = 3;
        let c = best_of_3(|| run_c(&exe, &text, &colours, repeat, matrix))
            - best_of_3(|| run_c(&exe, &text, &colours, 0, matrix));
        let lib_rate = rgb.len() as f64 / lib;
        let c_rate = (repeat * rgb.len()) as f64 / c;
        let counts = compact.encode_f32(&xyz, &mut texels);
        println!(
            "{name:>18}: {} colours ({} in range, {} projected, {} outside): library {:.3} M texels/s, C {:.3} M texels/s, C/library {:.2}",
            rgb.len(),
            counts.in_range,
            counts.projected,
            counts.outside,
            lib_rate / 1e6,
            c_rate / 1e6,
            c_rate / lib_rate
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The C encoder over every record `repeat` times, as a process.
fn run_c(exe: &Path, text: &Path, colours: &Path, repeat: usize, m: [[f64; 3]; 3]) {
    let out = Command::new(exe)
        .arg("--bench")
        .arg(text)
        .arg(colours)
        .arg(repeat.to_string())
        .args(m.as_flattened().iter().map(|v| format!("{v:e}")))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The best wall time of three runs of `f`, in seconds.
fn best_of_3(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}
