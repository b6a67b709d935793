//! The compact layout (docs/compact.md): `convert --layout compact`, then `specconv expand`,
//! gives the spectral file `convert` writes directly, sample for sample within one half step,
//! every level; read by OpenImageIO (tests/compact_check.py), not by our reader.

use specconv_testkit::cmd::{script, script_json, Cmd, Scratch};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Converts `input` both ways with `extra`, expands the compact file and compares every
/// sample of every level; returns the fraction stored identically (all within one step).
fn expand_matches_convert(dir: &Scratch, input: &Path, name: &str, extra: &[&str]) -> f64 {
    let direct = dir.path(&format!("{name}_spectral.exr"));
    let compact = dir.path(&format!("{name}_compact.exr"));
    let expanded = dir.path(&format!("{name}_expanded.exr"));
    Cmd::convert(input, &direct).args(extra).ok();
    Cmd::convert(input, &compact)
        .args(extra)
        .args(["--layout", "compact"])
        .ok();
    Cmd::new(["expand"]).arg(&compact).arg(&expanded).ok();
    let levels = script_json("compact_check.py", ["steps", s(&direct), s(&expanded)]);
    let levels = levels.as_array().unwrap();
    assert!(!levels.is_empty());
    let (mut same, mut all) = (0.0, 0.0);
    for l in levels {
        // Level 0 within one half step; the filtered levels carry level 0's float32
        // differences (up to a quarter half step at a band's value) into smaller values, and
        // filters with negative lobes add some: 3 steps at most measured.
        let most = if l["level"] == 0 { 1 } else { 4 };
        assert!(l["max_steps"].as_u64().unwrap() <= most, "{name}: {l}");
        let n = l["samples"].as_f64().unwrap();
        same += l["identical"].as_f64().unwrap() * n;
        all += n;
    }
    same / all
}

#[test]
fn expanded_compact_textures_are_what_convert_writes_within_one_half_step() {
    let dir = Scratch::new("compact-expand");
    let images = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images");
    let chart = dir.path("chart.exr");
    script("compact_check.py", ["chart", s(&chart)]);
    let keep = ["--fixnan", "keep"];
    let cases: Vec<(&str, std::path::PathBuf, Vec<&str>)> = vec![
        ("photo", images.join("photo.jpg"), vec![]),
        ("alpha", images.join("srgba8.png"), vec![]),
        ("chart", chart.clone(), keep.to_vec()),
        (
            "grid",
            chart.clone(),
            [&keep[..], &["--bands", "400:700:5"]].concat(),
        ),
        (
            "paper",
            images.join("photo.jpg"),
            vec!["--model", "paper", "--blend", "0"],
        ),
        (
            "open",
            chart.clone(),
            [&keep[..], &["--model", "open"]].concat(),
        ),
        ("float", images.join("sky.hdr"), vec!["-d", "float"]),
        (
            "lanczos3",
            images.join("sky.hdr"),
            vec!["--filter", "lanczos3"],
        ),
        (
            "unbounded",
            images.join("photo.jpg"),
            vec!["--unbounded", "--half-rounding", "colour"],
        ),
        (
            "colour",
            images.join("photo.jpg"),
            vec!["--half-rounding", "colour"],
        ),
    ];
    for (name, input, extra) in cases {
        let same = expand_matches_convert(&dir, &input, name, &extra);
        eprintln!("{name}: {:.4} % of samples identical", 100.0 * same);
        // Float samples differ in the last bits where u ≠ 0.
        assert!(
            same > if name == "float" { 0.8 } else { 0.99 },
            "{name}: {same}"
        );
    }
}

#[test]
fn what_has_no_compact_form_is_refused_with_why() {
    let dir = Scratch::new("compact-refused");
    let png = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images/srgba8.png");
    let out = dir.path("out.exr");
    let compact = |extra: &[&str]| {
        Cmd::convert(&png, &out)
            .args(extra)
            .args(["--layout", "compact"])
    };
    compact(&["--emissive"]).fails(2, &["emission"]);
    compact(&["--method", "smits1999"]).fails(2, &["clustered"]);
    compact(&["--resize"]).fails(2, &["resize"]);
    // A spectral file is no compact texture.
    let spectral = dir.path("spectral.exr");
    Cmd::convert(&png, &spectral).ok();
    Cmd::new(["expand"])
        .arg(&spectral)
        .arg(dir.path("back.exr"))
        .fails(1, &["not a compact texture"]);
}
