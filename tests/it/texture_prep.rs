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
        constant(&dir.path(&format!("wood.{n}.png")), 16, rgb, &["-d", "uint8"]);
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
    Cmd::convert(format!("{d}/wood.<UDIM>.png"), format!("{d}/out.<UDIM>.exr")).ok();
    for n in [1001, 1002, 1011] {
        assert!(dir.path(&format!("out.{n}.exr")).is_file());
    }
    // `-o DIR` keeps each tile's number in its name, so tiles never share an output.
    let o = dir.path("o");
    std::fs::create_dir(&o).unwrap();
    Cmd::new([format!("{d}/wood.<UDIM>.png")]).arg("-o").arg(&o).ok();
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
        .refused(&dir, 2, &["unknown field {stme}", "{dir}, {stem}, {name}, {udim}, {tile}"]);
    Cmd::new([format!("{d}/wood.1001.png").as_str()])
        .args(["--output-template", &format!("{d}/{{stem.exr")])
        .refused(&dir, 2, &["no '}' closes"]);
    // A pattern with no tiles (a typo in the name).
    Cmd::new([format!("{d}/wod.<UDIM>.png").as_str()])
        .args(["-o", &d])
        .refused(&dir, 2, &["no UDIM tile matches", "wod.<UDIM>.png"]);
    // A pattern into one output without the token would write every tile over one file.
    Cmd::convert(format!("{d}/wood.<UDIM>.png"), format!("{d}/wood.exr"))
        .refused(&dir, 2, &["UDIM pattern (3 tiles)", "wood.<UDIM>.exr"]);
    // {udim} for an input with no tile number.
    constant(&dir.path("plain.png"), 8, "0.5,0.5,0.5", &["-d", "uint8"]);
    Cmd::new([format!("{d}/plain.png").as_str()])
        .args(["--output-template", &format!("{d}/{{stem}}.{{udim}}.exr")])
        .refused(&dir, 2, &["plain.png has no tile number"]);
    // A template without the tile that sends every tile to one name.
    Cmd::new([format!("{d}/wood.<UDIM>.png").as_str()])
        .args(["--output-template", &format!("{d}/all.exr")])
        .refused(&dir, 2, &["which two inputs would write"]);
}
