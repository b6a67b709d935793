//! PNG pictures: `report --plot FILE.png`, `simulate --image`, `preview`. Each is read back and
//! checked against what the command computed.

use crate::runner::*;
use std::collections::HashSet;
use std::path::Path;
use std::process::Command;

/// An 8-bit RGB picture read back from a PNG.
pub struct Picture {
    pub width: u32,
    pub height: u32,
    rgb: image::RgbImage,
}

impl Picture {
    pub fn read(path: &Path) -> Picture {
        let img = image::open(path)
            .unwrap_or_else(|e| panic!("{} is not a PNG: {e}", path.display()))
            .to_rgb8();
        Picture {
            width: img.width(),
            height: img.height(),
            rgb: img,
        }
    }

    pub fn at(&self, x: u32, y: u32) -> [u8; 3] {
        self.rgb.get_pixel(x, y).0
    }

    pub fn distinct_colours(&self) -> usize {
        self.rgb.pixels().map(|p| p.0).collect::<HashSet<_>>().len()
    }

    /// Pixels within `tol` of `c` in every channel.
    pub fn count_near(&self, c: [u8; 3], tol: u8) -> usize {
        self.rgb
            .pixels()
            .filter(|p| (0..3).all(|k| p.0[k].abs_diff(c[k]) <= tol))
            .count()
    }
}

#[test]
fn report_draws_its_plot_as_png() {
    let dir = Scratch::new("report-png");
    let plot = dir.path("cost.png");
    let cc = colorchecker();
    let out = Command::new(env!("CARGO_BIN_EXE_specconv"))
        .args(["report", "--spectra", cc.to_str().unwrap()])
        .args(["--clusters", "1,2", "--steps", "10", "--colours", "4096"])
        .args(["--jakob-resolution", "8", "-j", "1", "--json", "--plot"])
        .arg(&plot)
        .env("SPECCONV_CACHE_DIR", &dir.0)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pic = Picture::read(&plot);
    assert_eq!((pic.width, pic.height), (900, 600));
    // White ground, black axes and text, antialiased edges, and a point in each method's
    // colour: otsu2018 red (over pca: one cluster is the same point), meng2015 green,
    // jakob2019 blue.
    assert!(pic.distinct_colours() > 20, "{}", pic.distinct_colours());
    assert!(pic.count_near([255, 255, 255], 0) > 900 * 600 / 2);
    assert!(rows.as_array().unwrap().len() >= 6);
    for c in [[255, 0, 0], [0, 255, 0], [0, 0, 255]] {
        assert!(pic.count_near(c, 10) >= 20, "no point in {c:?}");
    }
    // Only what was asked is in the directory: the PNG and the jakob2019 table cache.
    assert!(
        dir.files().iter().all(|f| !f.contains(".tmp")),
        "{:?}",
        dir.files()
    );
}

fn scene(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

/// Every swatch of `--image` has the colour the --json report gives its cell.
fn swatches_match_the_report(v: &serde_json::Value, pic: &Picture) -> usize {
    let mut checked = 0;
    for s in v["image"]["swatches"].as_array().unwrap() {
        let patch = v["per_patch"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == s["patch"])
            .unwrap();
        let cell =
            &patch["colours"][s["method"].as_str().unwrap()][s["count"].as_u64().unwrap() as usize];
        let want: Vec<u8> = cell["srgb"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| (c.as_f64().unwrap() * 255.0).round() as u8)
            .collect();
        let at = |k: &str| s[k].as_u64().unwrap() as u32;
        // The centre and a corner: the swatch is filled flat.
        for (x, y) in [
            (at("x") + at("width") / 2, at("y") + at("height") / 2),
            (at("x") + 1, at("y") + 1),
        ] {
            assert_eq!(pic.at(x, y).to_vec(), want, "{s} {cell}");
        }
        checked += 1;
    }
    checked
}

#[test]
fn simulate_draws_one_block_per_patch_with_the_reports_colours() {
    shared("spectra/munsell1269_matte_380-800_1nm.csv");
    let dir = Scratch::new("simulate-image");
    let png = dir.path("box.png");
    let args = |extra: &[&str]| {
        let mut a = vec![
            "simulate".to_string(),
            "--scene".into(),
            scene("box_4000k_5500k.toml").display().to_string(),
            "--json".into(),
            "--image".into(),
            png.display().to_string(),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let v: serde_json::Value = serde_json::from_str(specconv(args(&[])).ok()).unwrap();
    let pic = Picture::read(&png);
    assert_eq!(
        (pic.width as u64, pic.height as u64),
        (
            v["image"]["width"].as_u64().unwrap(),
            v["image"]["height"].as_u64().unwrap()
        )
    );
    // 5 walls × (measured, 3 methods, rgb) × 9 counts, all as the report says.
    assert_eq!(swatches_match_the_report(&v, &pic), 5 * 5 * 9);
    // The red wall after 8 bounces is red in the picture, not only in the numbers.
    let s = v["image"]["swatches"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["patch"] == "left" && s["method"] == "measured" && s["count"] == 8)
        .unwrap();
    let [r, g, b] = pic.at(
        s["x"].as_u64().unwrap() as u32 + 5,
        s["y"].as_u64().unwrap() as u32 + 5,
    );
    assert!(r > 2 * g.max(b), "{r} {g} {b}");
    // Text: many more colours than the 225 swatches (antialiased glyphs, frames).
    assert!(pic.distinct_colours() > 300, "{}", pic.distinct_colours());

    // An existing picture is kept without --force; --patch chooses the blocks.
    specconv(args(&[])).fails(1, &["exists", "--force"]);
    let v: serde_json::Value =
        serde_json::from_str(specconv(args(&["--force", "--patch", "left"])).ok()).unwrap();
    assert_eq!(v["per_patch"].as_array().unwrap().len(), 1);
    assert_eq!(swatches_match_the_report(&v, &Picture::read(&png)), 5 * 9);
    specconv(args(&["--force", "--patch", "door"])).fails(1, &["no patch of that name", "floor"]);
    assert_eq!(dir.files(), ["box.png"]);
}

#[test]
fn simulate_image_refuses_what_it_cannot_draw() {
    shared("spectra/munsell1269_matte_380-800_1nm.csv");
    let dir = Scratch::new("simulate-image-bad");
    let furnace = scene("furnace_5500k.toml");
    let f = furnace.to_str().unwrap();
    let gif = dir.path("x.gif");
    specconv(["simulate", "--scene", f, "--image", gif.to_str().unwrap()])
        .fails(1, &["--image", "*.png"]);
    let png = dir.path("x.png");
    specconv(["simulate", "--scene", f, "--image", png.to_str().unwrap()])
        .fails(1, &["1269", "--patch"]);
    // A missing font is named, with the package and the variable.
    let out = Command::new(env!("CARGO_BIN_EXE_specconv"))
        .args(["simulate", "--scene", f, "--patch", "5R 4/14", "--image"])
        .arg(&png)
        .env("SPECCONV_FONT", dir.path("none.ttf"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("SPECCONV_FONT") && err.contains("none.ttf"),
        "{err}"
    );
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}
