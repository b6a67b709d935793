//! Texture prep as a studio does it (issue 21): UDIM tile sets and output templates, data maps
//! (roughness, normals) that are never uplifted, `to-rgb`'s declared colour, spectral inputs.
//! Inputs are made here with oiiotool and maketx; outputs are read with oiiotool and exrheader.

use crate::runner::*;
use std::path::Path;

/// A `size`² constant image of `rgb` (comma-separated) written by oiiotool, with `extra`
/// oiiotool arguments before the output (`-d uint8`, `--attrib …`).
fn constant(path: &Path, size: usize, rgb: &str, extra: &[&str]) {
    let channels = rgb.split(',').count().to_string();
    let mut args = vec![
        "--pattern".to_string(),
        format!("constant:color={rgb}"),
        format!("{size}x{size}"),
        channels,
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args.extend(["-o".into(), path.to_str().unwrap().into()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    tool("oiiotool", &args);
}

/// Three tiles of a UDIM set as 8-bit PNGs: 1001, 1002 and 1011 (the second row).
fn wood_tiles(dir: &Scratch) {
    for (n, rgb) in [
        (1001, "0.6,0.4,0.2"),
        (1002, "0.5,0.3,0.1"),
        (1011, "0.2,0.4,0.6"),
    ] {
        constant(
            &dir.path(&format!("wood.{n}.png")),
            16,
            rgb,
            &["-d", "uint8"],
        );
    }
}

#[test]
fn udim_patterns_convert_every_tile_with_the_studios_names() {
    let dir = Scratch::new("udim-template");
    wood_tiles(&dir);
    let template = format!("{}/{{stem}}_spectral.{{udim}}.exr", dir.0.display());
    for token in ["<UDIM>", "<udim>", "%(UDIM)d"] {
        let out = Cmd::new([format!("{}/wood.{token}.png", dir.0.display()).as_str()])
            .args(["--output-template", &template, "--json", "--force"])
            .ok()
            .json_lines();
        let inputs: Vec<&str> = out.iter().map(|r| r["input"].as_str().unwrap()).collect();
        let outputs: Vec<&str> = out.iter().map(|r| r["output"].as_str().unwrap()).collect();
        assert_eq!(inputs.len(), 3, "{token}: {inputs:?}");
        for (k, n) in [1001, 1002, 1011].into_iter().enumerate() {
            assert!(inputs[k].ends_with(&format!("/wood.{n}.png")), "{inputs:?}");
            assert!(
                outputs[k].ends_with(&format!("/wood_spectral.{n}.exr")),
                "{outputs:?}"
            );
        }
    }
    // What other tools see: three spectral tiles, each its own colour.
    let average = |n: u32| {
        let path = dir.path(&format!("wood_spectral.{n}.exr"));
        let header = tool("exrheader", &[path.to_str().unwrap()]);
        assert!(header.contains("T.550,000000nm"), "{header}");
        let stats = tool("oiiotool", &["--stats", path.to_str().unwrap()]);
        let line = stats.lines().find(|l| l.contains("Stats Avg")).unwrap();
        line.to_string()
    };
    assert_ne!(average(1001), average(1011));
    assert_ne!(average(1001), average(1002));
    no_temporaries(&dir.0);
}

#[test]
fn a_single_pattern_names_its_outputs_by_the_same_token() {
    let dir = Scratch::new("udim-single");
    wood_tiles(&dir);
    let d = dir.0.display();
    Cmd::convert(
        format!("{d}/wood.<UDIM>.png"),
        format!("{d}/out.<UDIM>.exr"),
    )
    .ok();
    for n in [1001, 1002, 1011] {
        assert!(dir.path(&format!("out.{n}.exr")).is_file());
    }
    // `-o DIR` keeps each tile's number in its name, so tiles never share an output.
    let o = dir.path("o");
    std::fs::create_dir(&o).unwrap();
    Cmd::new([format!("{d}/wood.<UDIM>.png")])
        .arg("-o")
        .arg(&o)
        .ok();
    let mut names: Vec<String> = std::fs::read_dir(&o)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "wood.1001_spectral.exr",
            "wood.1002_spectral.exr",
            "wood.1011_spectral.exr"
        ]
    );
}

#[test]
fn careless_udim_and_template_lines_are_refused_before_anything_is_written() {
    let dir = Scratch::new("udim-careless");
    wood_tiles(&dir);
    let d = dir.0.display().to_string();
    // A typo in a field: exit 2 naming it and the fields there are.
    Cmd::new([format!("{d}/wood.1001.png").as_str()])
        .args(["--output-template", &format!("{d}/{{stme}}_spectral.exr")])
        .refused(
            &dir,
            2,
            &[
                "unknown field {stme}",
                "{dir}, {stem}, {name}, {ext}, {udim}, {tile}",
            ],
        );
    Cmd::new([format!("{d}/wood.1001.png").as_str()])
        .args(["--output-template", &format!("{d}/{{stem.exr")])
        .refused(&dir, 2, &["no '}' closes"]);
    // Doubled braces, as Jinja writes fields (issue 31: the error named `{{stem}`): the
    // braces as written and the field they hold.
    Cmd::new([format!("{d}/wood.1001.png").as_str()])
        .args([
            "--output-template",
            &format!("{d}/{{{{stem}}}}_spectral.exr"),
        ])
        .refused(
            &dir,
            2,
            &[
                "has {{stem}}, which writes the field {stem} with braces doubled",
                "one brace on each side",
            ],
        );
    // A pattern with no tiles (a typo in the name).
    Cmd::new([format!("{d}/wod.<UDIM>.png").as_str()])
        .args(["-o", &d])
        .refused(&dir, 2, &["no UDIM tile matches", "wod.<UDIM>.png"]);
    // A pattern into one output without the token would write every tile over one file.
    Cmd::convert(format!("{d}/wood.<UDIM>.png"), format!("{d}/wood.exr")).refused(
        &dir,
        2,
        &["UDIM pattern (3 tiles)", "wood.<UDIM>.exr"],
    );
    // {udim} for an input with no tile number.
    constant(&dir.path("plain.png"), 8, "0.5,0.5,0.5", &["-d", "uint8"]);
    Cmd::new([format!("{d}/plain.png").as_str()])
        .args(["--output-template", &format!("{d}/{{stem}}.{{udim}}.exr")])
        .refused(&dir, 2, &["plain.png has no tile number"]);
    // A template without the tile that sends every tile to one name.
    Cmd::new([format!("{d}/wood.<UDIM>.png").as_str()])
        .args(["--output-template", &format!("{d}/all.exr")])
        .refused(
            &dir,
            2,
            &["wood.1001.png and ", "wood.1002.png would both write"],
        );
}

/// The built-in ACES config with a studio's file rules: `*_normal.*` and `*_mask.*` are `Raw`.
fn studio_config(dir: &Scratch) -> std::path::PathBuf {
    let yaml = specconv_ocio::CG_CONFIG_YAML.replace(
        "  - !<Rule> {name: Default, colorspace: ACES2065-1}",
        "  - !<Rule> {name: normals, colorspace: Raw, pattern: \"*_normal\", extension: \"*\"}\n  - !<Rule> {name: masks, colorspace: Raw, pattern: \"*_mask\", extension: \"*\"}\n  - !<Rule> {name: Default, colorspace: ACES2065-1}",
    );
    assert_ne!(yaml, specconv_ocio::CG_CONFIG_YAML);
    dir.write("studio.ocio", &yaml)
}

/// A studio's library: a one-channel roughness map, a normal map its config calls Raw, and an
/// albedo.
fn library(dir: &Scratch) {
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:min=0.2:max=0.8",
            "32x32",
            "1",
            "-d",
            "uint8",
            "-o",
            dir.path("brick_roughness.png").to_str().unwrap(),
        ],
    );
    constant(
        &dir.path("brick_normal.png"),
        32,
        "0.541,0.439,1.0",
        &["-d", "uint8"],
    );
    constant(
        &dir.path("brick_albedo.png"),
        32,
        "0.6,0.4,0.2",
        &["-d", "uint8"],
    );
}

#[test]
fn data_maps_are_skipped_by_default_never_uplifted_and_not_failures() {
    let dir = Scratch::new("data-skip");
    library(&dir);
    let config = studio_config(&dir);
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let names = [
        "brick_roughness.png",
        "brick_normal.png",
        "brick_albedo.png",
    ];
    let mut args: Vec<String> = vec!["--ocio".into(), config.to_str().unwrap().into()];
    args.extend(
        names
            .iter()
            .map(|n| dir.path(n).to_str().unwrap().to_owned()),
    );
    args.extend(["-o".into(), out.to_str().unwrap().into(), "--json".into()]);
    let run = Cmd::new(&args).ok();
    let records = run.json_lines();
    let field = |i: usize, k: &str| records[i][k].as_str().unwrap_or("null").to_owned();
    assert_eq!(field(0, "status"), "data", "{records:?}");
    assert_eq!(field(0, "role"), "data");
    assert_eq!(field(0, "colorspace_rule"), "one-channel");
    assert_eq!(field(1, "status"), "data");
    assert_eq!(field(1, "colorspace"), "Raw");
    assert_eq!(field(1, "colorspace_rule"), "file-rule");
    assert_eq!(field(2, "status"), "ok");
    assert_eq!(field(2, "role"), "colour");
    assert!(
        run.stderr
            .contains("1 converted, 0 skipped, 2 data textures skipped, 0 failed"),
        "{}",
        run.stderr
    );
    // Only the albedo was written.
    let written: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(written, ["brick_albedo_spectral.exr"]);
    // `--colorspace raw` makes any texture data; info says so and names the file.
    let normal = dir.path("brick_normal.png");
    let v = Cmd::new([
        "info",
        "--json",
        "--colorspace",
        "raw",
        normal.to_str().unwrap(),
    ])
    .ok()
    .json();
    assert_eq!(v["role"], "data");
    assert_eq!(v["colorspace_rule"], "colorspace-option");
    let text = Cmd::new([
        "--ocio",
        config.to_str().unwrap(),
        "info",
        normal.to_str().unwrap(),
    ])
    .ok();
    assert!(
        text.stdout.contains("brick_normal.png") && text.stdout.contains("role:         data"),
        "{}",
        text.stdout
    );
    // A single channel its colour space calls colour is achromatic colour, and uplifted.
    let rough = dir.path("brick_roughness.png");
    let v = Cmd::convert(&rough, out.join("grey.exr"))
        .args(["--colorspace", "sRGB - Texture", "--json"])
        .ok()
        .json();
    assert_eq!(v["status"], "ok");
    assert_eq!(v["role"], "achromatic");
    assert_eq!(v["bands"], 36);
}

#[test]
fn data_copy_resizes_to_powers_of_two_as_maketx_does() {
    let dir = Scratch::new("data-copy-resize");
    let config = studio_config(&dir);
    // A mask of a size that is no power of two (its name makes it Raw by the studio's rules).
    let rough = dir.path("odd_mask.png");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:min=0:max=1:seed=5",
            "40x24",
            "1",
            "-d",
            "uint8",
            "-o",
            rough.to_str().unwrap(),
        ],
    );
    let ours = dir.path("rough.exr");
    let v = Cmd::convert(&rough, &ours)
        .args(["--ocio", config.to_str().unwrap()])
        .args([
            "--data", "copy", "--resize", "--filter", "lanczos3", "--json",
        ])
        .ok()
        .json();
    assert_eq!(v["status"], "copied", "{v}");
    let theirs = dir.path("maketx.exr");
    tool(
        "maketx",
        &[
            rough.to_str().unwrap(),
            "--resize",
            "--filter",
            "lanczos3",
            "-o",
            theirs.to_str().unwrap(),
        ],
    );
    let levels = |p: &std::path::Path| {
        let info = tool("oiiotool", &["--info", "-v", p.to_str().unwrap()]);
        info.lines()
            .find(|l| l.contains("MIP-map levels"))
            .map(|l| l.trim().to_string())
            .unwrap_or_else(|| panic!("{info}"))
    };
    assert_eq!(
        levels(&ours),
        "MIP-map levels: 64x32 32x16 16x8 8x4 4x2 2x1 1x1"
    );
    assert_eq!(levels(&ours), levels(&theirs));
    // The same resized values as maketx's (level 0).
    let diff = std::process::Command::new("oiiotool")
        .args([ours.to_str().unwrap(), theirs.to_str().unwrap()])
        .args(["--fail", "0.002", "--warn", "0.002", "--diff"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&diff.stdout);
    assert!(said.contains("PASS"), "{said}");
}

#[test]
fn data_copy_writes_a_mipmapped_data_texture_with_the_values_and_metadata_kept() {
    let dir = Scratch::new("data-copy");
    library(&dir);
    let config = studio_config(&dir);
    // A maketx texture with wrap modes, as a studio's normal map is often delivered.
    let tx = dir.path("wall_normal.tx");
    tool(
        "maketx",
        &[
            dir.path("brick_normal.png").to_str().unwrap(),
            "--swrap",
            "periodic",
            "--twrap",
            "clamp",
            "-o",
            tx.to_str().unwrap(),
        ],
    );
    for (input, output) in [
        ("brick_roughness.png", "rough.exr"),
        ("wall_normal.tx", "normal.exr"),
    ] {
        let v = Cmd::convert(dir.path(input), dir.path(output))
            .args([
                "--ocio",
                config.to_str().unwrap(),
                "--data",
                "copy",
                "--json",
            ])
            .ok()
            .json();
        assert_eq!(v["status"], "copied", "{v}");
        assert_eq!(v["role"], "data");
        assert_eq!(v["levels"], 6);
        let info = tool(
            "oiiotool",
            &["--info", "-v", dir.path(output).to_str().unwrap()],
        );
        // maketx's level sizes, tiled, unconverted (no spectral channels), provenance kept.
        assert!(
            info.contains("MIP-map levels: 32x32 16x16 8x8 4x4 2x2 1x1"),
            "{info}"
        );
        assert!(info.contains("tile size: 64 x 64"), "{info}");
        assert!(!info.contains("T.550"), "{info}");
        assert!(info.contains("specconvSourceColorspace: \"Raw\""), "{info}");
        // The values are the input's, as oiiotool reads both (8-bit steps are 1/255).
        let diff = std::process::Command::new("oiiotool")
            .args([
                dir.path(input).to_str().unwrap(),
                dir.path(output).to_str().unwrap(),
            ])
            .args(["--fail", "0.001", "--warn", "0.001", "--diff"])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&diff.stdout);
        assert!(said.contains("PASS"), "{said}");
    }
    // The copy records the settings that made it: -u finds it up to date.
    let again = Cmd::convert(dir.path("brick_roughness.png"), dir.path("rough.exr"))
        .args(["--ocio", config.to_str().unwrap()])
        .args(["--data", "copy", "-u", "--json"])
        .ok()
        .json();
    assert_eq!(again["status"], "skipped", "{again}");
    let normal = tool(
        "oiiotool",
        &["--info", "-v", dir.path("normal.exr").to_str().unwrap()],
    );
    assert!(normal.contains("wrapmodes: \"periodic,clamp\""), "{normal}");
    // --wrap names a copy's wrap modes as it names a spectral texture's.
    Cmd::convert(&tx, dir.path("wrapped.exr"))
        .args(["--ocio", config.to_str().unwrap()])
        .args(["--data", "copy", "--wrap", "mirror,black"])
        .ok();
    let wrapped = tool(
        "oiiotool",
        &["--info", "-v", dir.path("wrapped.exr").to_str().unwrap()],
    );
    assert!(wrapped.contains("wrapmodes: \"mirror,black\""), "{wrapped}");
    no_temporaries(&dir.0);
}

#[test]
fn careless_data_lines_fail_clearly_and_never_touch_the_input() {
    let dir = Scratch::new("data-careless");
    library(&dir);
    let rough_exr = dir.path("rough.exr");
    tool(
        "oiiotool",
        &[
            dir.path("brick_roughness.png").to_str().unwrap(),
            "-d",
            "half",
            "-o",
            rough_exr.to_str().unwrap(),
        ],
    );
    let before = std::fs::read(&rough_exr).unwrap();
    // Copying a data texture onto itself, with or without --force: refused, input unchanged.
    for extra in [&[][..], &["--force"][..]] {
        Cmd::convert(&rough_exr, &rough_exr)
            .args(["--data", "copy"])
            .args(extra)
            .refused(&dir, 2, &["is the input"]);
    }
    assert_eq!(std::fs::read(&rough_exr).unwrap(), before);
    // --data fail: a failure (exit 1), with advice for a data map, not for colour.
    let out = Cmd::convert(dir.path("brick_roughness.png"), dir.path("r.exr"))
        .args(["--data", "fail"])
        .run();
    out.one_error_line(
        1,
        &[
            "brick_roughness.png",
            "a data texture (one channel",
            "--data copy",
        ],
    );
    assert!(!dir.path("r.exr").exists());
    // A data policy that is no policy.
    Cmd::convert(dir.path("brick_roughness.png"), dir.path("r.exr"))
        .args(["--data", "uplift"])
        .fails(2, &["uplift"]);
}

/// Mean XYZ (D65) of `path` as colour-science computes it from the file's own declaration:
/// its `chromaticities` (OpenEXR's Rec.709/D65 when it has none), Bradford-adapted to D65;
/// with whether it has `acesImageContainerFlag`.
fn xyz_as_declared(path: &Path) -> (Vec<f64>, bool) {
    const CODE: &str = r#"
import sys, json, numpy as np, OpenImageIO as oiio, colour
buf = oiio.ImageBuf(sys.argv[1])
spec = buf.spec()
rgb = np.asarray(buf.get_pixels(oiio.FLOAT))[..., :3].reshape(-1, 3).mean(axis=0)
c = spec.getattribute("chromaticities")
if c is None:
    c = (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290)
primaries, white = np.array(c[:6]).reshape(3, 2), np.array(c[6:8])
xyz = colour.normalised_primary_matrix(primaries, white) @ rgb
xyz = colour.adaptation.chromatic_adaptation_VonKries(
    xyz, colour.xy_to_XYZ(white), colour.xy_to_XYZ([0.3127, 0.3290]), transform="Bradford")
flag = spec.getattribute("acesImageContainerFlag")
print(json.dumps({"xyz": list(map(float, xyz)), "aces": flag == 1}))
"#;
    let out = python_output(["-c", CODE, path.to_str().unwrap()]);
    let v = json(&String::from_utf8_lossy(&out));
    let xyz = v["xyz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    (xyz, v["aces"].as_bool().unwrap())
}

#[test]
fn to_rgb_declares_the_space_it_writes_so_other_readers_get_the_input_colour() {
    let dir = Scratch::new("to-rgb-declared");
    // An ACEScg texture, declared by its AP1 chromaticities, as a studio's EXRs are.
    let input = dir.path("plate.exr");
    constant(
        &input,
        8,
        "0.45,0.30,0.12",
        &[
            "--attrib:type=float[8]",
            "chromaticities",
            "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767",
            "-d",
            "float",
        ],
    );
    let (want, _) = xyz_as_declared(&input);
    let spectral = dir.path("plate_spectral.exr");
    Cmd::convert(&input, &spectral).args(["-d", "float"]).ok();
    for (space, aces) in [
        (None, false),
        (Some("ACES2065-1"), true),
        (Some("Linear Rec.2020"), false),
    ] {
        let back = dir.path("back.exr");
        let mut cmd = Cmd::to_rgb(&spectral, &back).arg("--force");
        if let Some(s) = space {
            cmd = cmd.args(["--colorspace", s]);
        }
        cmd.ok();
        let (got, flag) = xyz_as_declared(&back);
        assert_eq!(flag, aces, "{space:?}");
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-3,
                "{space:?}: {got:?} read back, {want:?} in"
            );
        }
        let header = tool("exrheader", &[back.to_str().unwrap()]);
        assert!(header.contains("chromaticities"), "{header}");
        // specconv's own reader takes it as the space written.
        let v = Cmd::new(["info", "--json", back.to_str().unwrap()])
            .ok()
            .json();
        assert_eq!(v["colorspace"], space.unwrap_or("ACEScg"), "{v}");
        assert_eq!(v["colorspace_rule"], "declared");
    }
}

#[test]
fn a_studio_configs_default_rule_outranks_the_format_default_and_info_says_so() {
    let dir = Scratch::new("default-rule");
    // A studio's config: the ACES one with a rule of its own; its Default rule is ACES2065-1.
    // (The Academy's config unedited decides as built in: studio.rs.)
    let default = "  - !<Rule> {name: Default, colorspace: ACES2065-1}";
    let yaml = specconv_ocio::CG_CONFIG_YAML.replace(
        default,
        &format!(
            "  - !<Rule> {{name: normals, colorspace: Raw, pattern: \"*_normal*\", extension: \"*\"}}\n{default}"
        ),
    );
    assert_ne!(yaml, specconv_ocio::CG_CONFIG_YAML);
    let config = dir.write("studio.ocio", &yaml);
    let exr = dir.path("plate.exr");
    constant(&exr, 4, "0.3,0.2,0.1", &["-d", "half"]);
    let png = dir.path("paint.png");
    constant(&png, 4, "0.3,0.2,0.1", &["-d", "uint8"]);
    let info = |ocio: &Path, file: &Path| {
        Cmd::new([
            "--ocio",
            ocio.to_str().unwrap(),
            "info",
            "--json",
            file.to_str().unwrap(),
        ])
        .ok()
        .json()
    };
    let v = info(&config, &exr);
    assert_eq!(v["colorspace"], "ACES2065-1", "{v}");
    assert_eq!(v["colorspace_rule"], "config-default");
    assert_eq!(v["colorspace_row"], 5);
    let reason = v["colorspace_reason"].as_str().unwrap();
    assert!(
        reason.contains("'Default' file rule") && reason.contains("studio's policy"),
        "{reason}"
    );
    // The same config from $OCIO.
    let v = Cmd::new(["info", "--json", exr.to_str().unwrap()])
        .env("OCIO", &config)
        .ok()
        .json();
    assert_eq!(v["colorspace"], "ACES2065-1");
    // Built in, the Academy's config is nobody's policy: the OpenEXR default applies.
    let v = info(Path::new("aces"), &exr);
    assert_eq!(v["colorspace"], "Linear Rec.709 (sRGB)");
    assert_eq!(v["colorspace_rule"], "default");
    // Integer pixels stay sRGB texture whatever a Default rule says.
    let v = info(&config, &png);
    assert_eq!(v["colorspace"], "sRGB - Texture");
    // And info names the file in every error, first.
    let bad = dir.write("bad.exr", "not an image");
    Cmd::new(["info", bad.to_str().unwrap()])
        .run()
        .one_error_line(1, &["bad.exr: "]);
}

#[test]
fn a_spectral_input_is_refused_with_one_line_saying_what_to_do() {
    let dir = Scratch::new("spectral-input");
    let png = dir.path("albedo.png");
    constant(&png, 8, "0.6,0.4,0.2", &["-d", "uint8"]);
    let spectral = dir.path("albedo_spectral.exr");
    Cmd::convert(&png, &spectral).ok();
    let out = Cmd::convert(&spectral, dir.path("again.exr")).run();
    out.one_error_line(
        1,
        &[
            "already a spectral image (36 bands of reflectance, 380–730 nm",
            "to-rgb",
            "--bands",
        ],
    );
    assert!(
        !out.stderr.contains("T.380"),
        "no list of channels: {}",
        out.stderr
    );
    assert!(!dir.path("again.exr").exists());
}

/// Issue 57, item 14: a compact file is spectra too: `convert` refuses it as it refuses a
/// spectral EXR, naming `expand`, and writes nothing; its colour is read when channels are named.
#[test]
fn a_compact_input_is_refused_naming_expand() {
    let dir = Scratch::new("compact-input");
    let png = dir.path("albedo.png");
    constant(&png, 8, "0.6,0.4,0.2", &["-d", "uint8"]);
    let compact = dir.path("albedo_compact.exr");
    Cmd::convert(&png, &compact)
        .args(["--layout", "compact"])
        .ok();
    let again = dir.path("again.exr");
    Cmd::convert(&compact, &again).run().one_error_line(
        1,
        &[
            "a compact spectral texture",
            "specconv expand",
            "--channels",
        ],
    );
    assert!(!again.exists());
    Cmd::convert(&compact, &again)
        .args(["--channels", "R,G,B"])
        .ok();
    assert!(again.exists());
}

/// Issue 45, item 14: a data texture written through is named as data, not as a spectral file
/// (`-o DIR`'s `STEM_data.exr`, a template's `{role}`), and `info` shows it as data; an
/// output the user names is kept. Both names are planned, so neither may be a file specconv
/// did not make, and `-u` finds either up to date.
#[test]
fn data_copies_have_names_of_their_own() {
    let dir = Scratch::new("data-names");
    library(&dir);
    std::fs::create_dir_all(dir.path("out")).unwrap();
    let inputs = ["brick_roughness.png", "brick_albedo.png"].map(|i| dir.path(i));
    let batch = |extra: &[&str]| {
        Cmd::new(["convert", "--data", "copy", "--json"])
            .args(&inputs)
            .args(extra)
            .run()
    };
    let records = batch(&["-o", dir.path("out").to_str().unwrap()]);
    let records = records.json_lines();
    let output_of = |name: &str| {
        records
            .iter()
            .find(|r| r["input"].as_str().is_some_and(|i| i.ends_with(name)))
            .map(|r| r["output"].as_str().unwrap_or_default().to_string())
            .unwrap_or_default()
    };
    assert!(
        output_of("brick_roughness.png").ends_with("out/brick_roughness_data.exr"),
        "{records:?}"
    );
    assert!(
        output_of("brick_albedo.png").ends_with("out/brick_albedo_spectral.exr"),
        "{records:?}"
    );
    let mut files: Vec<String> = std::fs::read_dir(dir.path("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["brick_albedo_spectral.exr", "brick_roughness_data.exr"]
    );
    let info = Cmd::new(["info"])
        .arg(dir.path("out/brick_roughness_data.exr"))
        .ok();
    assert!(info.ok().contains("role:         data"), "{}", info.ok());
    // Both up to date: skipped by -u, whichever name each has.
    let again = batch(&["-o", dir.path("out").to_str().unwrap(), "-u"]).json_lines();
    let statuses: Vec<&str> = again.iter().filter_map(|r| r["status"].as_str()).collect();
    assert_eq!(statuses, ["skipped", "skipped"], "{again:?}");
    // A file specconv did not make at the data name is never replaced, even when -u.
    std::fs::create_dir_all(dir.path("foreign")).unwrap();
    let foreign = dir.path("foreign/brick_roughness_data.exr");
    std::fs::write(&foreign, b"mine").unwrap();
    for extra in [&[][..], &["-u"][..]] {
        let foreign_dir = dir.path("foreign");
        let mut args = vec!["-o", foreign_dir.to_str().unwrap()];
        args.extend(extra);
        let out = batch(&args);
        out.fails(2, &["brick_roughness_data.exr"]);
    }
    assert_eq!(std::fs::read(&foreign).unwrap(), b"mine");
    assert!(!dir.path("foreign/brick_albedo_spectral.exr").exists());
    // A template's {role}; without it, the one name the user chose.
    let t = format!("{}/{{stem}}.{{role}}.exr", dir.path("t").display());
    std::fs::create_dir_all(dir.path("t")).unwrap();
    batch(&["--output-template", &t]).ok();
    assert!(dir.path("t/brick_roughness.data.exr").exists());
    assert!(dir.path("t/brick_albedo.spectral.exr").exists());
    Cmd::convert(&inputs[0], dir.path("mine.exr"))
        .args(["--data", "copy"])
        .ok();
    assert!(dir.path("mine.exr").exists());
    no_temporaries(&dir.0);
}
