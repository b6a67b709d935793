//! A studio's config and files decide (issue 32): the precedence of colour evidence
//! (docs/colour.md) on a typical asset's files, written by oiiotool, under a studio config of
//! our own (testdata/ocio/studio_rules.ocio: the official CG config plus file rules for data
//! maps and `*_acescg*`), against what tools outside specconv make of the same files:
//! PyOpenColorIO's `getColorSpaceFromFilepath` on the same config and path, and OpenImageIO's
//! `oiio:ColorSpace` (what oiiotool and maketx take a file to be). tests/studio_rules.py
//! writes the files and asks both.

use crate::runner::*;
use std::path::{Path, PathBuf};

/// The studio config of these tests.
fn studio_config() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/ocio/studio_rules.ocio")
}

/// Writes the asset into `dir`; returns, per file, what OCIO and OpenImageIO make of it.
fn asset(dir: &Scratch) -> Vec<serde_json::Value> {
    let config = studio_config();
    let v = script_json("studio_rules.py", [dir.0.as_os_str(), config.as_os_str()]);
    v.as_array().unwrap().clone()
}

fn info(config: &Path, file: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "--ocio",
        config.to_str().unwrap(),
        "info",
        "--json",
        file.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    Cmd::new(args).ok().json()
}

/// What specconv must choose for a file of the asset under the studio config: colour space,
/// rule, row (0: the data-map rule), role, and a piece of the evidence it overrules.
struct Expected {
    file: &'static str,
    colorspace: &'static str,
    rule: &'static str,
    row: u64,
    role: &'static str,
    overrides: Option<&'static str>,
}

const fn e(
    file: &'static str,
    colorspace: &'static str,
    rule: &'static str,
    row: u64,
    role: &'static str,
    overrides: Option<&'static str>,
) -> Expected {
    Expected {
        file,
        colorspace,
        rule,
        row,
        role,
        overrides,
    }
}

const WEAK_PNG: &str = "the file's PNG sRGB chunk with its gAMA and cHRM (sRGB - Texture)";

const EXPECTED: [Expected; 12] = [
    e(
        "rock_normal.png",
        "Raw",
        "file-rule",
        2,
        "data",
        Some(WEAK_PNG),
    ),
    e(
        "rock_mask.png",
        "Raw",
        "file-rule",
        2,
        "data",
        Some(WEAK_PNG),
    ),
    e("rock_ao.png", "Raw", "file-rule", 2, "data", Some(WEAK_PNG)),
    e(
        "fog_acescg.exr",
        "ACEScg",
        "file-rule",
        2,
        "achromatic",
        None,
    ),
    e("wall_acescg.exr", "ACEScg", "file-rule", 2, "colour", None),
    e(
        "tiles_acescg.exr",
        "ACEScg",
        "file-rule",
        2,
        "colour",
        Some("the file's EXR chromaticities (Linear Rec.2020)"),
    ),
    e("plate_ap1.exr", "ACEScg", "declared", 3, "colour", None),
    e(
        "rock_spec_ap1.exr",
        "ACEScg",
        "declared",
        3,
        "achromatic",
        None,
    ),
    e(
        "rock_albedo.png",
        "sRGB - Texture",
        "declared",
        4,
        "colour",
        None,
    ),
    e(
        "plate.exr",
        "ACES2065-1",
        "config-default",
        5,
        "colour",
        None,
    ),
    e(
        "rock_roughness.png",
        "Raw",
        "one-channel",
        0,
        "data",
        Some(WEAK_PNG),
    ),
    e(
        "rock_rough.exr",
        "Raw",
        "one-channel",
        0,
        "data",
        Some("the OCIO config's 'Default' file rule (ACES2065-1)"),
    ),
];

#[test]
fn a_studio_configs_rules_decide_data_maps_and_agree_with_opencolorio_where_a_rule_matches() {
    let dir = Scratch::new("studio-rules");
    let config = studio_config();
    let outside = asset(&dir);
    for want in &EXPECTED {
        let theirs = outside
            .iter()
            .find(|f| f["name"] == want.file)
            .unwrap_or_else(|| panic!("{}: not written", want.file));
        let file = Path::new(theirs["file"].as_str().unwrap());
        let v = info(&config, file, &[]);
        let name = want.file;
        assert_eq!(v["colorspace"], want.colorspace, "{name}: {v}");
        assert_eq!(v["colorspace_rule"], want.rule, "{name}: {v}");
        assert_eq!(
            v["colorspace_row"].as_u64().unwrap_or(0),
            want.row,
            "{name}"
        );
        assert_eq!(v["role"], want.role, "{name}: {v}");
        assert_eq!(
            v["colorspace_overrides"].as_str(),
            want.overrides,
            "{name}: {v}"
        );
        // Consistent PNG chunks (what oiiotool writes) are one declaration: no warning.
        assert_eq!(v["colorspace_warnings"], serde_json::json!([]), "{name}");
        // OpenColorIO: where an explicit rule matches the path, it decides, as in OCIO.
        // Elsewhere OCIO can only answer its Default rule (ACES2065-1); specconv ranks the
        // file's declarations above it, and one channel is data (docs/colour.md).
        let ocio = theirs["ocio"].as_str().unwrap();
        let only_default = theirs["ocio_only_default"].as_bool().unwrap();
        if want.row == 2 {
            assert!(!only_default, "{name}");
            assert_eq!(ocio, want.colorspace, "{name}: OCIO's file rules disagree");
        } else {
            assert!(only_default, "{name}: an explicit rule matched in OCIO");
            assert_eq!(ocio, "ACES2065-1", "{name}");
        }
        // OpenImageIO calls every PNG it wrote sRGB, data maps too (what oiiotool and maketx
        // go by): specconv takes that as weak evidence, below the config's rules.
        if name.ends_with(".png") {
            assert_eq!(theirs["oiio_colorspace"], "sRGB", "{name}");
            assert_eq!(theirs["png"]["gAMA"], 45455, "{name}");
        }
        eprintln!(
            "{name}: specconv {} (row {}, {}); OCIO {ocio}; OpenImageIO {}",
            want.colorspace, want.row, want.rule, theirs["oiio_colorspace"]
        );
    }

    // Row 1 overrules everything, and says what.
    let normal = dir.path("rock_normal.png");
    let v = info(&config, &normal, &["--colorspace", "sRGB - Texture"]);
    assert_eq!(v["colorspace_row"], 1, "{v}");
    assert_eq!(v["role"], "colour");
    assert_eq!(
        v["colorspace_overrides"],
        "the OCIO config's file rule 'normals' (Raw)"
    );
    // Row 6: the built-in config has no rule of a studio's, so its Default rule is not used.
    let v = info(Path::new("aces"), &dir.path("plate.exr"), &[]);
    assert_eq!(v["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(v["colorspace_row"], 6);
    // The text form says which row decided.
    let text = Cmd::new([
        "--ocio",
        config.to_str().unwrap(),
        "info",
        normal.to_str().unwrap(),
    ])
    .ok()
    .stdout;
    assert!(
        text.contains("precedence:   row 2 of 6: a studio config's explicit file rule"),
        "{text}"
    );
}

#[test]
fn a_batch_under_a_studio_config_uplifts_colour_only_and_records_the_row() {
    let dir = Scratch::new("studio-batch");
    let config = studio_config();
    asset(&dir);
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let names = [
        "rock_normal.png",
        "rock_mask.png",
        "rock_rough.exr",
        "rock_albedo.png",
    ];
    let mut args: Vec<String> = vec!["--ocio".into(), config.to_str().unwrap().into()];
    args.extend(names.iter().map(|n| dir.path(n).to_str().unwrap().into()));
    args.extend(["-o", out.to_str().unwrap(), "--data", "copy", "--json"].map(String::from));
    let run = Cmd::new(&args).ok();
    let records = run.json_lines();
    let by_name = |n: &str| {
        records
            .iter()
            .find(|r| r["input"].as_str().unwrap().ends_with(n))
            .unwrap_or_else(|| panic!("{n}: {records:?}"))
    };
    for data in &names[..3] {
        let r = by_name(data);
        assert_eq!(r["status"], "copied", "{data}: {r}");
        assert_eq!(r["colorspace"], "Raw", "{data}: {r}");
        // Written through, never uplifted: no spectral channel.
        let output = Path::new(r["output"].as_str().unwrap());
        let header = tool("oiiotool", &["--info", "-v", output.to_str().unwrap()]);
        assert!(!header.contains("T.550"), "{data}: {header}");
    }
    assert_eq!(by_name("rock_normal.png")["colorspace_row"], 2);
    assert_eq!(by_name("rock_rough.exr")["colorspace_rule"], "one-channel");
    let albedo = by_name("rock_albedo.png");
    assert_eq!(albedo["status"], "ok", "{albedo}");
    assert_eq!(albedo["colorspace"], "sRGB - Texture");
    assert_eq!(albedo["colorspace_row"], 4);
    assert!(!run.stderr.contains("warning"), "{}", run.stderr);
}

#[test]
fn consistent_png_chunks_give_no_warning_and_disagreeing_ones_do() {
    let dir = Scratch::new("studio-png");
    asset(&dir);
    // Forty PNGs as oiiotool writes them (sRGB, gAMA 45455, Rec.709 cHRM): no warning.
    let pngs = dir.path("pngs");
    std::fs::create_dir(&pngs).unwrap();
    let albedo = dir.path("rock_albedo.png");
    for i in 0..40 {
        std::fs::copy(&albedo, pngs.join(format!("albedo{i:02}.png"))).unwrap();
    }
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let mut args: Vec<String> = (0..40)
        .map(|i| pngs.join(format!("albedo{i:02}.png")).display().to_string())
        .collect();
    args.extend(["-o", out.to_str().unwrap(), "--json"].map(String::from));
    let run = Cmd::new(&args).ok();
    assert!(!run.stderr.contains("warning"), "{}", run.stderr);
    let records = run.json_lines();
    assert_eq!(records.len(), 40);
    assert!(records.iter().all(|r| r["status"] == "ok"
        && r["colorspace"] == "sRGB - Texture"
        && r["colorspace_row"] == 4));
    // A gAMA of 1/1.8 beside the sRGB chunk is a second, different declaration: sRGB is
    // used (the PNG specification ranks it above gAMA) and the disagreement is said.
    let v = Cmd::new([
        "info",
        "--json",
        dir.path("gamma18_albedo.png").to_str().unwrap(),
    ])
    .ok()
    .json();
    assert_eq!(v["colorspace"], "sRGB - Texture");
    let warnings = v["colorspace_warnings"].to_string();
    assert!(
        warnings.contains("PNG sRGB chunk says 'sRGB - Texture'")
            && warnings.contains("gAMA 0.55556"),
        "{warnings}"
    );
}

/// Files a config's Default rule could decide, written by oiiotool: half and float EXRs that
/// declare nothing (RGB and one channel), one with AP1 chromaticities, PNGs with and without
/// an sRGB chunk, grey and colour, 8 and 16 bits.
fn undeclared_files(dir: &Scratch) -> Vec<PathBuf> {
    let make = |name: &str, channels: &str, format: &str, extra: &[&str]| {
        let p = dir.path(name);
        let mut args = vec!["--pattern", "constant:color=0.3,0.2,0.1", "8x8", channels];
        args.extend(extra);
        args.extend(["-d", format, "-o", p.to_str().unwrap()]);
        tool("oiiotool", &args);
        p
    };
    let ap1 = "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767";
    vec![
        make("plate.exr", "3", "half", &[]),
        make("plate_float.exr", "3", "float", &[]),
        make("rough.exr", "1", "half", &[]),
        make(
            "plate_ap1.exr",
            "3",
            "half",
            &["--attrib:type=float[8]", "chromaticities", ap1],
        ),
        make("albedo.png", "3", "uint8", &[]),
        make("albedo16.png", "3", "uint16", &[]),
        make("rough.png", "1", "uint8", &[]),
        make("albedo.tif", "3", "uint8", &[]),
    ]
}

/// What `info` decides of `file` with `--ocio CONFIG`, or with `$OCIO` = CONFIG.
fn decision(config: &str, file: &Path, by_env: bool) -> String {
    let cmd = if by_env {
        Cmd::new(["info", "--json", file.to_str().unwrap()]).env("OCIO", config)
    } else {
        Cmd::new(["--ocio", config, "info", "--json", file.to_str().unwrap()])
    };
    let v = cmd.ok().json();
    format!(
        "{} / {} / row {} / {} / warnings {}",
        v["colorspace"],
        v["colorspace_rule"],
        v["colorspace_row"],
        v["role"],
        v["colorspace_warnings"]
    )
}

#[test]
fn the_official_configs_given_as_files_decide_as_the_built_in_ones() {
    // Issue 45: `--ocio aces` and the same official config as a file chose ACES2065-1 and
    // linear Rec.709 for one EXR (ΔE00 11.6), the file's Default rule taken as a studio's.
    let dir = Scratch::new("official-twins");
    let files = undeclared_files(&dir);
    for kind in [
        specconv_ocio::BuiltinConfig::Cg,
        specconv_ocio::BuiltinConfig::Studio,
    ] {
        let official = shared(&format!("ocio/{}.ocio", kind.official_name()));
        let official = official.to_str().unwrap();
        let builtin = format!("ocio://{}", kind.official_name());
        // The same text elsewhere, under another name, is still the Academy's config.
        let copy = dir.write(
            &format!("{kind:?}-copy.ocio"),
            &std::fs::read_to_string(official).unwrap(),
        );
        for file in &files {
            let want = decision(&builtin, file, false);
            for (config, by_env) in [
                (official, false),
                (official, true),
                (copy.to_str().unwrap(), false),
            ] {
                assert_eq!(
                    decision(config, file, by_env),
                    want,
                    "{}: {config} (by $OCIO: {by_env}) against {builtin}",
                    file.display()
                );
            }
        }
    }
}

#[test]
fn an_edited_official_config_is_the_studios_own_policy() {
    let dir = Scratch::new("official-edited");
    let files = undeclared_files(&dir);
    let plate = &files[0];
    let text =
        std::fs::read_to_string(shared("ocio/cg-config-v1.0.0_aces-v1.3_ocio-v2.1.ocio")).unwrap();
    let default = "  - !<Rule> {name: Default, colorspace: ACES2065-1}";
    assert!(text.contains(default));
    // Its Default rule changed, or a rule added before it: the config is a studio's, whose
    // Default rule decides float files that declare nothing (row 5).
    let edits = [
        (
            "default-acescg",
            text.replace(default, "  - !<Rule> {name: Default, colorspace: ACEScg}"),
            "\"ACEScg\"",
        ),
        (
            "added-rule",
            text.replace(
                default,
                &format!("  - !<Rule> {{name: normals, colorspace: Raw, pattern: \"*_normal*\", extension: \"*\"}}\n{default}"),
            ),
            "\"ACES2065-1\"",
        ),
    ];
    for (name, yaml, space) in edits {
        let config = dir.write(&format!("{name}.ocio"), &yaml);
        let got = decision(config.to_str().unwrap(), plate, false);
        assert!(
            got.starts_with(&format!("{space} / \"config-default\" / row 5")),
            "{name}: {got}"
        );
    }
}
