//! `specconv info` and `specconv colorspaces` from the command line, and every input
//! failure of issue 3: one `specconv: error:` line, exit 1 (2 for settings), no panic.

use crate::runner::*;
use std::path::{Path, PathBuf};

pub(crate) fn testdata(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata")
        .join(rel)
}

pub(crate) fn arg(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn info_describes_a_mipmapped_texture() {
    let tx = testdata("images/srgba8.tx");
    let out = Cmd::new(["info", arg(&tx)]).run();
    let text = out.ok();
    for line in [
        "format:       tiff",
        "size:         61 x 47",
        "channels:     4 (R, G, B, A)",
        "alpha:        A",
        "pixel format: uint8",
        "storage:      tiles of 16 x 16",
        "MIP levels:   6 (61x47 30x23 15x11 7x5 3x2 1x1)",
        // OIIO labels every 8-bit TIFF sRGB; that is its guess, not the file's declaration.
        "OIIO label:   sRGB (oiio:ColorSpace)",
        "colour space: sRGB - Texture",
        "chosen by:    default: integer pixels are sRGB texture",
        "to XYZ:       OCIO, through cie_xyz_d65_interchange (CIE-XYZ-D65)",
    ] {
        assert!(text.contains(line), "missing {line:?} in\n{text}");
    }
}

#[test]
fn info_json_reports_what_the_reader_sees_and_the_colour_space_choice() {
    let v = Cmd::new([
        "info",
        "--json",
        arg(&testdata("images/half_tiled_alpha.exr")),
    ])
    .ok()
    .json();
    assert_eq!(v["format"], "openexr");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(61), Some(47))
    );
    assert_eq!(v["pixel_format"], "half");
    assert_eq!(v["tile_size"], serde_json::json!([16, 16]));
    assert_eq!(v["mip_levels"], serde_json::json!([[61, 47]]));
    assert_eq!(v["channels"].as_array().unwrap().len(), 4);
    assert_eq!(v["alpha_channel"], 3);
    // OIIO's EXR reader says "Linear" for every file; without chromaticities OpenEXR means
    // linear Rec.709 with a D65 white, the config's Linear Rec.709 (sRGB).
    assert_eq!(v["declared_color_space"], "Linear");
    assert_eq!(v["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(v["colorspace_rule"], "default");
    assert!(v["spectral"].is_null());

    // No declaration and integer pixels: sRGB - Texture by default.
    let v = Cmd::new(["info", "--json", arg(&testdata("images/rgb16.tif"))])
        .ok()
        .json();
    assert_eq!(v["declared_color_space"], serde_json::Value::Null);
    assert_eq!(v["colorspace"], "sRGB - Texture");
    assert_eq!(v["colorspace_rule"], "default");

    // --colorspace (or oiiotool's --iscolorspace) wins, by name or alias.
    for flag in ["--colorspace", "--iscolorspace"] {
        let v = Cmd::new([
            "info",
            "--json",
            flag,
            "lin_rec2020",
            arg(&testdata("images/srgb8.png")),
        ])
        .ok()
        .json();
        assert_eq!(v["colorspace"], "Linear Rec.2020");
        assert_eq!(v["colorspace_rule"], "colorspace-option");
        assert_eq!(v["colorspace_reason"], "--colorspace");
    }
}

#[test]
fn info_reads_every_testdata_image() {
    let mut n = 0;
    for entry in std::fs::read_dir(testdata("images")).unwrap() {
        let path = entry.unwrap().path();
        let v = Cmd::new(["info", "--json", arg(&path)]).ok().json();
        assert!(v["width"].as_u64().unwrap() > 0, "{}", path.display());
        n += 1;
    }
    assert!(n >= 10);
}

#[test]
fn colorspaces_lists_names_aliases_and_roles() {
    let text = Cmd::new(["colorspaces"]).ok().stdout;
    assert!(
        text.starts_with("config: 'aces' (built in: ACES CG config v1.0.0"),
        "{text}"
    );
    for needle in [
        "scene_linear             ACEScg",
        "cie_xyz_d65_interchange  CIE-XYZ-D65",
        "  sRGB - Texture\n      aliases: srgb_tx, Utility - sRGB - Texture, srgb_texture, \
         Input - Generic - sRGB - Texture, sRGB Encoded Rec.709 (sRGB)",
        "  Raw  [data, cannot be uplifted]",
        "  CIE-XYZ-D65  [display-referred]",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
    let v = Cmd::new(["colorspaces", "--json", "--ocio", "aces"])
        .ok()
        .json();
    let names: Vec<&str> = v["color_spaces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"ACEScct") && names.contains(&"Linear P3-D65"),
        "{names:?}"
    );
}

#[test]
fn colorspaces_takes_ocio_builtin_names_from_the_flag_and_the_environment() {
    let text = Cmd::new(["colorspaces", "--ocio", "ocio://studio-config-latest"])
        .ok()
        .stdout;
    for needle in [
        "config: 'ocio://studio-config-latest' (built in: ACES Studio config v1.0.0, as \
         studio-config-v1.0.0_aces-v1.3_ocio-v2.1)",
        "  ARRI LogC4\n      aliases: arri_logc4",
        "  S-Log3 S-Gamut3.Cine\n      aliases: slog3_sgamut3cine,",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
    let out = Cmd::new(["colorspaces"])
        .env("OCIO", "ocio://default")
        .run();
    let text = out.stdout.clone();
    assert!(out.code == 0);
    assert!(
        text.starts_with("config: 'ocio://default' (from $OCIO; built in: ACES CG config")
            && text.contains("  Gamma 2.2 Rec.709 - Texture")
            && !text.contains("ARRI LogC4"),
        "{text}"
    );
    Cmd::new(["colorspaces", "--ocio", "ocio://no-such-config"]).fails(
        2,
        &[
            "unknown built-in OCIO config 'ocio://no-such-config'",
            "'ocio://studio-config-latest'",
        ],
    );
}

#[test]
fn colorspaces_reads_a_config_file_and_ocio_from_the_environment() {
    let cfg = testdata("ocio/aces_interchange_only.ocio");
    let text = Cmd::new(["colorspaces", "--ocio", arg(&cfg)]).ok().stdout;
    assert!(
        text.contains("cie_xyz_d65_interchange  (not defined)"),
        "{text}"
    );
    let out = Cmd::new(["colorspaces"]).env("OCIO", &cfg).run();
    let text = out.stdout.clone();
    assert!(out.code == 0);
    assert!(
        text.contains("(from $OCIO)") && text.contains("aces_interchange         ACES2065-1"),
        "{text}"
    );
}

#[test]
fn info_uses_the_aces_interchange_route_when_there_is_no_xyz_role() {
    let cfg = testdata("ocio/aces_interchange_only.ocio");
    let exr = testdata("images/float_scanline.exr");
    // (Without --colorspace the file's linear Rec.709 has no colour space in this config and
    // goes through its exact matrix instead.)
    let text = Cmd::new([
        "info",
        "--ocio",
        arg(&cfg),
        "--colorspace",
        "ACEScg",
        arg(&exr),
    ])
    .ok()
    .stdout;
    assert!(
        text.contains("through aces_interchange (ACES2065-1)"),
        "{text}"
    );
}

/// One error line (libpng may add its own diagnostics for broken PNGs) and exit `code`: 1 for
/// a file that cannot be read, 2 for a config or colour space that cannot work for any file.
#[track_caller]
fn fails_clearly(code: i32, args: &[&str], needles: &[&str]) {
    let out = Cmd::new(args).run();
    out.fails(code, needles);
    let ours: Vec<&str> = out
        .stderr
        .lines()
        .filter(|l| l.starts_with("specconv:"))
        .collect();
    assert_eq!(ours.len(), 1, "{}", out.stderr);
    assert!(ours[0].starts_with("specconv: error: "), "{}", out.stderr);
}

#[test]
fn bad_images_fail_with_one_clear_line() {
    let missing = testdata("images/missing.exr");
    fails_clearly(1, &["info", arg(&missing)], &["missing.exr: no such file"]);
    for (name, needle) in [
        ("broken/truncated.exr", "Unexpected end of file"),
        ("broken/truncated.png", "end of file"),
        ("broken/not_an_image.png", "Not a PNG file"),
        ("broken/unknown.format", "could not find a format reader"),
    ] {
        let p = testdata(name);
        fails_clearly(
            1,
            &["info", arg(&p)],
            &[name.rsplit('/').next().unwrap(), needle],
        );
    }
}

#[test]
fn bad_colour_management_fails_with_one_clear_line() {
    let png = testdata("images/srgb8.png");
    fails_clearly(
        2,
        &["info", "--colorspace", "ACEScgg", arg(&png)],
        &["unknown colour space 'ACEScgg'", "did you mean 'ACEScg'"],
    );
    // A data space is no error: info says the texture is data (texture_prep.rs).
    fails_clearly(
        2,
        &["colorspaces", "--ocio", "/no/such.ocio"],
        &["/no/such.ocio: no such file"],
    );
    for (cfg, needle) in [
        ("ocio/broken_yaml.ocio", "end of sequence flow not found"),
        ("ocio/dangling_role.ocio", "no_such_space"),
    ] {
        let c = testdata(cfg);
        fails_clearly(
            2,
            &["colorspaces", "--ocio", arg(&c)],
            &["failed to load", needle],
        );
    }
    let c = testdata("ocio/no_interchange.ocio");
    fails_clearly(
        2,
        &[
            "info",
            "--ocio",
            arg(&c),
            "--colorspace",
            "linear",
            arg(&png),
        ],
        &["neither a cie_xyz_d65_interchange nor an aces_interchange role"],
    );
}

/// Text that would pass for other lines where it is shown: line breaks, a carriage return,
/// a terminal escape, NEL, a Unicode line separator, a bidirectional override.
const FORGERIES: [&str; 6] = [
    "ours\nspecconvSource: FORGED.png\ncommercial use: yes",
    "ours\r\nspecconvCommercialUse: yes",
    "ours\u{1b}[2K\rspecconvSource: FORGED.png",
    "ours\u{85}specconvSource: FORGED.png",
    "ours\u{2028}specconvSource: FORGED.png",
    "ours\u{202e}gnp.DEGROF :ecruoSvnoccceps",
];

/// Whether `text` holds a character that a terminal would not show as itself.
fn hidden_in(text: &str) -> bool {
    text.chars()
        .any(|c| (c.is_control() && c != '\n') || matches!(c, '\u{2028}' | '\u{202e}'))
}

#[test]
fn info_shows_every_attribute_on_one_line_and_nothing_passes_for_provenance() {
    let dir = Scratch::new("info-forged");
    let input = testdata("images/srgb8.png");
    let real = dir.path("real.exr");
    Cmd::convert(&input, &real).ok();
    let lines = Cmd::new(["info", arg(&real)]).run().ok().lines().count();
    for (k, forged) in FORGERIES.iter().enumerate() {
        // A file whose provenance was edited by another tool (oiiotool, outside the project).
        let edited = dir.path(&format!("edited{k}.exr"));
        let attrib = format!("specconvModel={forged:?}");
        tool(
            "oiiotool",
            &[
                arg(&real),
                "--sattrib",
                "specconvModel",
                forged,
                "-o",
                arg(&edited),
            ],
        );
        let out = Cmd::new(["info", arg(&edited)]).run();
        let text = out.ok();
        assert_eq!(text.lines().count(), lines, "{attrib:?}:\n{text}");
        assert_eq!(
            text.lines()
                .filter(|l| l.starts_with("specconvSource:"))
                .count(),
            1,
            "{text}"
        );
        assert!(
            !text.lines().any(|l| l.starts_with("commercial use")),
            "{text}"
        );
        assert!(!hidden_in(text), "{text:?}");
        // JSON keeps the value as it is, escaped by JSON: one line.
        let v = Cmd::new(["info", "--json", arg(&edited)]).run();
        assert_eq!(v.ok().lines().count(), 1, "{}", v.stdout);
        assert!(v.json().to_string().contains("ours"), "{}", v.stdout);
    }
}

#[test]
fn no_input_attribute_imitates_specconv_s_own() {
    let dir = Scratch::new("info-imitate");
    let input = dir.path("in.exr");
    let names = [
        "specconvSource",
        "SpecconvSource",
        "SPECCONVCOMMERCIALUSE",
        "specconv:Model",
        "spec_conv_Model",
        "Spec-Conv Commercial Use",
    ];
    let mut args = vec![arg(&testdata("images/half_scanline.exr")).to_string()];
    for n in names {
        args.extend(["--sattrib".into(), n.into(), "FORGED".into()]);
    }
    args.extend([
        "--sattrib".into(),
        "studio:specconvNote".into(),
        "kept".into(),
    ]);
    args.extend(["-o".into(), arg(&input).into()]);
    tool(
        "oiiotool",
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    let out = dir.path("out.exr");
    Cmd::convert(&input, &out).ok();
    // As exrheader (OpenEXR's own tool) lists the output's attributes.
    let header = tool("exrheader", &[arg(&out)]);
    assert!(!header.contains("FORGED"), "{header}");
    assert!(header.contains("studio:specconvNote"), "{header}");
    assert_eq!(header.matches("specconvSource ").count(), 1, "{header}");
}

#[test]
fn an_error_naming_a_hostile_file_is_one_line_of_visible_text() {
    let dir = Scratch::new("info-hostile-name");
    for forged in FORGERIES {
        let name = dir.path(&format!("{forged}.png"));
        let out = Cmd::new(["info"]).arg(&name).run();
        out.one_error_line(1, &["no such file"]);
        assert!(!hidden_in(&out.stderr), "{:?}", out.stderr);
    }
}
