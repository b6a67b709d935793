//! `specconv simulate`: the example scenes and malformed ones.

use crate::runner::*;
use std::path::PathBuf;

fn scene(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn series(v: &serde_json::Value, method: &str) -> Vec<f64> {
    v["mean_delta_e"][method]
        .as_array()
        .unwrap_or_else(|| panic!("no {method} in {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn the_furnace_example_shows_the_papers_drift() {
    // The scene file points at ../shared beside the checkout, as the tests do.
    shared("spectra/munsell1269_matte_380-800_1nm.csv");
    let out = Cmd::new([
        "simulate",
        "--scene",
        scene("furnace_5500k.toml").to_str().unwrap(),
        "--json",
    ])
    .run();
    let v = json(out.ok());
    assert_eq!(v["patches"], 1269);
    assert_eq!(v["counts"].as_array().unwrap().len(), 9);
    assert!(v.get("per_patch").is_none(), "1269 patches: means only");
    let (o, s, m, rgb) = (
        series(&v, "otsu2018"),
        series(&v, "smits1999"),
        series(&v, "meng2015"),
        series(&v, "rgb"),
    );
    for k in 1..=8 {
        assert!(o[k] < s[k] && o[k] < m[k] && o[k] < rgb[k], "K={k}");
        if k > 1 {
            assert!(s[k] > s[k - 1] && m[k] > m[k - 1], "K={k}");
        }
    }
    // The text report has the same table.
    let text = Cmd::new([
        "simulate",
        "--scene",
        scene("furnace_5500k.toml").to_str().unwrap(),
    ])
    .run();
    let t = text.ok();
    assert!(
        t.contains("mean CIEDE2000 from the measured reference"),
        "{t}"
    );
    assert!(t.contains(&format!("{:.4}", o[8])), "{t}");
}

#[test]
fn the_box_example_reports_every_wall() {
    shared("spectra/munsell1269_matte_380-800_1nm.csv");
    let out = Cmd::new([
        "simulate",
        "--scene",
        scene("box_4000k_5500k.toml").to_str().unwrap(),
        "--json",
    ])
    .run();
    let v = json(out.ok());
    let walls: Vec<&str> = v["per_patch"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(walls, ["floor", "ceiling", "back", "left", "right"]);
    for p in v["per_patch"].as_array().unwrap() {
        for (method, cells) in p["colours"].as_object().unwrap() {
            for c in cells.as_array().unwrap() {
                let d = c["delta_e"].as_f64();
                assert!(d.is_some_and(f64::is_finite), "{method}: {c}");
                if method == "measured" {
                    assert_eq!(d, Some(0.0));
                }
            }
        }
    }
    // The red wall sees only bounced light: black at count 0, red after.
    let left = &v["per_patch"][3]["colours"]["measured"];
    assert_eq!(left[0]["srgb"], serde_json::json!([0.0, 0.0, 0.0]));
    let rgb = left[1]["srgb"].as_array().unwrap();
    assert!(rgb[0].as_f64().unwrap() > 2.0 * rgb[1].as_f64().unwrap());
}

/// A scene of two Munsell chips under 5500 K, `body` (top-level keys) first.
fn write_scene(s: &Scratch, body: &str) -> PathBuf {
    let munsell = munsell();
    s.write(
        "scene.toml",
        &format!(
            "{body}\n[[lights]]\nspectrum = \"blackbody:5500\"\npower = 1.0\n\n[[patches]]\nspectra = {:?}\nsamples = [\"5R 4/14\", \"5B 7/2\"]\n",
            munsell.to_str().unwrap()
        ),
    )
}

fn run(path: &std::path::Path) -> Output {
    Cmd::new(["simulate", "--scene", path.to_str().unwrap()]).run()
}

#[test]
fn a_matrix_scene_converges_and_colours_need_no_reference() {
    let s = Scratch::new("simulate-matrix");
    let p = write_scene(
        &s,
        "effect = \"converged\"\nform_factors = [[0.0, 0.5], [0.5, 0.0]]\n",
    );
    let v = Cmd::new(["simulate", "--scene", p.to_str().unwrap(), "--json"])
        .ok()
        .json();
    assert_eq!(v["counts"], serde_json::json!(["converged"]));
    assert!(series(&v, "otsu2018")[0].is_finite());
    // A colour-only patch has no measured reference: ΔE from RGB multiplication only.
    let p = s.write(
        "colour.toml",
        "bounces = 2\nform_factors = \"furnace\"\n[[lights]]\nspectrum = \"D65\"\npower = 2\n\
         [[patches]]\nname = \"red\"\ncolour = [0.8, 0.1, 0.1]\ncolorspace = \"sRGB - Texture\"\n",
    );
    let v = Cmd::new(["simulate", "--scene", p.to_str().unwrap(), "--json"])
        .ok()
        .json();
    assert!(v.get("mean_delta_e").is_none());
    assert!(v["mean_delta_e_rgb"]["otsu2018"][2].as_f64().unwrap() > 0.0);
}

#[test]
fn malformed_scenes_get_clear_errors() {
    let s = Scratch::new("simulate-bad");
    let cases: [(&str, &[&str]); 7] = [
        (
            "bounces = 2\nform_factors = [[0.7, 0.5], [0.0, 0.1]]\n",
            &["row 1 (5R 4/14) sums to 1.2", "at most 1"],
        ),
        (
            "bounces = 100000000000\nform_factors = \"furnace\"\n",
            &["GiB", "ask for at most"],
        ),
        (
            "bounces = 2\nform_factors = \"sphere\"\n",
            &["unknown form-factor preset `sphere`"],
        ),
        (
            "bounces = 2\nform_factors = \"box\"\n",
            &["box preset needs five patches", "floor"],
        ),
        ("form_factors = \"furnace\"\n", &["bounces = K"]),
        (
            "bounces = 2\nform_factors = \"furnace\"\nmethods = [\"magic\"]\n",
            &["method `magic`"],
        ),
        (
            "effect = \"converged\"\nform_factors = \"furnace\"\n",
            &["does not converge", "bounces = K"],
        ),
    ];
    for (body, needles) in cases {
        run(&write_scene(&s, body)).fails(1, needles);
    }
    let munsell = munsell();
    let m = munsell.to_str().unwrap();
    let p = s.write(
        "unknown.toml",
        &format!("bounces = 1\nform_factors = \"furnace\"\n[[lights]]\nspectrum = \"E\"\npower = 1\n[[patches]]\nspectra = {m:?}\nsample = \"5R 99/99\"\n"),
    );
    run(&p).fails(1, &["unknown sample `5R 99/99`", "CSV header"]);
    let p = s.write(
        "negative.toml",
        &format!("bounces = 1\nform_factors = \"furnace\"\n[[lights]]\nspectrum = \"E\"\npower = -3\n[[patches]]\nspectra = {m:?}\nsample = \"5R 4/14\"\n"),
    );
    run(&p).fails(1, &["power -3", "≥ 0"]);
    let p = s.write("typo.toml", "bounce = 1\n");
    run(&p).fails(1, &["not a valid scene", "bounce"]);
}

fn testdata(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/images")
        .join(name)
}

/// CIELAB of `patch`'s otsu2018 rendering after one bounce.
fn bounced_lab(v: &serde_json::Value, patch: &str) -> [f64; 3] {
    let p = v["per_patch"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == patch)
        .unwrap_or_else(|| panic!("no patch {patch} in {v}"));
    let lab = &p["colours"]["otsu2018"][1]["lab"];
    [0, 1, 2].map(|k| lab[k].as_f64().unwrap())
}

#[test]
fn a_texture_pixel_is_the_colour_convert_would_read() {
    let s = Scratch::new("simulate-texture");
    // The top right of the ramp is red; its 8-bit code values, decoded here, are the same
    // colour given as sRGB in the scene.
    let png = testdata("srgb8.png");
    let img = image::open(&png).unwrap().to_rgb8();
    let (x, y) = (img.width() - 1, 3);
    let code = img.get_pixel(x, y).0.map(|c| f64::from(c) / 255.0);
    let scene = |pixel: &str, extra: &str| {
        format!(
            "bounces = 1\nform_factors = \"furnace\"\n{extra}\n[[lights]]\nspectrum = \"D65\"\npower = 1\n\
             [[patches]]\nname = \"tex\"\ntexture = {:?}\npixel = {pixel}\n\
             [[patches]]\nname = \"col\"\ncolour = {code:?}\ncolorspace = \"sRGB - Texture\"\n",
            png.to_str().unwrap()
        )
    };
    let p = s.write("tex.toml", &scene(&format!("[{x}, {y}]"), ""));
    let v = Cmd::new(["simulate", "--scene", p.to_str().unwrap(), "--json"])
        .ok()
        .json();
    let (tex, col) = (bounced_lab(&v, "tex"), bounced_lab(&v, "col"));
    // Both reach XYZ through the same OCIO conversion (the colour as sRGB - Texture).
    let d = specconv_colour::lab::ciede2000(tex, col);
    assert!(d < 0.05, "{d}: {tex:?} {col:?}");
    // Half light, half reflection after one bounce in a furnace: a pale red.
    assert!(tex[1] > 15.0 && tex[1] > 2.0 * tex[2].abs(), "red: {tex:?}");
    // `colorspace` is convert's --colorspace: read as linear, the code values are not decoded
    // (sRGB decoding lowers every value below 1), so the same pixel is lighter.
    let p = s.write(
        "linear.toml",
        &scene(&format!("[{x}, {y}]"), "")
            .replace("pixel =", "colorspace = \"Linear Rec.709 (sRGB)\"\npixel ="),
    );
    let v = Cmd::new(["simulate", "--scene", p.to_str().unwrap(), "--json"])
        .ok()
        .json();
    let linear = bounced_lab(&v, "tex");
    assert!(
        linear[0] > tex[0] && specconv_colour::lab::ciede2000(linear, tex) > 0.5,
        "{linear:?} {tex:?}"
    );

    // Errors: a pixel outside, a missing file, a pixel that is not a colour, no pixel.
    let p = s.write("far.toml", &scene("[61, 0]", ""));
    run(&p).fails(1, &["pixel = [61, 0] is outside", "61×47", "0 to 60"]);
    let p = s.write(
        "missing.toml",
        &scene("[0, 0]", "").replace(png.to_str().unwrap(), "no_such.png"),
    );
    run(&p).fails(1, &["patch tex", "cannot read the texture", "no_such.png"]);
    let nan = s.path("nan.exr");
    exr::prelude::write_rgb_file(&nan, 2, 2, |x, _| {
        (if x == 1 { f32::NAN } else { 0.5 }, 0.5, 0.5)
    })
    .unwrap();
    let p = s.write(
        "nan.toml",
        &scene("[1, 0]", "").replace(png.to_str().unwrap(), "nan.exr"),
    );
    run(&p).fails(1, &["pixel [1, 0] of", "NaN", "choose another pixel"]);
    let p = s.write(
        "nopixel.toml",
        &scene("[0, 0]", "").replace("pixel = [0, 0]\n", ""),
    );
    run(&p).fails(1, &["pixel = [x, y]"]);
}

/// `simulate` builds its methods as `convert` does: `--blend` at convert's default width is
/// the default, and the method options change what it reports.
#[test]
fn simulate_takes_converts_method_options_with_its_defaults() {
    let s = Scratch::new("simulate-options");
    // A model whose spectra of these two chips lie near a cluster boundary and outside [0, 1],
    // so that --blend and --unbounded change them (the default `open` uplifts both inside).
    let p = write_scene(
        &s,
        "bounces = 3\nform_factors = \"furnace\"\nmodel = \"extended\"\n",
    );
    let p = p.to_str().unwrap();
    let run = |extra: &[&str]| {
        let args = [&["simulate", "--scene", p, "--json"], extra].concat();
        Cmd::new(args).ok().json()
    };
    let default = run(&[]);
    let width = specconv_spectral::otsu2018::blend::DEFAULT_WIDTH.to_string();
    assert_eq!(run(&["--blend", &width]), default);
    assert_eq!(run(&["--blend", &width, "--bounded"]), default);
    assert_ne!(run(&["--blend", "0"]), default);
    assert_ne!(run(&["--unbounded"]), default);
    // --method replaces the scene's list; --bands the grid of every spectrum.
    let one = run(&["--method", "smits1999", "--bands", "400:700:5"]);
    assert_eq!(
        one["methods"],
        serde_json::json!(["measured", "smits1999", "rgb"])
    );
    Cmd::new(["simulate", "--scene", p, "--blend=-1"]).fails(1, &["blend width"]);
}

/// A colour's `colorspace` is a colour space of the scene's OCIO config, as --colorspace, and
/// defaults to its sRGB texture space; a name it lacks is refused with its suggestions.
#[test]
fn a_colour_is_read_in_a_colour_space_of_the_ocio_config() {
    let s = Scratch::new("simulate-colorspace");
    let scene = |space: &str| {
        format!(
            "bounces = 1\nform_factors = \"furnace\"\n[[lights]]\nspectrum = \"D65\"\npower = 1\n\
             [[patches]]\nname = \"red\"\ncolour = [0.8, 0.1, 0.1]\n{space}"
        )
    };
    let lab = |space: &str| {
        let p = s.write("colour.toml", &scene(space));
        bounced_lab(
            &Cmd::new(["simulate", "--scene", p.to_str().unwrap(), "--json"])
                .ok()
                .json(),
            "red",
        )
    };
    let texture = lab("colorspace = \"sRGB - Texture\"\n");
    assert_eq!(lab(""), texture);
    assert_eq!(lab("colorspace = \"srgb_tx\"\n"), texture);
    let linear = lab("colorspace = \"Linear Rec.709 (sRGB)\"\n");
    assert!(specconv_colour::lab::ciede2000(linear, texture) > 1.0);
    let p = s.write("unknown.toml", &scene("colorspace = \"sRGB\"\n"));
    run(&p).fails(
        1,
        &[
            "patch red",
            "unknown colour space 'sRGB'",
            "'sRGB - Texture'",
        ],
    );
}
