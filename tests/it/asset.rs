//! `specconv asset` (issue 46, docs/assets.md): stages built with Pixar's usd-core
//! (tests/asset_stages.py), each texture decided by the material that reads it, and the layer
//! the command writes opened with usd-core again. Without usd-core in `$SPECCONV_PYTHON` these
//! tests are skipped, loudly, unless `$SPECCONV_REQUIRE_USD` is set (CI sets it).

use crate::runner::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The interpreter with usd-core, or `None` (skip) when it has none.
fn usd() -> Option<String> {
    python_with("pxr.Usd", "usd-core")
}

/// `$SPECCONV_PYTHON` when it imports `modules` (comma-separated), or `None` (skip, said
/// loudly); with `$SPECCONV_REQUIRE_USD` set, a missing module fails the test, naming the
/// `packages` to install.
pub(crate) fn python_with(modules: &str, packages: &str) -> Option<String> {
    let python = python();
    let has = std::process::Command::new(&python)
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has {
        assert!(
            std::env::var_os("SPECCONV_REQUIRE_USD").is_none(),
            "SPECCONV_REQUIRE_USD is set but {python} lacks {packages} (pip install {packages})"
        );
        eprintln!("SKIPPED: {python} lacks {packages} (pip install {packages})");
    }
    has.then_some(python)
}

/// The textures of the stages, written by oiiotool, then the stage `kind` in `dir`.
fn stage(dir: &Path, kind: &str) {
    let tex = dir.join("tex");
    std::fs::create_dir_all(&tex).unwrap();
    for name in [
        "rock_albedo",
        "rock_arm",
        "rock_normal",
        "clean_albedo",
        "dirty_albedo",
        "never",
        "shared",
        "wood.1001",
        "wood.1002",
    ] {
        let p = tex.join(format!("{name}.png"));
        let p = p.to_str().unwrap();
        tool(
            "oiiotool",
            &["--pattern", "checker", "8x8", "4", "-d", "uint8", "-o", p],
        );
    }
    let exr = tex.join("wood_acescg.exr");
    let exr = exr.to_str().unwrap();
    tool(
        "oiiotool",
        &["--pattern", "checker", "8x8", "3", "-d", "half", "-o", exr],
    );
    script("asset_stages.py", [kind, dir.to_str().unwrap()]);
}

fn asset(python: &str, stage: &Path, out: &Path) -> Cmd {
    Cmd::new([
        "asset",
        stage.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ])
    .env("SPECCONV_USD_PYTHON", python)
}

/// Every file under `dir`, recursively, with its size.
fn tree(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let m = std::fs::symlink_metadata(&p).unwrap();
        if m.is_dir() {
            v.extend(tree(&p));
        } else {
            v.push((p, m.len()));
        }
    }
    v.sort();
    v
}

/// The record of the texture whose file name is `name` (the first of its tiles).
pub(crate) fn record<'a>(records: &'a [Value], name: &str) -> &'a Value {
    records
        .iter()
        .find(|r| r["asset"]["texture"].as_str().unwrap().ends_with(name))
        .unwrap_or_else(|| panic!("no record of {name}: {records:#?}"))
}

/// What usd-core makes of the layer (tests/asset_layer_view.py): each texture node's
/// `inputs:file` as the spectral choice (render context `spectral`) reads it, with its
/// customData; and, checked here for every test stage, that with no choice made every
/// `inputs:file` and every material's surface is the stage's own (issue 56, item 1).
fn layer_files(python: &str, layer: &Path) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/asset_layer_view.py");
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(layer)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(
        v["rgb_changed"].as_array().map(Vec::len),
        Some(0),
        "what RGB renderers read changed: {v:#}"
    );
    v
}

/// The basic stage in `dir/shot`, with the texture it reads outside its folder
/// (`dir/outside/sky.png`); returns the stage's folder.
fn basic_shot(dir: &Scratch) -> PathBuf {
    let shot = dir.path("shot");
    std::fs::create_dir_all(&shot).unwrap();
    std::fs::create_dir_all(dir.path("outside")).unwrap();
    let sky = dir.path("outside/sky.png");
    let sky = sky.to_str().unwrap();
    tool(
        "oiiotool",
        &["--pattern", "checker", "8x8", "3", "-d", "uint8", "-o", sky],
    );
    stage(&shot, "basic");
    shot
}

#[test]
fn the_material_decides_and_the_layer_points_at_the_spectral_files() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-basic");
    let shot = basic_shot(&dir);
    let before = tree(&dir.0);
    let out = dir.path("out");
    let run = asset(&python, &shot.join("shot.usda"), &out)
        .arg("--json")
        .ok();
    let records = run.json_lines();
    // Only what bound materials read, the selected variant's: 7 files, the UDIM pattern's two
    // tiles each a record.
    let names: Vec<&str> = records
        .iter()
        .map(|r| r["input"].as_str().unwrap())
        .collect();
    assert_eq!(records.len(), 8, "{names:?}");
    assert!(!names
        .iter()
        .any(|n| n.contains("clean_albedo") || n.contains("never")));
    // rgb → diffuseColor with a → opacity: one colour texture with alpha, sRGB as declared.
    let albedo = record(&records, "rock_albedo.png");
    assert_eq!(albedo["status"], "ok");
    assert_eq!(albedo["colorspace"], "sRGB - Texture");
    assert_eq!(albedo["asset"]["rule"], "source-color-space");
    assert!(albedo["asset"]["why"]
        .as_str()
        .unwrap()
        .contains("with alpha"));
    // ARM (r, g, b → occlusion, roughness, metallic) and a raw normal map: data, skipped.
    for data in ["rock_arm.png", "rock_normal.png"] {
        let r = record(&records, data);
        assert_eq!(r["status"], "data", "{r:#}");
        assert_eq!(r["asset"]["rule"], "data-input");
        assert_eq!(r["role"], "data");
    }
    let arm = record(&records, "rock_arm.png");
    let inputs: Vec<&str> = arm["asset"]["uses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|u| u["input"].as_str().unwrap())
        .collect();
    assert_eq!(inputs.len(), 3, "{inputs:?}");
    // The MaterialX colorspace names the space outright: ACEScg, over the EXR's silence.
    let acescg = record(&records, "wood_acescg.exr");
    assert_eq!(acescg["colorspace"], "ACEScg");
    assert_eq!(acescg["asset"]["rule"], "materialx-colorspace");
    // The variant selected (dirty), `auto`: the file's evidence (an 8-bit PNG: sRGB).
    let dirty = record(&records, "dirty_albedo.png");
    assert_eq!(dirty["asset"]["rule"], "colour-input");
    assert_ne!(dirty["colorspace_rule"], "colorspace-option");
    assert!(dirty["asset"]["colorspace_given"].is_null());
    assert_eq!(dirty["colorspace"], "sRGB - Texture");
    // UDIM tiles, and a texture outside the stage's folder: outputs inside DIR.
    assert!(out.join("tex/wood_spectral.1001.exr").is_file());
    assert!(out.join("tex/wood_spectral.1002.exr").is_file());
    let sky_out = record(&records, "sky.png")["output"]
        .as_str()
        .unwrap()
        .to_owned();
    assert!(
        Path::new(&sky_out).starts_with(out.join("external")),
        "{sky_out}"
    );
    // Nothing outside DIR was written or changed.
    let after: Vec<(PathBuf, u64)> = tree(&dir.0)
        .into_iter()
        .filter(|(p, _)| !p.starts_with(&out))
        .collect();
    assert_eq!(before, after);
    no_temporaries(&out);
    // The layer, opened by usd-core: colour textures at their spectral files (their originals
    // recorded), data textures untouched.
    let layer = out.join("shot_spectral.usda");
    let v = layer_files(&python, &layer);
    let files = &v["files"];
    let node = &files["/World/Rock/Looks/Rock/Albedo"];
    assert_eq!(node["file"], "./tex/rock_albedo_spectral.exr");
    assert_eq!(node["original"], "./tex/rock_albedo.png");
    assert_eq!(node["scs"], "raw");
    assert_eq!(
        Path::new(node["resolved"].as_str().unwrap()),
        out.join("tex/rock_albedo_spectral.exr")
    );
    assert_eq!(
        files["/World/Looks/Mx/Wood"]["file"],
        "./tex/wood_spectral.<UDIM>.exr"
    );
    assert_eq!(
        files["/World/Rock/Looks/Rock/Arm"]["file"],
        "./tex/rock_arm.png"
    );
    assert!(files["/World/Rock/Looks/Rock/Arm"]["original"].is_null());
    // A MaterialX node's colorspace would convert the spectra from ACEScg: raw, the original kept.
    let mx = &files["/World/Looks/Mx/Base"];
    assert_eq!(mx["file"], "./tex/wood_acescg_spectral.exr");
    assert_eq!(
        (&mx["cs"], &mx["original_cs"]),
        (&json("\"raw\""), &json("\"acescg\""))
    );
    assert!(files["/World/Rock/Looks/Rock/Albedo"]["cs"].is_null());
    // The switch (issue 56, item 1): the spectral render context's surface is the copy; with
    // no choice (checked by layer_files for every input) the stage's own network.
    assert_eq!(
        v["contexts"]["/World/Rock/Looks/Rock"],
        "/World/Rock/Looks/Rock/Surface_spectral"
    );
    assert_eq!(
        node["copy"], "/World/Rock/Looks/Rock/Albedo_spectral",
        "{v:#}"
    );
    // A second run with -u converts nothing and rewrites the layer.
    let again = asset(&python, &shot.join("shot.usda"), &out)
        .args(["--json", "-u"])
        .ok()
        .json_lines();
    assert!(again
        .iter()
        .all(|r| r["status"] == "skipped" || r["status"] == "data"));
}

#[test]
fn dry_run_prints_decisions_and_writes_nothing() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-dry");
    let shot = basic_shot(&dir);
    let out = dir.path("out");
    let run = asset(&python, &shot.join("shot.usda"), &out)
        .args(["--dry-run", "--json"])
        .ok();
    let decisions = run.json_lines();
    assert!(!out.exists(), "a dry run made {}", out.display());
    let rules: Vec<&str> = decisions
        .iter()
        .map(|d| d["rule"].as_str().unwrap())
        .collect();
    assert!(rules.contains(&"data-input") && rules.contains(&"materialx-colorspace"));
}

/// Issue 57, item 13, and issue 58, item 5: modules in the directory `asset` runs in are not
/// the reader's. A stray `json.py` and `pxr.py` there (each would leave a mark and break the
/// reader) change nothing: the reader runs in `python -I`, and of `$PYTHONPATH` only absolute
/// folders are put back, so an empty entry, `.` or a relative folder (`sub`, holding another
/// `json.py`) does not bring the working directory back.
#[test]
fn modules_in_the_working_directory_are_never_imported() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-stray");
    let shot = basic_shot(&dir);
    let marks = dir.path("imported");
    std::fs::create_dir_all(dir.path("sub")).unwrap();
    for module in ["json", "pxr", "MaterialX", "sub/json"] {
        dir.write(
            &format!("{module}.py"),
            &format!(
                "open({:?}, 'a').write('{module}\\n')\nraise SystemExit(9)\n",
                marks.to_str().unwrap()
            ),
        );
    }
    let out = dir.path("out");
    let run = asset(&python, &shot.join("shot.usda"), &out)
        .args(["--dry-run", "--json"])
        .env("PYTHONPATH", ":.:sub")
        .current_dir(&dir.0)
        .ok();
    assert!(!run.json_lines().is_empty());
    assert!(!marks.exists(), "{:?}", std::fs::read_to_string(&marks));
    // The check of the check: the same interpreter without -I, in that folder, runs them.
    let plain = std::process::Command::new(&python)
        .args(["-c", "import json"])
        .current_dir(&dir.0)
        .status()
        .unwrap();
    assert_eq!(plain.code(), Some(9));
    assert_eq!(std::fs::read_to_string(&marks).unwrap(), "json\n");
}

/// Issue 57, item 12: an interpreter that fails without a word is named, not "failed:".
#[test]
fn an_interpreter_that_says_nothing_is_named() {
    if usd().is_none() {
        return;
    }
    let dir = Scratch::new("asset-false");
    let shot = basic_shot(&dir);
    asset("/bin/false", &shot.join("shot.usda"), &dir.path("out")).fails(
        1,
        &[
            "'/bin/false' exited with",
            "said nothing",
            "SPECCONV_USD_PYTHON",
        ],
    );
}

/// Issue 57, item 5: a normal map reaching `normal` through more nodes than the reader
/// follows is not taken for colour: the walk says it gave up, the texture is not converted
/// (exit 1), and the layer leaves it alone; the colour texture beside it is converted.
#[test]
fn a_walk_that_gives_up_decides_nothing() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-deep");
    stage(&dir.0, "deep");
    let out = dir.path("out");
    let run = asset(&python, &dir.path("deep.usda"), &out)
        .arg("--json")
        .run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    let records = json_lines_of(&run.stdout);
    let normal = record(&records, "rock_normal.png");
    assert_eq!(normal["asset"]["rule"], "undecided", "{normal:#}");
    let why = normal["asset"]["why"].as_str().unwrap();
    assert!(
        why.contains("gave up") && why.contains("/Looks/Deep/Pass"),
        "{why}"
    );
    assert!(!out.join("tex/rock_normal_spectral.exr").exists());
    assert_eq!(record(&records, "rock_albedo.png")["status"], "ok");
}

/// Issue 57, item 6: a UDIM pattern read as colour and one of its tiles read by name as a
/// normal map: a conflict naming both, neither converted, exit 1, and no tile written.
#[test]
fn a_tile_read_as_data_and_as_a_colour_pattern_is_a_conflict() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-udim-conflict");
    stage(&dir.0, "udim_conflict");
    let out = dir.path("out");
    let run = asset(&python, &dir.path("udim_conflict.usda"), &out).run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(
        run.stderr.contains("wood.1001.png is read as")
            && run.stderr.contains("wood.<UDIM>.png (colour-input)")
            && run.stderr.contains("(data-input)"),
        "{}",
        run.stderr
    );
    let written: Vec<_> = tree(&out)
        .into_iter()
        .filter(|(p, _)| p.to_string_lossy().contains("wood"))
        .collect();
    assert!(written.is_empty(), "{written:?}");
}

#[test]
fn a_conflict_names_both_uses_and_is_never_uplifted() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-conflict");
    stage(&dir.0, "conflict");
    let out = dir.path("out");
    let run = asset(&python, &dir.path("conflict.usda"), &out).fails(
        1,
        &[
            "/Looks/A/Surface.inputs:diffuseColor reads rgb of /Textures/Tex",
            "/Looks/B/Surface.inputs:normal reads rgb of /Textures/Tex",
            "outside its material",
            "not converted",
        ],
    );
    drop(run);
    assert!(!out.join("tex/shared_spectral.exr").exists());
}

/// One file as colour in one material and as data in another (each texture node in its
/// material): converted; with the spectral choice /Looks/A reads the spectral file, and
/// /Looks/B, which only reads data from it, has no spectral network and reads the original.
#[test]
fn one_file_as_colour_and_as_data_is_converted_and_the_data_keeps_the_original() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-shared");
    stage(&dir.0, "shared");
    let out = dir.path("out");
    let records = asset(&python, &dir.path("shared.usda"), &out)
        .args(["--json"])
        .ok()
        .json_lines();
    assert_eq!(records.len(), 1, "{records:#?}");
    assert_eq!(records[0]["asset"]["rule"], "source-color-space");
    assert!(
        records[0]["asset"]["why"]
            .as_str()
            .unwrap()
            .contains("its data uses keep the original file (/Looks/B/Surface.inputs:normal"),
        "{records:#?}"
    );
    let view = layer_files(&python, &out.join("shared_spectral.usda"));
    assert_eq!(
        view["files"]["/Looks/A/Tex"]["file"],
        "./tex/shared_spectral.exr"
    );
    assert_eq!(view["files"]["/Looks/B/Tex"]["file"], "./tex/shared.png");
    assert_eq!(view["files"]["/Looks/B/Tex"]["copy"], Value::Null);
    // No spectral network: the render context falls back to the universal one.
    assert_eq!(view["contexts"]["/Looks/B"], "/Looks/B/Surface", "{view:#}");
}

#[test]
fn a_missing_texture_names_the_prim_that_reads_it() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-missing");
    stage(&dir.0, "missing");
    // Where it was looked for too (the layer's folder).
    let at = format!("(looked for at {})", dir.path("tex/gone.png").display());
    asset(&python, &dir.path("missing.usda"), &dir.path("out"))
        .fails(1, &["/Looks/M/Gone", "gone.png", &at, "does not exist"]);
}

#[test]
fn a_reference_cycle_is_a_clear_error_and_writes_nothing() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-cycle");
    stage(&dir.0, "cycle");
    let out = dir.path("out");
    let run = asset(&python, &dir.path("cycle_a.usda"), &out).run_within(Duration::from_secs(120));
    assert_eq!(run.code, 1);
    let err = &run.stderr;
    assert!(
        err.contains("does not compose") && err.contains("Cycle"),
        "{err}"
    );
    assert!(tree(&out).is_empty(), "{:?}", tree(&out));
}

#[test]
fn a_usdz_package_is_read_and_its_textures_copied_out_inside_dir() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-usdz");
    stage(&dir.0, "package");
    let out = dir.path("out");
    // A dry run on a package decides its textures and writes nothing: no DIR, no record
    // (it once failed for want of DIR/.specconv-asset.json; found on usd-wg/assets).
    let dry = asset(&python, &dir.path("packed.usdz"), &out)
        .args(["--dry-run", "--json"])
        .ok()
        .json_lines();
    assert_eq!(dry.len(), 1, "{dry:#?}");
    assert_eq!(dry[0]["rule"], "source-color-space", "{dry:#?}");
    assert!(!out.exists());
    let records = asset(&python, &dir.path("packed.usdz"), &out)
        .arg("--json")
        .ok()
        .json_lines();
    assert_eq!(records.len(), 1);
    assert_eq!(records[0]["status"], "ok");
    let output = PathBuf::from(records[0]["output"].as_str().unwrap());
    assert!(
        output.starts_with(out.join("packed_usdz")),
        "{}",
        output.display()
    );
    let v = layer_files(&python, &out.join("packed_spectral.usda"));
    let file = v["files"]["/Looks/P/Albedo"]["resolved"].as_str().unwrap();
    assert_eq!(Path::new(file), output);
    // Copied out again unchanged, the copy is kept as it was: -u finds the output up to date.
    let again = asset(&python, &dir.path("packed.usdz"), &out)
        .args(["--json", "-u"])
        .ok()
        .json_lines();
    assert_eq!(again[0]["status"], "skipped", "{:#}", again[0]);
    // A corrupt package: usd-core's refusal, said as an error.
    let bytes = std::fs::read(dir.path("packed.usdz")).unwrap();
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    bad[mid..mid + 64].fill(b'X');
    std::fs::write(dir.path("corrupt.usdz"), &bad).unwrap();
    asset(&python, &dir.path("corrupt.usdz"), &dir.path("out2"))
        .fails(1, &["usd-core cannot open the stage"]);
}

/// Issue 57, item 11: `a.png`, `a.tif` and `a_png.png` in one folder, all colour: three
/// outputs, three names (where stem and extension meet, the path's hash), the same on a second
/// run (`-u` skips all three), each material's layer input its own file.
#[test]
fn outputs_whose_names_meet_are_told_apart_and_stay_so() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-stem-clash");
    std::fs::create_dir_all(dir.path("tex")).unwrap();
    for (name, pattern) in [("a.png", "4"), ("a.tif", "2"), ("a_png.png", "3")] {
        let p = dir.path(&format!("tex/{name}"));
        tool(
            "oiiotool",
            &[
                "--pattern",
                "checker",
                "8x8",
                pattern,
                "-d",
                "uint8",
                "-o",
                p.to_str().unwrap(),
            ],
        );
    }
    script("asset_stages.py", ["stem_clash", dir.0.to_str().unwrap()]);
    let out = dir.path("out");
    let outputs = |extra: &str| -> Vec<(String, String)> {
        let mut v: Vec<(String, String)> = asset(&python, &dir.path("stem_clash.usda"), &out)
            .args(["--json", extra])
            .ok()
            .json_lines()
            .iter()
            .map(|r| {
                (
                    r["output"].as_str().unwrap().to_string(),
                    r["status"].as_str().unwrap().to_string(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let first = outputs("--force");
    assert_eq!(first.len(), 3, "{first:?}");
    let names: std::collections::BTreeSet<&String> = first.iter().map(|(o, _)| o).collect();
    assert_eq!(names.len(), 3, "{first:?}");
    assert!(first
        .iter()
        .all(|(o, status)| status == "ok" && Path::new(o).is_file()));
    let again = outputs("-u");
    assert!(
        again.iter().all(|(_, status)| status == "skipped"),
        "{again:?}"
    );
    assert_eq!(
        again.iter().map(|(o, _)| o).collect::<Vec<_>>(),
        first.iter().map(|(o, _)| o).collect::<Vec<_>>()
    );
    let v = layer_files(&python, &out.join("stem_clash_spectral.usda"));
    let mut resolved: Vec<&str> = (0..3)
        .map(|k| {
            v["files"][format!("/Looks/M{k}/Albedo")]["resolved"]
                .as_str()
                .unwrap()
        })
        .collect();
    resolved.sort();
    assert_eq!(
        resolved,
        first.iter().map(|(o, _)| o.as_str()).collect::<Vec<_>>()
    );
}

/// Issue 57, item 12: what usd-core, MaterialX or Python raise on a hostile asset is one line
/// that says what is wrong, exit 1, no traceback, nothing written in DIR: a Latin-1 byte in a
/// texture's path (the stage's text is not UTF-8 there), a MaterialX graph input whose
/// `interfacename` names itself on the walk from a texture to the shader, a usdz whose members
/// are deflated (usdz stores them).
#[test]
fn a_reader_s_failure_is_one_line_that_says_what_is_wrong() {
    let Some(python) = python_with("pxr.Usd, MaterialX", "usd-core MaterialX") else {
        return;
    };
    let dir = Scratch::new("asset-reader-failures");
    std::fs::create_dir_all(dir.path("tex")).unwrap();
    let png = dir.path("tex/a.png");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "checker",
            "8x8",
            "3",
            "-d",
            "uint8",
            "-o",
            png.to_str().unwrap(),
        ],
    );
    let mut latin = b"#usda 1.0\ndef Material \"M\"\n{\n    token outputs:surface.connect = </M/S.outputs:surface>\n    def Shader \"S\"\n    {\n        uniform token info:id = \"UsdPreviewSurface\"\n        color3f inputs:diffuseColor.connect = </M/T.outputs:rgb>\n        token outputs:surface\n    }\n    def Shader \"T\"\n    {\n        uniform token info:id = \"UsdUVTexture\"\n        asset inputs:file = @./tex/caf".to_vec();
    latin.extend_from_slice(b"\xe9.png@\n        float3 outputs:rgb\n    }\n}\n");
    std::fs::write(dir.path("latin.usda"), latin).unwrap();
    let looped = r#"<?xml version="1.0"?>
<materialx version="1.38">
  <nodegraph name="NG">
    <input name="base" type="color3" interfacename="base" />
    <image name="img" type="color3">
      <input name="file" type="filename" value="tex/a.png" />
    </image>
    <mix name="blend" type="color3">
      <input name="fg" type="color3" nodename="img" />
      <input name="bg" type="color3" interfacename="base" />
    </mix>
    <output name="out" type="color3" nodename="blend" />
  </nodegraph>
  <standard_surface name="SS" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="NG" output="out" />
  </standard_surface>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SS" />
  </surfacematerial>
</materialx>
"#;
    dir.write("looped.mtlx", looped);
    let deflate = "import sys, zipfile\n\
        from pxr import Usd\n\
        Usd.Stage.CreateNew(sys.argv[1] + '/d.usdc').Save()\n\
        with zipfile.ZipFile(sys.argv[1] + '/deflated.usdz', 'w', zipfile.ZIP_DEFLATED) as z:\n\
        \x20   z.write(sys.argv[1] + '/d.usdc', 'd.usdc')\n\
        \x20   z.write(sys.argv[1] + '/tex/a.png', 'tex/a.png')\n";
    let made = std::process::Command::new(&python)
        .args(["-c", deflate, dir.0.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    for (file, needles) in [
        (
            "latin.usda",
            &[
                "not text in its encoding",
                r"\xe9.png@",
                "</M/T.inputs:file>",
            ][..],
        ),
        ("looped.mtlx", &["loops", "interfacenames"][..]),
        ("deflated.usdz", &["compressed files are not supported"][..]),
    ] {
        let out = dir.path(&format!("out-{file}"));
        let run = asset(&python, &dir.path(file), &out).run();
        run.one_error_line(1, needles);
        assert!(!run.stderr.contains("Traceback"), "{file}: {}", run.stderr);
        assert!(tree(&out).is_empty(), "{file}: {:?}", tree(&out));
    }
}

/// Issue 57, item 2: a stage that sublayers `STEM_spectral.usda`, converted into its own
/// folder: the layer would be written over a file the stage reads; refused with every flag,
/// the sublayer and the stage unchanged, nothing converted.
#[test]
fn a_layer_the_stage_sublayers_is_never_written_over() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-self-sublayer");
    stage(&dir.0, "self_sublayer");
    let (stage_file, own) = (
        dir.path("self_sublayer.usda"),
        dir.path("self_sublayer_spectral.usda"),
    );
    let before = (
        std::fs::read(&stage_file).unwrap(),
        std::fs::read(&own).unwrap(),
    );
    for flags in [&[][..], &["-u"], &["--force"]] {
        asset(&python, &stage_file, &dir.0).args(flags).fails(
            2,
            &["self_sublayer_spectral.usda is a file the stage reads"],
        );
        let after = (
            std::fs::read(&stage_file).unwrap(),
            std::fs::read(&own).unwrap(),
        );
        assert!(after == before, "{flags:?}: changed");
        assert!(
            !dir.path("tex/rock_albedo_spectral.exr").exists(),
            "{flags:?}"
        );
    }
}

/// Issue 56, item 3: the layer has the stage's defaultPrim and names the stage relative to
/// itself, so that it is referenced as the stage is and moves with it: the stage's folder
/// (its output inside) moved elsewhere, the layer still composes, without errors, every
/// spectral file found under the new folder. `-u` on an unchanged asset leaves the layer
/// as it was, bytes and mtime.
#[test]
fn the_layer_is_packaged_to_be_referenced_and_moved() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-packaging");
    let shot = basic_shot(&dir);
    let out = shot.join("out");
    asset(&python, &shot.join("shot.usda"), &out).ok();
    let layer = out.join("shot_spectral.usda");
    let text = std::fs::read_to_string(&layer).unwrap();
    assert!(text.contains("defaultPrim = \"World\""), "{text}");
    assert!(
        !text.contains(shot.to_str().unwrap().trim_end_matches('/')) || {
            // Only the provenance of each override (customData) names absolute paths.
            text.lines()
                .filter(|l| l.contains(shot.to_str().unwrap()))
                .all(|l| l.contains("originalResolved"))
        },
        "{text}"
    );
    let (mtime, bytes) = (
        std::fs::metadata(&layer).unwrap().modified().unwrap(),
        std::fs::read(&layer).unwrap(),
    );
    std::thread::sleep(Duration::from_millis(20));
    asset(&python, &shot.join("shot.usda"), &out).arg("-u").ok();
    assert_eq!(std::fs::read(&layer).unwrap(), bytes);
    assert_eq!(
        std::fs::metadata(&layer).unwrap().modified().unwrap(),
        mtime
    );
    // Moved with its output: composes, and every spectral file is the moved one.
    let moved = dir.path("moved");
    std::fs::rename(&shot, &moved).unwrap();
    let code = "import json, sys\n\
        from pxr import Usd, Sdf\n\
        s = Usd.Stage.Open(sys.argv[1])\n\
        files = [p.GetAttribute('inputs:file').Get().resolvedPath\n\
        \x20        or p.GetAttribute('inputs:file').Get().path for p in s.Traverse()\n\
        \x20        if p.GetAttribute('inputs:file') and 'spectral' in p.GetAttribute('inputs:file').Get().path]\n\
        ref = Usd.Stage.CreateInMemory()\n\
        ref.DefinePrim('/Shot').GetReferences().AddReference(sys.argv[1])\n\
        print(json.dumps(dict(errors=[str(e) for e in s.GetCompositionErrors()], files=files,\n\
        \x20   referenced=ref.GetPrimAtPath('/Shot').GetChildren() != [])))\n";
    let got = std::process::Command::new(&python)
        .args([
            "-c",
            code,
            moved.join("out/shot_spectral.usda").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        got.status.success(),
        "{}",
        String::from_utf8_lossy(&got.stderr)
    );
    let v = json(&String::from_utf8_lossy(&got.stdout));
    assert_eq!(v["errors"].as_array().unwrap().len(), 0, "{v:#}");
    assert_eq!(v["referenced"], true, "{v:#}");
    let files = v["files"].as_array().unwrap();
    assert!(!files.is_empty(), "{v:#}");
    for f in files {
        let f = f.as_str().unwrap();
        // A UDIM pattern is not resolved by usd-core: its tile 1001, from the layer's folder.
        let f = match f.strip_prefix("./") {
            Some(rel) if f.contains("<UDIM>") => {
                moved.join("out").join(rel.replace("<UDIM>", "1001"))
            }
            _ => PathBuf::from(f),
        };
        assert!(
            f.starts_with(&moved) && f.is_file(),
            "{}: {v:#}",
            f.display()
        );
    }
}

/// Issue 56, item 2 in part: an Arnold network (`arnold:image` → `arnold:standard_surface`)
/// and a RenderMan one (`PxrTexture` → `PxrSurface`) each read a file this reader does not
/// decide: never "nothing to convert" in silence. Each is reported, naming the shader, its prim
/// and the file, in text and in --json (status `unknown-shader`); `--strict` (a warning is a
/// failure, as for `convert`) makes the run exit 1; nothing is converted either way.
#[test]
fn unknown_shaders_that_read_files_are_reported_and_fail_under_strict() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-foreign");
    stage(&dir.0, "foreign");
    let run = asset(&python, &dir.path("foreign.usda"), &dir.path("out")).run();
    assert_eq!(run.code, 0, "{}", run.stderr);
    let needle = "unknown shader studio:projector at /Looks/Studio/Image reads \
                  ./tex/clean_albedo.png";
    assert!(run.stderr.contains(needle), "{needle}: {}", run.stderr);
    // Arnold's and RenderMan's readers are known (their definitions' tables): converted.
    for known in ["rock_albedo_spectral.exr", "dirty_albedo_spectral.exr"] {
        assert!(
            dir.path("out/tex").join(known).is_file(),
            "{known}: {}",
            run.stderr
        );
    }
    assert!(
        !run.stderr.contains("unknown shader arnold"),
        "{}",
        run.stderr
    );
    assert!(!run.stderr.contains("unknown shader Pxr"), "{}", run.stderr);
    let run = asset(&python, &dir.path("foreign.usda"), &dir.path("strict"))
        .args(["--strict", "--json"])
        .run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    let records = json_lines_of(&run.stdout);
    let shaders: Vec<&str> = records
        .iter()
        .filter(|r| r["status"] == "unknown-shader")
        .map(|r| r["asset"]["shader"].as_str().unwrap())
        .collect();
    assert_eq!(shaders, ["studio:projector"], "{records:#?}");
    // The run fails, as a warning does under --strict; what it knows is converted.
    let written: Vec<String> = tree(&dir.path("strict"))
        .iter()
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".exr"))
        .collect();
    assert_eq!(
        written,
        ["dirty_albedo_spectral.exr", "rock_albedo_spectral.exr"]
    );
}

/// A reader's file input authored as no path (`int inputs:filename = 3` on a PxrTexture) is one
/// line naming the prim and input and how to author it, exit 1, nothing written.
#[test]
fn a_file_input_that_is_no_path_is_named() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-file-type");
    let stage_file = dir.write(
        "odd.usda",
        "#usda 1.0\ndef Material \"M\" {\n    token outputs:ri:surface.connect = \
         </M/S.outputs:out>\n    def Shader \"S\" {\n        uniform token info:id = \
         \"PxrSurface\"\n        color3f inputs:diffuseColor.connect = \
         </M/T.outputs:resultRGB>\n        token outputs:out\n    }\n    def Shader \"T\" {\n \
                uniform token info:id = \"PxrTexture\"\n        int inputs:filename = 3\n \
                color3f outputs:resultRGB\n    }\n}\ndef Mesh \"G\" (prepend apiSchemas = \
         [\"MaterialBindingAPI\"]) {\n    rel material:binding = </M>\n}\n",
    );
    let run = asset(&python, &stage_file, &dir.path("out")).run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert!(
        run.stderr
            .contains("/M/T.inputs:filename is typed int, not a path"),
        "{}",
        run.stderr
    );
    assert_eq!(run.stderr.trim().lines().count(), 1, "{}", run.stderr);
    assert!(!dir.path("out").join("odd_spectral.usda").exists());
}

/// Issue 56, item 2: every shading model's network (UsdPreviewSurface, standard_surface,
/// open_pbr_surface, gltf_pbr in USD; Arnold's standard_surface; RenderMan's PxrSurface) with
/// colour, data, alpha, normal, bump and subsurface textures. Each texture's decision is the
/// role tests/asset_stages.py checked against the definition's type of the input it reaches
/// (MaterialX's nodedefs and usd-core's Sdr read there on their own; for Arnold and
/// RenderMan the USD types their writers give), every use names its type and definition,
/// and the layer (read by usd-core) gives RGB renderers every file input as it was and the
/// spectral context exactly the colour textures' spectral files, each read raw.
#[test]
fn every_shading_model_s_textures_take_the_role_of_their_input_s_type() {
    let Some(python) = python_with("pxr.Usd, MaterialX", "usd-core MaterialX") else {
        return;
    };
    let dir = Scratch::new("asset-networks");
    script("asset_stages.py", ["networks", dir.0.to_str().unwrap()]);
    let roles = roles_with_textures(&dir, "networks.json");
    let stage_file = dir.path("networks.usda");
    let run = asset(&python, &stage_file, &dir.path("out"))
        .args(["--json"])
        .run();
    assert_eq!(run.code, 0, "{}", run.stderr);
    assert!(!run.stderr.contains("unknown shader"), "{}", run.stderr);
    let records = json_lines_of(&run.stdout);
    let mut decided = std::collections::BTreeMap::new();
    for r in records.iter().filter(|r| r["asset"]["texture"].is_string()) {
        let file = Path::new(r["asset"]["texture"].as_str().unwrap());
        let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
        let kind = r["asset"]["decision"]["kind"].as_str().unwrap().to_owned();
        for u in r["asset"]["uses"].as_array().unwrap() {
            assert!(
                u["input_type"].is_string() && u["defined_by"].is_string(),
                "{stem}: {u}"
            );
        }
        let rule = r["asset"]["rule"].as_str().unwrap().to_owned();
        decided.insert(stem, (kind, rule));
    }
    let kinds: std::collections::BTreeMap<String, String> = decided
        .iter()
        .map(|(k, (kind, _))| (k.clone(), kind.clone()))
        .collect();
    assert_eq!(kinds, roles, "{}", run.stderr);
    // The space a reader's own input declares (PxrTexture's linearize 1, Arnold's
    // color_space) is the material's.
    let declared: std::collections::BTreeMap<String, String> =
        serde_json::from_str(&std::fs::read_to_string(dir.path("declared.json")).unwrap()).unwrap();
    for (file, rule) in &declared {
        assert_eq!(&decided[file].1, rule, "{file}: {}", run.stderr);
    }
    let layer = dir.path("out/networks_spectral.usda");
    // With no choice made, every file input is the stage's own (checked in layer_files).
    let view = layer_files(&python, &layer);
    let files = view["files"].as_object().unwrap();
    assert_eq!(files.len(), 27, "{view:#}");
    // ch_base also feeds subsurface_radius (data): in the spectral network that input stays
    // connected to the original node, which reads the original file.
    let code = "import sys\nfrom pxr import Usd\ns = Usd.Stage.Open(sys.argv[1])\n\
                p = s.GetPrimAtPath('/Looks/Chess/Surface_spectral')\n\
                for n in ('base_color', 'subsurface_radius'):\n\
                \x20   print(n, p.GetAttribute('inputs:' + n).GetConnections()[0])\n";
    let got = std::process::Command::new(&python)
        .args(["-c", code, layer.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&got.stdout),
        "base_color /Looks/Chess/T_ch_base_spectral.outputs:out\n\
         subsurface_radius /Looks/Chess/T_ch_base.outputs:out\n",
        "{}",
        String::from_utf8_lossy(&got.stderr)
    );
    for (node, f) in files {
        let file = f["file"].as_str().unwrap();
        let stem = file.trim_start_matches("./tex/").trim_end_matches(".png");
        let stem = stem.trim_end_matches("_spectral.exr");
        match roles[stem].as_str() {
            "colour" => {
                assert_eq!(file, format!("./tex/{stem}_spectral.exr"), "{node}");
                assert!(f["copy"].is_string(), "{node}: {f}");
                // Read as written: the reader's own word for it, where it has one.
                let raw = &f["raw"];
                let id_raw = [("sourceColorSpace", "raw"), ("color_space", "Raw")];
                assert!(
                    raw.as_object().unwrap().is_empty()
                        || id_raw.iter().any(|(k, v)| raw[*k] == *v)
                        || raw["linearize"] == 0,
                    "{node}: {f}"
                );
            }
            _ => assert_eq!(file, format!("./tex/{stem}.png"), "{node}: {f}"),
        }
    }
}

/// Issue 56, item 5: `asset --layout compact` end to end: every colour texture a compact file
/// (its `specconvLayout`, read by oiiotool), the layer's spectral context pointing at them,
/// `-u` skipping them all and leaving the layer as it was; and a stage-level line of storage
/// (the bytes read and written), which the compact layout keeps below the spectral one's.
#[test]
fn the_compact_layout_works_end_to_end_with_a_storage_summary() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-compact");
    let shot = basic_shot(&dir);
    let storage = |run: &Output| -> (f64, f64) {
        let line = run
            .stderr
            .lines()
            .find(|l| l.starts_with("specconv: storage:"))
            .unwrap_or_else(|| panic!("no storage line: {}", run.stderr));
        // The exact figures: "(N bytes)".
        let bytes: Vec<f64> = line
            .split('(')
            .filter_map(|w| w.split(" bytes)").next()?.parse::<f64>().ok())
            .collect();
        (bytes[0], bytes[1])
    };
    let out = dir.path("compact");
    let run = asset(&python, &shot.join("shot.usda"), &out)
        .args(["--layout", "compact", "--json"])
        .ok();
    let records = run.json_lines();
    let written: Vec<&str> = records
        .iter()
        .filter(|r| r["status"] == "ok")
        .map(|r| r["output"].as_str().unwrap())
        .collect();
    assert!(written.len() >= 5, "{records:#?}");
    for o in &written {
        let info = tool("oiiotool", &["--info", "-v", o]);
        assert!(
            info.contains("specconvLayout: \"compact 2\""),
            "{o}: {info}"
        );
    }
    let v = layer_files(&python, &out.join("shot_spectral.usda"));
    let albedo = &v["files"]["/World/Rock/Looks/Rock/Albedo"];
    assert!(
        written.contains(&albedo["resolved"].as_str().unwrap()),
        "{v:#}"
    );
    let (_, compact_out) = storage(&run);
    let layer = std::fs::read(out.join("shot_spectral.usda")).unwrap();
    let again = asset(&python, &shot.join("shot.usda"), &out)
        .args(["--layout", "compact", "--json", "-u"])
        .ok();
    assert!(again
        .json_lines()
        .iter()
        .all(|r| r["status"] == "skipped" || r["status"] == "data"));
    assert_eq!(
        std::fs::read(out.join("shot_spectral.usda")).unwrap(),
        layer
    );
    let spectral = asset(&python, &shot.join("shot.usda"), &dir.path("spectral")).ok();
    let (read, spectral_out) = storage(&spectral);
    assert!(read > 0.0 && spectral_out > 0.0, "{}", spectral.stderr);
    eprintln!("read {read} bytes: spectral {spectral_out}, compact {compact_out}");
}

/// Issue 56, item 1: a MaterialX-in-USD material whose only terminal is
/// `outputs:mtlx:surface` gets its spectral terminal from that one: the render context
/// `spectral` reads the copy, and what RGB renderers read is unchanged (layer_files).
#[test]
fn a_material_with_only_a_render_context_terminal_gets_the_switch() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-mtlx-context");
    stage(&dir.0, "mtlx_context");
    let out = dir.path("out");
    asset(&python, &dir.path("mtlx_context.usda"), &out).ok();
    let v = layer_files(&python, &out.join("mtlx_context_spectral.usda"));
    assert_eq!(
        v["contexts"]["/Looks/M"], "/Looks/M/Surface_spectral",
        "{v:#}"
    );
    let image = &v["files"]["/Looks/M/Image"];
    assert_eq!(image["file"], "./tex/rock_albedo_spectral.exr", "{v:#}");
    assert_eq!(image["cs"], "raw", "{v:#}");
}

/// Issue 57, item 4: usdz members `escape.png` and `../escape.png` are two pictures; each is
/// copied out to its own file inside DIR (`..` escaped, not dropped), each with its own bytes,
/// converted to its own output, and each material's layer input names its own.
#[test]
fn two_usdz_members_that_differ_only_by_dots_stay_two_files() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-usdz-escape");
    stage(&dir.0, "escape_package");
    let out = dir.path("out");
    let records = asset(&python, &dir.path("escape.usdz"), &out)
        .arg("--json")
        .ok()
        .json_lines();
    assert_eq!(records.len(), 2, "{records:#?}");
    let inputs: Vec<PathBuf> = records
        .iter()
        .map(|r| PathBuf::from(r["input"].as_str().unwrap()))
        .collect();
    assert_ne!(inputs[0], inputs[1]);
    let copied = out.join("escape_usdz");
    for input in &inputs {
        assert!(input.starts_with(&copied), "{}", input.display());
    }
    // Each copy holds the bytes of the member it names: the two sources differ.
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    let mine = |name: &str| bytes(&dir.path(&format!("tex/{name}.png")));
    let copies: Vec<Vec<u8>> = inputs.iter().map(|p| bytes(p)).collect();
    assert_ne!(mine("rock_albedo"), mine("rock_normal"));
    let mut want = vec![mine("rock_albedo"), mine("rock_normal")];
    let mut got = copies.clone();
    want.sort();
    got.sort();
    assert_eq!(got, want);
    let v = layer_files(&python, &out.join("escape_spectral.usda"));
    let resolved = |p: &str| v["files"][p]["resolved"].as_str().unwrap().to_string();
    let (a, b) = (resolved("/Looks/In/Albedo"), resolved("/Looks/Up/Albedo"));
    assert_ne!(a, b);
    for r in [&a, &b] {
        assert!(Path::new(r).starts_with(&out), "{r}");
        assert!(Path::new(r).is_file(), "{r}");
    }
}

/// Issue 57, item 3: a usdz's copy-outs follow the output rules: a user's file of the same
/// name under `DIR/STEM_usdz/` is kept (exit 2, -u or --force); the asset's own copy is
/// replaced when the package's member changed.
#[test]
fn a_usdz_copy_out_never_replaces_a_file_the_asset_did_not_write() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-usdz-own");
    stage(&dir.0, "package");
    // Where usd-core's packaging puts the member, as a first run copies it out.
    let first = dir.path("first");
    asset(&python, &dir.path("packed.usdz"), &first).ok();
    let (copy, _) = tree(&first)
        .into_iter()
        .find(|(p, _)| p.ends_with("rock_albedo.png"))
        .expect("a copy-out");
    let out = dir.path("out");
    let theirs = out.join(copy.strip_prefix(&first).unwrap());
    std::fs::create_dir_all(theirs.parent().unwrap()).unwrap();
    std::fs::write(&theirs, b"a user's picture").unwrap();
    for flags in [&[][..], &["-u"], &["--force"]] {
        asset(&python, &dir.path("packed.usdz"), &out)
            .args(flags)
            .fails(2, &["rock_albedo.png", "did not write it"]);
        assert_eq!(std::fs::read(&theirs).unwrap(), b"a user's picture");
    }
    // Moved away: copied out, converted, and the next -u run keeps its own copy.
    std::fs::remove_file(&theirs).unwrap();
    asset(&python, &dir.path("packed.usdz"), &out).ok();
    let copied = std::fs::read(&theirs).unwrap();
    asset(&python, &dir.path("packed.usdz"), &out)
        .arg("-u")
        .ok();
    assert_eq!(std::fs::read(&theirs).unwrap(), copied);
}

#[test]
fn hostile_texture_paths_fail_cleanly_inside_dir() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-hostile");
    stage(&dir.0, "hostile");
    let fifo = dir.path("tex/fifo.png");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let out = dir.path("out");
    let run = asset(&python, &dir.path("hostile.usda"), &out)
        .arg("--json")
        .run_within(Duration::from_secs(120));
    assert_eq!(run.code, 1, "{}", &run.stderr);
    let records = json_lines_of(&run.stdout);
    // The FIFO and /dev/zero are refused by kind, never opened; `..` out of the folder lands
    // under DIR/external.
    for r in &records {
        if let Some(o) = r["output"].as_str().filter(|o| !o.is_empty()) {
            assert!(Path::new(o).starts_with(&out), "{o}");
        }
    }
    assert_eq!(record(&records, "fifo.png")["status"], "failed");
    assert_eq!(record(&records, "zero")["status"], "failed");
    for (p, _) in tree(&out) {
        assert!(p.starts_with(&out));
    }
    // The stage itself a FIFO: refused before usd-core could block on it.
    let stage_fifo = dir.path("stage.usda");
    std::process::Command::new("mkfifo")
        .arg(&stage_fifo)
        .status()
        .unwrap();
    asset(&python, &stage_fifo, &out).fails(2, &["not a regular file"]);
    // A folder below DIR that is a link elsewhere (left there, or planted): refused before
    // anything is written through it.
    let (linked, away) = (dir.path("linked"), dir.path("away"));
    std::fs::create_dir_all(&linked).unwrap();
    std::fs::create_dir_all(&away).unwrap();
    std::os::unix::fs::symlink(&away, linked.join("tex")).unwrap();
    asset(&python, &dir.path("hostile.usda"), &linked).fails(2, &["symbolic link", "tex"]);
    assert_eq!(
        std::fs::read_dir(&away).unwrap().count(),
        0,
        "nothing through the link"
    );
}

/// The roles a fixture script wrote (`{file stem: role}`, in `dir`), each file made as
/// `dir/tex/STEM.png` by oiiotool.
pub(crate) fn roles_with_textures(
    dir: &Scratch,
    json_name: &str,
) -> std::collections::BTreeMap<String, String> {
    let roles: std::collections::BTreeMap<String, String> =
        serde_json::from_str(&std::fs::read_to_string(dir.path(json_name)).unwrap()).unwrap();
    std::fs::create_dir_all(dir.path("tex")).unwrap();
    for name in roles.keys() {
        let p = dir.path(&format!("tex/{name}.png"));
        tool(
            "oiiotool",
            &[
                "--pattern",
                "checker",
                "8x8",
                "4",
                "-d",
                "uint8",
                "-o",
                p.to_str().unwrap(),
            ],
        );
    }
    roles
}

fn json_lines_of(text: &str) -> Vec<Value> {
    text.lines().map(|l| json(l)).collect()
}

#[test]
fn ten_thousand_prims_are_read_in_bounded_time() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-many");
    stage(&dir.0, "many");
    let run = asset(&python, &dir.path("many.usda"), &dir.path("out"))
        .args(["--dry-run", "--json"])
        .run_within(Duration::from_secs(300));
    assert!(run.code == 0, "{}", &run.stderr);
    let decisions = json_lines_of(&run.stdout);
    assert_eq!(decisions.len(), 1);
    assert_eq!(decisions[0]["uses"].as_array().unwrap().len(), 1);
}

#[test]
fn without_usd_core_the_error_says_what_to_install() {
    let dir = Scratch::new("asset-nousd");
    let stage = dir.write("s.usda", "#usda 1.0\n");
    // An interpreter with no site-packages at all: no pxr.
    let wrapper = dir.write("python", "#!/bin/sh\nexec python3 -I -S \"$@\"\n");
    std::process::Command::new("chmod")
        .arg("+x")
        .arg(&wrapper)
        .status()
        .unwrap();
    Cmd::new([
        "asset",
        stage.to_str().unwrap(),
        "-o",
        dir.path("out").to_str().unwrap(),
    ])
    .env("SPECCONV_USD_PYTHON", &wrapper)
    .fails(1, &["has no usd-core", "-m pip install usd-core"]);
    Cmd::new([
        "asset",
        stage.to_str().unwrap(),
        "-o",
        dir.path("out").to_str().unwrap(),
    ])
    .env("SPECCONV_USD_PYTHON", dir.path("no-such-python"))
    .fails(
        1,
        &["cannot run the Python interpreter", "pip install usd-core"],
    );
    Cmd::new([
        "asset",
        stage.to_str().unwrap(),
        "-o",
        "x",
        "--colorspace",
        "ACEScg",
    ])
    .fails(2, &["asset takes no --colorspace"]);
}

#[test]
fn data_textures_follow_the_data_policy_and_colour_ones_convert() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-data");
    stage(&dir.0, "mixed");
    let mixed = dir.path("mixed.usda");
    // With --data fail the data texture is a failure, and the colour one is converted.
    let run = asset(&python, &mixed, &dir.path("out"))
        .args(["--json", "--data", "fail"])
        .run();
    assert_eq!(run.code, 1, "{}", run.stderr);
    let r = json_lines_of(&run.stdout);
    assert_eq!(record(&r, "rock_arm.png")["status"], "failed");
    let error = record(&r, "rock_arm.png")["error"]
        .as_str()
        .unwrap()
        .to_owned();
    assert!(error.contains("data policy fail"), "{error}");
    assert_eq!(record(&r, "rock_albedo.png")["status"], "ok");
    // With --data copy it is written through, tagged data, and not pointed at by the layer.
    let out = dir.path("out2");
    let r = asset(&python, &mixed, &out)
        .args(["--json", "--data", "copy"])
        .ok()
        .json_lines();
    assert_eq!(record(&r, "rock_arm.png")["status"], "copied");
    // Named as data, as `convert -o DIR` names a data copy.
    assert!(record(&r, "rock_arm.png")["output"]
        .as_str()
        .unwrap()
        .ends_with("tex/rock_arm_data.exr"));
    assert!(out.join("tex/rock_arm_data.exr").is_file());
    let v = layer_files(&python, &out.join("mixed_spectral.usda"));
    assert_eq!(v["files"]["/Looks/M/Arm"]["file"], "./tex/rock_arm.png");
    assert_eq!(
        v["files"]["/Looks/M/Albedo"]["file"],
        "./tex/rock_albedo_spectral.exr"
    );
}

/// Slurm's commands as a cluster that took the job and then forgot it: `sbatch` prints a job
/// id, `scontrol` and `sacct` know none, so states come from the tasks' own end events.
/// Returns a PATH with them first.
fn forgetful_slurm(dir: &Scratch) -> String {
    use std::os::unix::fs::PermissionsExt;
    let bin = dir.path("bin");
    std::fs::create_dir_all(&bin).unwrap();
    for (name, text) in [
        ("sbatch", "cat > /dev/null; echo 4242"),
        ("scontrol", "echo 'Invalid job id specified' >&2; exit 1"),
        ("sacct", "exit 1"),
    ] {
        let p = bin.join(name);
        std::fs::write(&p, format!("#!/bin/sh\n{text}\n")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let path = std::env::var("PATH").unwrap_or_default();
    format!("{}:{path}", bin.display())
}

/// `farm submit STAGE` into `out` with the job directory `job`, then every task of round 0 run
/// as Slurm runs it (the round's script, `$SLURM_ARRAY_TASK_ID`, standard output and error into
/// the task's log); returns the manifest.
fn farm_stage(python: &str, path: &str, stage: &Path, (out, job): (&Path, &Path)) -> Value {
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    Cmd::new(["farm", "submit", &s(stage), "-o", &s(out), "--tasks", "2"])
        .args(["--job-dir", &s(job), "--json"])
        .env("PATH", path)
        .env("SPECCONV_USD_PYTHON", python)
        .ok();
    let manifest = json(&std::fs::read_to_string(job.join("manifest.json")).unwrap());
    let round = job.join("round-0");
    for t in 0..manifest["rounds"][0]["tasks"].as_array().unwrap().len() {
        let log = |ext: &str| std::fs::File::create(round.join(format!("task-{t}.{ext}"))).unwrap();
        let status = std::process::Command::new("bash")
            .arg(round.join("job.sbatch"))
            .env("SLURM_ARRAY_TASK_ID", t.to_string())
            .env("PATH", path)
            .env_remove("SPECCONV_USD_PYTHON")
            .current_dir(manifest["workdir"].as_str().unwrap())
            .stdout(log("jsonl"))
            .stderr(log("err"))
            .status()
            .unwrap();
        assert!(
            status.success(),
            "task {t}: {}",
            std::fs::read_to_string(round.join(format!("task-{t}.err"))).unwrap()
        );
    }
    manifest
}

/// The files of `dir` but the farm's marker, as (path below `dir`, bytes).
fn contents(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    tree(dir)
        .into_iter()
        // The farm's folder, and the asset's record (it holds the files' times).
        .filter(|(p, _)| !KEPT.iter().any(|k| p.ends_with(k)))
        .map(|(p, _)| {
            (
                p.strip_prefix(dir).unwrap().to_path_buf(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect()
}

/// `farm submit STAGE`: each texture decided once, at submit, by the asset's rule and carried
/// in the manifest, so the tasks (no usd-core on them) convert every texture as `asset` does,
/// byte for byte, and `collect` writes the same layer. An edited manifest and a stage changed
/// between submit and run never get a layer.
#[test]
fn a_stage_on_the_farm_converts_every_texture_as_asset_does() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-farm");
    let shot = basic_shot(&dir);
    let stage = shot.join("shot.usda");
    let local = dir.path("local");
    asset(&python, &stage, &local).ok();
    let path = forgetful_slurm(&dir);
    let (out, job) = (dir.path("farm"), dir.path("job"));
    let m = farm_stage(&python, &path, &stage, (&out, &job));
    // The decisions travel with the files: the material's spaces, the data space for data.
    let space = |name: &str| {
        m["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["input"].as_str().unwrap().ends_with(name))
            .unwrap_or_else(|| panic!("{name}: {m:#}"))["colorspace"]
            .clone()
    };
    assert_eq!(space("rock_albedo.png"), "sRGB - Texture");
    assert_eq!(space("wood_acescg.exr"), "ACEScg");
    assert_eq!(space("wood.1002.png"), "sRGB - Texture");
    assert!(
        space("dirty_albedo.png").is_null(),
        "the file decides its space"
    );
    assert_eq!(space("rock_arm.png"), "Raw");
    assert_eq!(m["asset"]["stage"], stage.to_str().unwrap());
    let collect = |path: &str| {
        Cmd::new(["farm", "collect", job.to_str().unwrap()])
            .env("PATH", path)
            .env("SPECCONV_USD_PYTHON", &python)
            .run()
    };
    let c = collect(&path);
    assert_eq!(c.code, 0, "{}\n{}", c.stdout, c.stderr);
    assert!(c.stdout.contains("8 files: 8 done"), "{}", c.stdout);
    assert!(
        c.stderr.contains("5 texture node(s) given spectral files"),
        "{}",
        c.stderr
    );
    // The same files, byte for byte, the layer too.
    let (a, f) = (contents(&local), contents(&out));
    let names = |v: &[(PathBuf, Vec<u8>)]| v.iter().map(|(p, _)| p.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&f));
    for ((name, x), (_, y)) in a.iter().zip(&f) {
        assert!(
            x == y,
            "{} differs between asset and the farm",
            name.display()
        );
    }

    // A manifest edited to give a texture another colour space: the tasks would convert it so,
    // but no layer is written over it.
    let text = std::fs::read_to_string(job.join("manifest.json")).unwrap();
    let edited = text.replacen("\"sRGB - Texture\"", "\"ACEScg\"", 1);
    assert_ne!(edited, text);
    std::fs::write(job.join("manifest.json"), &edited).unwrap();
    let layer = out.join("shot_spectral.usda");
    std::fs::remove_file(&layer).unwrap();
    let c = collect(&path);
    assert_eq!(c.code, 1, "{}\n{}", c.stdout, c.stderr);
    assert!(
        c.stderr.contains("is not written") && c.stderr.contains("manifest was edited"),
        "{}",
        c.stderr
    );
    assert!(!layer.exists());
    // One edited to point a texture's output out of DIR: refused whole, exit status 2.
    let away = text.replacen(
        out.join("tex/").to_str().unwrap(),
        &format!("{}/../../", out.join("tex").display()),
        1,
    );
    assert_ne!(away, text);
    std::fs::write(job.join("manifest.json"), &away).unwrap();
    let c = collect(&path);
    assert_eq!(c.code, 2, "{}\n{}", c.stdout, c.stderr);
    assert!(
        c.stderr.contains("output tree") && c.stderr.contains("edited or damaged"),
        "{}",
        c.stderr
    );

    // The stage changed between submit and run (the albedo now says raw): the tasks convert as
    // decided at submit, and collect finds the stage plans otherwise and writes no layer.
    let (out2, job2) = (dir.path("farm2"), dir.path("job2"));
    let asset_layer = shot.join("asset.usda");
    let before = std::fs::read_to_string(&asset_layer).unwrap();
    let changed = before.replacen("\"sRGB\"", "\"raw\"", 1);
    assert_ne!(changed, before);
    Cmd::new([
        "farm",
        "submit",
        stage.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
        "--tasks",
        "1",
        "--dry-run",
    ])
    .env("PATH", &path)
    .env("SPECCONV_USD_PYTHON", &python)
    .ok();
    let submitted = {
        let s = |p: &Path| p.to_str().unwrap().to_owned();
        Cmd::new([
            "farm",
            "submit",
            &s(&stage),
            "-o",
            &s(&out2),
            "--tasks",
            "1",
        ])
        .args(["--job-dir", &s(&job2)])
        .env("PATH", &path)
        .env("SPECCONV_USD_PYTHON", &python)
        .ok()
    };
    assert!(
        submitted.stdout.contains("submitted job 4242"),
        "{}",
        submitted.stdout
    );
    std::fs::write(&asset_layer, changed).unwrap();
    let round = job2.join("round-0");
    let status = std::process::Command::new("bash")
        .arg(round.join("job.sbatch"))
        .env("SLURM_ARRAY_TASK_ID", "0")
        .env("PATH", &path)
        .stdout(std::fs::File::create(round.join("task-0.jsonl")).unwrap())
        .status()
        .unwrap();
    assert!(status.success());
    let c = Cmd::new(["farm", "collect", job2.to_str().unwrap()])
        .env("PATH", &path)
        .env("SPECCONV_USD_PYTHON", &python)
        .run();
    assert_eq!(c.code, 1, "{}\n{}", c.stdout, c.stderr);
    assert!(
        c.stderr.contains("no longer plans") || c.stderr.contains("now plans"),
        "{}",
        c.stderr
    );
    assert!(!out2.join("shot_spectral.usda").exists());
    std::fs::write(&asset_layer, before).unwrap();

    // A stage is submitted alone, into -o DIR.
    let s = stage.to_str().unwrap();
    Cmd::new(["farm", "submit", s, s, "-o", "x", "--tasks", "1"]).fails(2, &["submitted alone"]);
    Cmd::new([
        "farm",
        "submit",
        s,
        "--output-template",
        "{stem}.exr",
        "--job-dir",
        "j",
        "--tasks",
        "1",
    ])
    .env("SPECCONV_USD_PYTHON", &python)
    .fails(2, &["give -o DIR"]);
}

/// A grey texture its material calls colour without naming a space is uplifted as grey in the
/// space the file's evidence gives (the material outranks the data-map rule); a grey one that
/// feeds roughness stays data. The temporary layer a killed run left is removed by the next.
#[test]
fn a_grey_texture_the_material_calls_colour_is_uplifted_and_a_dead_runs_layer_temporary_goes() {
    let Some(python) = usd() else { return };
    let dir = Scratch::new("asset-grey");
    stage(&dir.0, "grey");
    for name in ["grey_albedo", "grey_rough"] {
        let p = dir.path(&format!("tex/{name}.png"));
        tool(
            "oiiotool",
            &[
                "--pattern",
                "noise",
                "8x8",
                "1",
                "-d",
                "uint8",
                "-o",
                p.to_str().unwrap(),
            ],
        );
    }
    let out = dir.path("out");
    std::fs::create_dir_all(&out).unwrap();
    let stale = out.join(".grey_spectral.usda.specconv-0123456789abcdef.tmp");
    std::fs::write(&stale, "half a layer").unwrap();
    let r = asset(&python, &dir.path("grey.usda"), &out)
        .arg("--json")
        .ok()
        .json_lines();
    let albedo = record(&r, "grey_albedo.png");
    assert_eq!(albedo["status"], "ok", "{albedo:#}");
    assert_eq!(albedo["colorspace"], "sRGB - Texture");
    assert_eq!(albedo["asset"]["rule"], "colour-input");
    assert!(albedo["asset"]["why"]
        .as_str()
        .unwrap()
        .contains("uplifted as grey"));
    // `convert` alone takes it as data, by the data-map rule: the material made the difference.
    let alone = Cmd::convert(dir.path("tex/grey_albedo.png"), dir.path("alone.exr"))
        .arg("--json")
        .ok()
        .json();
    assert_eq!(alone["status"], "data");
    assert_eq!(record(&r, "grey_rough.png")["status"], "data");
    assert!(
        !stale.exists(),
        "the dead run's temporary layer is still there"
    );
    let v = layer_files(&python, &out.join("grey_spectral.usda"));
    assert_eq!(
        v["files"]["/Looks/G/Albedo"]["file"],
        "./tex/grey_albedo_spectral.exr"
    );
    // Three channels of which `--channels R` reads one: the rule sees what the conversion
    // reads (it looked at the whole file before, and the albedo came out as data).
    for name in ["grey_albedo", "grey_rough"] {
        let p = dir.path(&format!("tex/{name}.png"));
        let p = p.to_str().unwrap();
        tool(
            "oiiotool",
            &["--pattern", "noise", "8x8", "3", "-d", "uint8", "-o", p],
        );
    }
    let one = dir.path("one");
    let r = asset(&python, &dir.path("grey.usda"), &one)
        .args(["--json", "--channels", "R"])
        .ok()
        .json_lines();
    let albedo = record(&r, "grey_albedo.png");
    assert_eq!(albedo["status"], "ok", "{albedo:#}");
    assert_eq!(albedo["channels"], serde_json::json!(["R"]), "{albedo:#}");
    assert!(albedo["asset"]["why"]
        .as_str()
        .unwrap()
        .contains("uplifted as grey"));
    assert_eq!(record(&r, "grey_rough.png")["status"], "data");
}
