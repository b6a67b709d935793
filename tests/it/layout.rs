//! File structure kept or chosen from input to output: data and display windows on every MIP
//! level, subimages (parts) and layered channels; and damaged files refused before any output.
//! Checked with OpenEXR's exrheader and OpenImageIO (tests/oiio_levels.py): the output has the
//! input's windows, and its pixels sit where those of the same image without a window do.

use crate::runner::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn layout(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/layout")
        .join(name)
}

fn broken(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/broken")
        .join(name)
}

/// tests/oiio_levels.py with `args`; its JSON output, if any.
fn oiio_levels(args: &[&Path]) -> Value {
    serde_json::from_slice(&script("oiio_levels.py", args)).unwrap_or(Value::Null)
}

fn describe(path: &Path) -> Vec<Value> {
    oiio_levels(&[Path::new("describe"), path])
        .as_array()
        .unwrap()
        .clone()
}

/// exrheader's dataWindow and displayWindow lines.
fn exr_windows(path: &Path) -> Vec<String> {
    tool("exrheader", &[path.to_str().unwrap()])
        .lines()
        .filter(|l| l.starts_with("dataWindow") || l.starts_with("displayWindow"))
        .map(str::to_owned)
        .collect()
}

fn convert(input: &Path, output: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        input.to_str().unwrap(),
        output.to_str().unwrap(),
        "-d",
        "float",
        "--force",
    ];
    args.extend_from_slice(extra);
    Cmd::new(args).run()
}

#[test]
fn data_and_display_windows_are_kept_on_every_level() {
    let dir = Scratch::new("layout-windows");
    let mip = dir.path("window_mip.exr");
    oiio_levels(&[Path::new("mipmap"), &layout("window.exr"), &mip]);
    let inputs = [
        layout("window.exr"),
        layout("window_negative.exr"),
        mip.clone(),
    ];
    for input in &inputs {
        let name = input.file_name().unwrap().to_str().unwrap();
        let output = dir.path(&format!("out_{name}"));
        convert(input, &output, &[]).ok();
        // exrheader: the very windows of the input.
        let want = exr_windows(input);
        assert_eq!(want.len(), 2, "{want:?}");
        assert!(!want[0].contains("(0 0)"), "{name}: the input has a window");
        assert_eq!(exr_windows(&output), want, "{name}");

        // The same pixels without a window (origin 0, display = data).
        let plain = dir.path(&format!("plain_{name}"));
        let plain_out = dir.path(&format!("plain_out_{name}"));
        if input == &mip {
            let flat = dir.path("plain_flat.exr");
            tool(
                "oiiotool",
                &[
                    layout("window.exr").to_str().unwrap(),
                    "--origin",
                    "+0+0",
                    "--fullpixels",
                    "-o",
                    flat.to_str().unwrap(),
                ],
            );
            oiio_levels(&[Path::new("mipmap"), &flat, &plain]);
        } else {
            tool(
                "oiiotool",
                &[
                    input.to_str().unwrap(),
                    "--origin",
                    "+0+0",
                    "--fullpixels",
                    "-o",
                    plain.to_str().unwrap(),
                ],
            );
        }
        convert(&plain, &plain_out, &[]).ok();

        // OpenImageIO, level by level: every level of the MIP map made here has the input's
        // data-window origin (as OpenEXR's MIP maps do), the sizes halving (rounded down), and
        // the pixels of the windowless conversion.
        let (i, o, p) = (describe(input), describe(&output), describe(&plain_out));
        assert_eq!(o.len(), p.len());
        assert!(o.len() > 5, "{name}: MIP-mapped");
        let top = &i[0];
        for (k, (o, p)) in o.iter().zip(&p).enumerate() {
            let d = top["data"].as_array().unwrap();
            let size = |v: &serde_json::Value| (v.as_u64().unwrap() >> k).max(1);
            let want = serde_json::json!([d[0], d[1], size(&d[2]), size(&d[3])]);
            assert_eq!(o["data"], want, "{name} level {k}");
            // OpenImageIO reports a smaller level's display window as its data window.
            let display = if k == 0 { &top["display"] } else { &o["data"] };
            assert_eq!(&o["display"], display, "{name} level {k}");
            assert_eq!(o["sha1"], p["sha1"], "{name} level {k}");
        }
    }
}

#[test]
fn subimages_are_chosen_by_index_or_name_and_reported() {
    let dir = Scratch::new("layout-parts");
    let parts = layout("parts.exr");
    // Part 'albedo' on its own, as a reference.
    let albedo = dir.path("albedo.exr");
    tool(
        "oiiotool",
        &[
            parts.to_str().unwrap(),
            "--subimage",
            "albedo",
            "-o",
            albedo.to_str().unwrap(),
        ],
    );
    let want = dir.path("want.exr");
    convert(&albedo, &want, &[]).ok();
    let want = describe(&want)[0]["sha1"].clone();
    for which in ["1", "albedo"] {
        let out = dir.path(&format!("out_{which}.exr"));
        let run = convert(&parts, &out, &["--subimage", which, "--json"]);
        let report: Value = serde_json::from_str(run.ok().trim()).unwrap();
        assert_eq!(report["subimage"], 1);
        assert_eq!(report["channels"], serde_json::json!(["R", "G", "B"]));
        assert_eq!(describe(&out)[0]["sha1"], want, "--subimage {which}");
    }
    // Without the option: the first, said in the summary.
    let run = convert(&parts, &dir.path("first.exr"), &[]);
    run.ok();
    assert!(
        run.stderr
            .contains("subimage 0 'beauty' of 2, channels R,G,B"),
        "{}",
        run.stderr
    );
    convert(&parts, &dir.path("x.exr"), &["--subimage", "normals"])
        .fails(1, &["no subimage \"normals\"", "0 'beauty', 1 'albedo'"]);
    convert(&parts, &dir.path("x.exr"), &["--subimage", "2"]).fails(1, &["no subimage \"2\""]);
    assert!(!dir.path("x.exr").exists());

    let info = Cmd::new(["info", parts.to_str().unwrap(), "--subimage", "albedo"]).run();
    assert!(
        info.ok()
            .contains("subimages:    2 (0 'beauty', 1 'albedo'); reading 1"),
        "{}",
        info.stdout
    );
}

#[test]
fn layered_channels_are_chosen_by_layer_or_names_and_never_silently() {
    let dir = Scratch::new("layout-layers");
    let layers = layout("layers.exr");
    // diffuse.R/G/B as a plain RGB file, by oiiotool, as the reference.
    let rgb = dir.path("rgb.exr");
    tool(
        "oiiotool",
        &[
            layers.to_str().unwrap(),
            "--ch",
            "diffuse.R,diffuse.G,diffuse.B",
            "--chnames",
            "R,G,B",
            "-o",
            rgb.to_str().unwrap(),
        ],
    );
    let want = dir.path("want.exr");
    convert(&rgb, &want, &[]).ok();
    let want = describe(&want)[0]["sha1"].clone();
    let diffuse = serde_json::json!(["diffuse.R", "diffuse.G", "diffuse.B"]);
    for flags in [
        &["--channels", "diffuse"][..],
        &["--channels", "diffuse.R,diffuse.G,diffuse.B"],
        &[],
    ] {
        let out = dir.path("out.exr");
        let mut args = flags.to_vec();
        args.push("--json");
        let run = convert(&layers, &out, &args);
        let report: Value = serde_json::from_str(run.ok().trim()).unwrap();
        assert_eq!(report["channels"], diffuse, "{flags:?}");
        assert_eq!(describe(&out)[0]["sha1"], want, "{flags:?}");
    }
    // Chosen alone: said so in the summary and by info.
    let run = convert(&layers, &dir.path("out.exr"), &[]);
    assert!(
        run.stderr
            .contains("channels diffuse.R,diffuse.G,diffuse.B (the only RGB layer"),
        "{}",
        run.stderr
    );
    let info = Cmd::new(["info", layers.to_str().unwrap(), "--json"]).run();
    let v: Value = serde_json::from_str(info.ok()).unwrap();
    assert_eq!(v["colour_channels"], diffuse);
    assert_eq!(v["channels_rule"], "only-rgb-layer");

    // Grey from a layer: rough.Y repeated.
    let out = dir.path("rough.exr");
    let run = convert(&layers, &out, &["--channels", "rough", "--json"]);
    let report: Value = serde_json::from_str(run.ok().trim()).unwrap();
    assert_eq!(report["channels"], serde_json::json!(["rough.Y"]));

    // Two RGB layers: refused, naming them, with nothing written; info still describes it.
    let two = layout("two_layers.exr");
    let out = dir.path("two.exr");
    convert(&two, &out, &[]).fails(
        1,
        &[
            "several layers hold R, G and B (diffuse, specular)",
            "--channels LAYER",
        ],
    );
    assert!(!out.exists());
    let info = Cmd::new(["info", two.to_str().unwrap()]).run();
    assert!(
        info.ok().contains("read as:      nothing yet:"),
        "{}",
        info.stdout
    );
    convert(&two, &out, &["--channels", "specular"]).ok();
    convert(
        &two,
        &dir.path("x.exr"),
        &["--channels", "diffuse.R,diffuse.Q,diffuse.B"],
    )
    .fails(1, &["no channel 'diffuse.Q'", "layers diffuse, specular"]);
}

#[test]
fn damaged_files_fail_before_any_output_is_made() {
    let dir = Scratch::new("layout-damaged");
    for (name, needles) in [
        (
            "lying_window.exr",
            &[
                "chunk 0 of 60 is said to start at byte",
                "truncated or damaged",
            ][..],
        ),
        (
            "lying_tiles.exr",
            &[
                "262661×15105 pixels",
                "the header is damaged or the file truncated",
            ],
        ),
        ("truncated_pixels.exr", &["the file is truncated"]),
        ("garbled_first_block.exr", &["reading pixels failed"]),
        ("truncated.exr", &["truncated"]),
    ] {
        let input = dir.path(name);
        std::fs::copy(broken(name), &input).unwrap();
        let out = dir.path("out.exr");
        let run = convert(&input, &out, &["--json"]);
        assert_eq!(run.code, 1, "{name}: {}", run.stderr);
        let report: Value = serde_json::from_str(run.stdout.trim()).unwrap();
        let error = report["error"].as_str().unwrap();
        for n in needles {
            assert!(error.contains(n), "{name}: {error}");
        }
        assert_eq!(
            dir.files(),
            vec![name.to_string()],
            "{name}: nothing left behind"
        );
        std::fs::remove_file(&input).unwrap();
    }
}

/// The size check passes valid files of every compression and block kind OpenImageIO writes.
#[test]
fn valid_files_of_every_compression_pass_the_size_check() {
    let dir = Scratch::new("layout-compressions");
    for compression in [
        "none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab",
    ] {
        for tiles in [&[][..], &["--tile", "16", "16"]] {
            let input = dir.path("in.exr");
            let mut args = vec![
                "--pattern",
                "noise:min=0:max=1:seed=3",
                "70x40",
                "4",
                "-d",
                "half",
                "--compression",
                compression,
            ];
            args.extend_from_slice(tiles);
            args.extend_from_slice(&["-o", input.to_str().unwrap()]);
            tool("oiiotool", &args);
            convert(&input, &dir.path("out.exr"), &[]).ok();
        }
    }
}
