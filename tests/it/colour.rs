//! The input colour-space rule (docs/colour.md) and straight alpha, against references outside
//! specconv: colour-science's RGB_to_XYZ with Bradford adaptation for OpenEXR chromaticities,
//! Little CMS for embedded ICC profiles (tests/colour_rule_images.py makes the images and
//! computes both), oiiotool for straight alpha.

use crate::runner::*;
use std::path::Path;

/// Runs tests/colour_rule_images.py: writes the images into `dir`, returns its reference XYZ.
fn make_images(dir: &Scratch) -> serde_json::Value {
    script_json("colour_rule_images.py", [&dir.0])
}

/// XYZ (CIE 1931, D65, white Y = 1) integrated from every pixel of a spectral EXR.
fn output_xyz(path: &Path) -> Vec<[f64; 3]> {
    let img = specconv_exr::read(path).unwrap();
    // As every reader integrates (the layout's reference: interpolated onto the 1 nm table).
    let a = specconv_colour::Integration::reflectance(
        &img.wavelengths,
        specconv_colour::Observer::Cie1931,
        specconv_colour::Illuminant::D65,
    )
    .unwrap();
    (0..img.width * img.height)
        .map(|p| {
            let r: Vec<f64> = img.bands.iter().map(|plane| plane[p] as f64).collect();
            a.xyz(&r)
        })
        .collect()
}

/// Largest difference relative to the reference's largest component, per pixel.
fn worst_relative(got: &[[f64; 3]], want: &serde_json::Value) -> f64 {
    let want = want.as_array().unwrap();
    assert_eq!(got.len(), want.len());
    let mut worst = 0.0f64;
    for (g, w) in got.iter().zip(want) {
        let w: Vec<f64> = w
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let scale = w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..3 {
            worst = worst.max((g[k] - w[k]).abs() / scale);
        }
    }
    worst
}

fn info(path: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", "--json", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    Cmd::new(args).ok().json()
}

#[test]
fn exr_chromaticities_and_icc_profiles_convert_to_the_reference_xyz() {
    let dir = Scratch::new("colour-rule");
    let reference = make_images(&dir);

    // What `info` names each EXR's colour space, and by which rule.
    let expected = [
        ("rec709", "Linear Rec.709 (sRGB)", "declared"),
        ("ap0", "ACES2065-1", "declared"),
        ("ap1", "ACEScg", "declared"),
        ("rec2020", "Linear Rec.2020", "declared"),
        ("p3d65", "Linear P3-D65", "declared"),
        ("xyz_e", "chromaticities: linear", "declared"),
        ("arbitrary", "chromaticities: linear", "declared"),
        ("none", "Linear Rec.709 (sRGB)", "default"),
    ];
    for case in reference["exr"].as_array().unwrap() {
        let file = Path::new(case["file"].as_str().unwrap());
        let name = case["case"].as_str().unwrap();
        let (_, space, rule) = expected.iter().find(|e| e.0 == name).unwrap();
        let v = info(file, &[]);
        let cs = &v;
        assert!(
            cs["colorspace"].as_str().unwrap().starts_with(space),
            "{name}: {cs}"
        );
        assert_eq!(cs["colorspace_rule"], *rule, "{name}: {cs}");
        assert_eq!(
            cs["colorspace_warnings"],
            serde_json::json!([]),
            "{name}: {cs}"
        );
        if name == "ap0" {
            assert_eq!(
                cs["colorspace_reason"],
                "declared by the file: EXR chromaticities, EXR acesImageContainerFlag"
            );
        }
        let out = dir.path(&format!("{name}_spectral.exr"));
        let line = Cmd::convert(file, &out)
            .args(["-d", "float", "--json"])
            .run();
        let record = json(line.ok());
        assert_eq!(record["colorspace"], cs["colorspace"], "{name}");
        assert_eq!(record["colorspace_rule"], cs["colorspace_rule"], "{name}");
        let worst = worst_relative(&output_xyz(&out), &case["xyz"]);
        eprintln!("{name}: XYZ within {worst:.1e} of colour-science");
        assert!(
            worst < 1e-4,
            "{name}: XYZ differs from colour-science's by {worst}"
        );
    }

    for case in reference["icc"].as_array().unwrap() {
        let file = Path::new(case["file"].as_str().unwrap());
        let v = info(file, &[]);
        let cs = &v;
        assert!(
            cs["colorspace"].as_str().unwrap().starts_with("ICC '"),
            "{cs}"
        );
        assert_eq!(cs["colorspace_reason"], "declared by the file: ICC profile");
        assert!(
            v["to_xyz"].as_str().unwrap().starts_with("Little CMS"),
            "{v}"
        );
        let out = dir.path(&format!(
            "{}_spectral.exr",
            file.file_name().unwrap().to_string_lossy()
        ));
        Cmd::convert(file, &out).args(["-d", "float"]).ok();
        let worst = worst_relative(&output_xyz(&out), &case["xyz"]);
        eprintln!("{}: XYZ within {worst:.1e} of Little CMS", file.display());
        assert!(
            worst < 1e-3,
            "{}: XYZ differs from Little CMS's by {worst}",
            file.display()
        );
    }
}

/// A 4×4 half OpenEXR of one colour, written by oiiotool with EXR `chromaticities` (eight
/// numbers) and the attributes `extra`.
fn constant_exr(path: &Path, chromaticities: &str, extra: &[&str]) {
    let mut args = vec![
        "--pattern",
        "constant:color=0.3,0.2,0.1",
        "4x4",
        "3",
        "-d",
        "half",
    ];
    args.extend(["--attrib:type=float[8]", "chromaticities", chromaticities]);
    args.extend(extra);
    args.extend(["-o", path.to_str().unwrap()]);
    tool("oiiotool", &args);
}

#[test]
fn colorspace_overrides_a_declaration_and_says_so_and_disagreements_warn() {
    let dir = Scratch::new("colour-override");
    let exr = dir.path("ap1.exr");
    constant_exr(
        &exr,
        "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767",
        &[],
    );
    let v = info(&exr, &["--colorspace", "lin_rec709"]);
    assert_eq!(v["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(
        v["colorspace_reason"],
        "--colorspace, overriding the file's EXR chromaticities (ACEScg)"
    );
    // The flag naming what the file declares overrides nothing.
    let v = info(&exr, &["--colorspace", "ACEScg"]);
    assert_eq!(v["colorspace_reason"], "--colorspace");

    // Rec.709 chromaticities with the ACES container flag: the chromaticities win, with a
    // warning naming both.
    let both = dir.path("both.exr");
    let aces_flag = ["--attrib:type=int", "acesImageContainerFlag", "1"];
    constant_exr(
        &both,
        "0.64,0.33,0.30,0.60,0.15,0.06,0.3127,0.3290",
        &aces_flag,
    );
    let v = info(&both, &[]);
    assert_eq!(v["colorspace"], "Linear Rec.709 (sRGB)");
    let warnings = v["colorspace_warnings"].to_string();
    assert!(
        warnings.contains("EXR chromaticities says 'Linear Rec.709 (sRGB)'")
            && warnings.contains("EXR acesImageContainerFlag says 'ACES2065-1'")
            && warnings.contains("using 'Linear Rec.709 (sRGB)'"),
        "{warnings}"
    );
    let out = Cmd::convert(&both, dir.path("o.exr")).run();
    out.ok();
    assert!(
        out.stderr.contains("specconv: warning:") && out.stderr.contains("acesImageContainerFlag"),
        "{}",
        out.stderr
    );
}

#[test]
fn a_config_file_rule_chooses_by_path_when_the_file_declares_nothing() {
    let dir = Scratch::new("colour-file-rule");
    let yaml = specconv_ocio::CG_CONFIG_YAML.replace(
        "  - !<Rule> {name: Default, colorspace: ACES2065-1}",
        "  - !<Rule> {name: acescg, colorspace: ACEScg, pattern: \"*_acescg\", extension: \"exr\"}\n  - !<Rule> {name: Default, colorspace: ACES2065-1}",
    );
    assert_ne!(yaml, specconv_ocio::CG_CONFIG_YAML);
    let config = dir.write("rules.ocio", &yaml);
    let make = |name: &str, chroma: bool| {
        let p = dir.path(name);
        let mut args = vec!["--pattern", "constant:color=0.3,0.2,0.1", "4x4", "3"];
        if chroma {
            args.extend([
                "--attrib:type=float[8]",
                "chromaticities",
                "0.708,0.292,0.170,0.797,0.131,0.046,0.3127,0.3290",
            ]);
        }
        args.extend(["-d", "half", "-o", p.to_str().unwrap()]);
        tool("oiiotool", &args);
        p
    };
    let ocio = ["--ocio", config.to_str().unwrap()];
    let v = info(&make("wall_acescg.exr", false), &ocio);
    assert_eq!(v["colorspace"], "ACEScg");
    assert_eq!(v["colorspace_rule"], "file-rule");
    assert_eq!(
        v["colorspace_reason"],
        "the OCIO config's file rule 'acescg'"
    );
    // Another name: only the Default rule matches; a config given as a file is the studio's
    // policy, so its Default rule (ACES2065-1) comes before the format's default (row 5).
    let v = info(&make("wall.exr", false), &ocio);
    assert_eq!(v["colorspace"], "ACES2065-1");
    assert_eq!(v["colorspace_rule"], "config-default");
    // The config's explicit rule (row 2) comes before a declaration (row 3), and says which
    // declaration it overrules.
    let v = info(&make("tiles_acescg.exr", true), &ocio);
    assert_eq!(v["colorspace"], "ACEScg");
    assert_eq!(v["colorspace_rule"], "file-rule");
    assert_eq!(
        v["colorspace_reason"],
        "the OCIO config's file rule 'acescg', over the file's EXR chromaticities (Linear Rec.2020)"
    );
    // Where no rule matches the path, the declaration decides (row 3).
    let v = info(&make("tiles.exr", true), &ocio);
    assert_eq!(v["colorspace"], "Linear Rec.2020");
    assert_eq!(v["colorspace_rule"], "declared");
    assert_eq!(v["colorspace_row"], 3);
}

/// Linear Rec.709 RGBA of pixel (0, 0) of `to-rgb`'s output.
fn back_to_linear(dir: &Scratch, spectral: &Path, name: &str) -> Vec<f32> {
    let back = dir.path(name);
    Cmd::to_rgb(spectral, &back)
        .args(["--colorspace", "lin_rec709"])
        .ok();
    let mut r = specconv_oiio::ImageReader::open(&back).unwrap();
    r.read_level(0).unwrap().pixel(0, 0).to_vec()
}

#[test]
fn straight_alpha_is_converted_then_premultiplied_as_oiiotool_does() {
    let dir = Scratch::new("colour-alpha");
    for (name, colour, alpha, want) in [
        ("white", "1,1,1", "0.43529411", [0.4353f32; 3]),
        ("green", "0,1,0", "0.50196078", [0.0, 0.502, 0.0]),
    ] {
        let png = dir.path(&format!("{name}.png"));
        tool(
            "oiiotool",
            &[
                "--pattern",
                &format!("constant:color={colour},{alpha}"),
                "4x4",
                "4",
                "-d",
                "uint8",
                "-o",
                png.to_str().unwrap(),
            ],
        );
        // oiiotool's reference: straight values as stored, converted, then premultiplied.
        let reference = dir.path(&format!("{name}_oiiotool.exr"));
        tool(
            "oiiotool",
            &[
                "--no-autopremult",
                png.to_str().unwrap(),
                "--colorconvert",
                "sRGB",
                "linear",
                "--premult",
                "-d",
                "float",
                "-o",
                reference.to_str().unwrap(),
            ],
        );
        let oiiotool_px = specconv_oiio::ImageReader::open(&reference)
            .unwrap()
            .read_level(0)
            .unwrap()
            .pixel(0, 0)
            .to_vec();
        let out = dir.path(&format!("{name}_spectral.exr"));
        let line = Cmd::convert(&png, &out).args(["-d", "float"]).run();
        line.ok();
        assert!(
            line.stderr.contains("straight alpha premultiplied"),
            "{}",
            line.stderr
        );
        let ours = back_to_linear(&dir, &out, &format!("{name}_back.exr"));
        eprintln!("{name}: specconv {ours:?}, oiiotool {oiiotool_px:?}");
        for c in 0..3 {
            assert!(
                (ours[c] - want[c]).abs() <= 1e-3 && (ours[c] - oiiotool_px[c]).abs() <= 1e-3,
                "{name} channel {c}: specconv {ours:?}, oiiotool {oiiotool_px:?}, expected {want:?}"
            );
        }
        // Told the colour is premultiplied already, the stored values are taken as they are.
        let out = dir.path(&format!("{name}_as_premultiplied.exr"));
        Cmd::convert(&png, &out)
            .args(["-d", "float", "--alpha", "premultiplied"])
            .ok();
        let as_is = back_to_linear(&dir, &out, &format!("{name}_back2.exr"));
        let full = if name == "white" {
            [1.0; 3]
        } else {
            [0.0, 1.0, 0.0]
        };
        for c in 0..3 {
            assert!((as_is[c] - full[c]).abs() <= 1e-3, "{name}: {as_is:?}");
        }
    }

    // A premultiplied OpenEXR comes back unchanged (not premultiplied twice).
    let exr = crate::convert::testdata("float_tiled_alpha.exr");
    let out = dir.path("exr_spectral.exr");
    Cmd::convert(&exr, &out)
        .args(["-d", "float", "--unbounded"])
        .ok();
    let back = dir.path("exr_back.exr");
    Cmd::to_rgb(&out, &back)
        .args(["--colorspace", "lin_rec709"])
        .ok();
    let input = specconv_oiio::ImageReader::open(&exr)
        .unwrap()
        .read_level(0)
        .unwrap();
    let got = specconv_oiio::ImageReader::open(&back)
        .unwrap()
        .read_level(0)
        .unwrap();
    let mut worst = 0.0f32;
    for y in 0..input.height {
        for x in 0..input.width {
            for c in 0..3 {
                let (u, v) = (input.pixel(x, y)[c], got.pixel(x, y)[c]);
                worst = worst.max((u - v).abs() / u.abs().max(1e-2));
            }
        }
    }
    assert!(worst < 1e-4, "premultiplied EXR changed by {worst}");
}

/// A 4×4 half OpenEXR of one colour that OpenImageIO 3 would tag: `colorInteropID` = `id`
/// (as oiiotool `--attrib colorInteropID` writes it), with the attributes `extra`.
fn interop_exr(path: &Path, id: &str, extra: &[&str]) {
    let mut args = vec![
        "--pattern",
        "constant:color=0.3,0.2,0.1",
        "4x4",
        "3",
        "-d",
        "half",
        "--attrib",
        "colorInteropID",
        id,
    ];
    args.extend(extra);
    args.extend(["-o", path.to_str().unwrap()]);
    tool("oiiotool", &args);
}

/// The colour spaces the Academy's configs give the Color Interop Forum's IDs (in ACES CG
/// v1.0.0's names; the v2 configs carry the IDs as aliases of the same spaces).
const ACES_NAMES: [(&str, &str); 13] = [
    ("lin_ap1_scene", "ACEScg"),
    ("lin_ap0_scene", "ACES2065-1"),
    ("lin_rec709_scene", "Linear Rec.709 (sRGB)"),
    ("lin_p3d65_scene", "Linear P3-D65"),
    ("lin_rec2020_scene", "Linear Rec.2020"),
    ("srgb_rec709_scene", "sRGB - Texture"),
    ("g24_rec709_scene", "Gamma 2.4 Rec.709 - Texture"),
    ("g22_rec709_scene", "Gamma 2.2 Rec.709 - Texture"),
    ("g18_rec709_scene", "Gamma 1.8 Rec.709 - Texture"),
    ("srgb_ap1_scene", "sRGB Encoded AP1 - Texture"),
    ("g22_ap1_scene", "Gamma 2.2 AP1 - Texture"),
    ("srgb_rec709_display", "sRGB - Texture"),
    ("lin_rec2020_display", "Linear Rec.2020"),
];

/// The chromaticities the OpenEXR recommendation (Annex A) gives the linear IDs.
const ANNEX_A: [(&str, &str); 6] = [
    (
        "lin_rec709_scene",
        "0.64,0.33,0.30,0.60,0.15,0.06,0.3127,0.3290",
    ),
    (
        "lin_ap0_scene",
        "0.7347,0.2653,0.0,1.0,0.0001,-0.0770,0.32168,0.33767",
    ),
    (
        "lin_ap1_scene",
        "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767",
    ),
    (
        "lin_p3d65_scene",
        "0.680,0.320,0.265,0.690,0.150,0.060,0.3127,0.3290",
    ),
    (
        "lin_rec2020_scene",
        "0.708,0.292,0.170,0.797,0.131,0.046,0.3127,0.3290",
    ),
    (
        "lin_adobergb_scene",
        "0.64,0.33,0.21,0.71,0.15,0.06,0.3127,0.3290",
    ),
];

#[test]
fn every_color_interop_id_is_a_strong_declaration() {
    use specconv_conversion::interop::{Meaning, IDS};
    let dir = Scratch::new("colour-interop");
    for (id, meaning) in IDS {
        for spelled in [id.to_string(), id.to_ascii_uppercase()] {
            let exr = dir.path(&format!("{spelled}.exr"));
            interop_exr(&exr, &spelled, &[]);
            let v = info(&exr, &[]);
            let said = format!("{spelled}: {v}");
            let warnings = v["colorspace_warnings"].to_string();
            match meaning {
                Meaning::Rgb(..) | Meaning::XyzD65 => {
                    assert_eq!(v["colorspace_row"], 3, "{said}");
                    assert_eq!(v["colorspace_rule"], "declared", "{said}");
                    assert_eq!(v["role"], "colour", "{said}");
                    if let Some((_, name)) = ACES_NAMES.iter().find(|(i, _)| *i == id) {
                        assert_eq!(v["colorspace"], *name, "{said}");
                    }
                    // Linear IDs: what the same primaries as chromaticities decide.
                    if let Some((_, c)) = ANNEX_A.iter().find(|(i, _)| *i == id) {
                        let chroma = dir.path(&format!("{id}-chromaticities.exr"));
                        constant_exr(&chroma, c, &[]);
                        let by_chroma = info(&chroma, &[]);
                        let name = by_chroma["colorspace"].as_str().unwrap();
                        let name = name.replace("chromaticities", id);
                        assert_eq!(v["colorspace"], name.as_str(), "{said}");
                    }
                }
                Meaning::Data => {
                    assert_eq!(v["role"], "data", "{said}");
                    assert_eq!(v["colorspace"], "Raw", "{said}");
                    assert_eq!(v["colorspace_row"], 3, "{said}");
                }
                Meaning::Unknown => {
                    assert_eq!(v["colorspace_rule"], "default", "{said}");
                    assert_eq!(warnings, "[]", "{said}");
                }
                Meaning::Unsupported(_) => {
                    assert_eq!(v["colorspace_rule"], "default", "{said}");
                    assert!(warnings.contains("colorInteropID"), "{said}");
                }
            }
        }
    }
}

#[test]
fn a_data_interop_id_is_never_uplifted_and_a_name_nobody_knows_is_said() {
    let dir = Scratch::new("colour-interop-data");
    // `data` beside AP1 chromaticities: the ID supplants them (OpenEXR recommendation), with
    // a warning naming both.
    let both = dir.path("normal.exr");
    interop_exr(
        &both,
        "data",
        &[
            "--attrib:type=float[8]",
            "chromaticities",
            "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767",
        ],
    );
    let v = info(&both, &[]);
    assert_eq!(
        (&v["role"], &v["colorspace"]),
        (&"data".into(), &"Raw".into()),
        "{v}"
    );
    let out = Cmd::convert(&both, dir.path("o.exr")).run();
    out.ok();
    assert!(!dir.path("o.exr").exists(), "{}", out.stderr);
    assert!(out.stderr.contains("a data texture"), "{}", out.stderr);
    // The caller still decides (row 1).
    let v = info(&both, &["--colorspace", "ACEScg"]);
    assert_eq!(v["role"], "colour");

    // Names neither the config nor the Forum's list knows: a warning that names the
    // attribute, then the next evidence (here the format's default).
    for id in [
        "studio:custom_log_a",
        "lin_ap2_scene",
        "acescg_linear",
        "ocio:unknown",
    ] {
        let exr = dir.path("odd.exr");
        interop_exr(&exr, id, &[]);
        let v = info(&exr, &[]);
        let warnings = v["colorspace_warnings"].to_string();
        assert!(
            warnings.contains(&format!("colorInteropID '{id}'"))
                && warnings.contains("not a Color Interop Forum ID"),
            "{id}: {warnings}"
        );
        assert_eq!(v["colorspace_rule"], "default", "{id}");
        let out = Cmd::convert(&exr, dir.path("odd_spectral.exr"))
            .arg("--force")
            .run();
        out.ok();
        assert!(
            out.stderr.contains("warning") && out.stderr.contains(id),
            "{id}: {}",
            out.stderr
        );
    }
    // A name of the config (an alias) is the config's, whatever the list says.
    let exr = dir.path("alias.exr");
    interop_exr(&exr, "lin_ap1", &[]);
    assert_eq!(info(&exr, &[])["colorspace"], "ACEScg");
}
