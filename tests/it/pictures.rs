//! PNG pictures: `report --plot FILE.png`, `simulate --image`, `preview`. Each is read back and
//! checked against what the command computed.

use crate::runner::*;
use std::collections::HashSet;
use std::path::Path;

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
    let rows = Cmd::new(["report", "--spectra", cc.to_str().unwrap()])
        .args(["--clusters", "1,2", "--steps", "10", "--colours", "4096"])
        .args(["--jakob-resolution", "8", "-j", "1", "--json", "--plot"])
        .arg(&plot)
        .env("SPECCONV_CACHE_DIR", &dir.0)
        .ok()
        .json();
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
    let v: serde_json::Value = Cmd::new(args(&[])).ok().json();
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
    Cmd::new(args(&[])).fails(2, &["exists", "--force"]);
    let v: serde_json::Value = Cmd::new(args(&["--force", "--patch", "left"])).ok().json();
    assert_eq!(v["per_patch"].as_array().unwrap().len(), 1);
    assert_eq!(swatches_match_the_report(&v, &Picture::read(&png)), 5 * 9);
    Cmd::new(args(&["--force", "--patch", "door"])).fails(1, &["no patch of that name", "floor"]);
    assert_eq!(dir.files(), ["box.png"]);
}

#[test]
fn simulate_image_refuses_what_it_cannot_draw() {
    shared("spectra/munsell1269_matte_380-800_1nm.csv");
    let dir = Scratch::new("simulate-image-bad");
    let furnace = scene("furnace_5500k.toml");
    let f = furnace.to_str().unwrap();
    let gif = dir.path("x.gif");
    Cmd::new(["simulate", "--scene", f, "--image", gif.to_str().unwrap()])
        .fails(2, &["--image", "*.png"]);
    let png = dir.path("x.png");
    Cmd::new(["simulate", "--scene", f, "--image", png.to_str().unwrap()])
        .fails(1, &["1269", "--patch"]);
    // A missing font is named, with the package and the variable.
    let out = Cmd::new(["simulate", "--scene", f, "--patch", "5R 4/14", "--image"])
        .arg(&png)
        .env("SPECCONV_FONT", dir.path("none.ttf"))
        .run();
    let err = &out.stderr;
    assert_eq!(out.code, 1, "{err}");
    assert!(
        err.contains("SPECCONV_FONT") && err.contains("none.ttf"),
        "{err}"
    );
    assert!(dir.files().is_empty(), "{:?}", dir.files());
}

/// A float RGB OpenEXR (scene-linear) of the given pixels, one row.
fn linear_exr(dir: &Scratch, name: &str, pixels: &[[f32; 3]]) -> std::path::PathBuf {
    let p = dir.path(name);
    exr::prelude::write_rgb_file(&p, pixels.len(), 1, |x, _| {
        let [r, g, b] = pixels[x];
        (r, g, b)
    })
    .unwrap();
    p
}

/// Converts `input` to a spectral EXR beside it.
fn spectral(dir: &Scratch, input: &Path, name: &str) -> std::path::PathBuf {
    let out = dir.path(name);
    Cmd::convert(input, &out)
        .args(["--quiet", "-d", "float"])
        .ok();
    out
}

fn preview(args: &[&str]) -> serde_json::Value {
    let mut a = vec!["preview", "--json"];
    a.extend_from_slice(args);
    Cmd::new(a).ok().json()
}

#[test]
fn preview_at_zero_bounces_is_what_to_rgb_gives() {
    let dir = Scratch::new("preview-k0");
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images/srgb8.png");
    let exr = spectral(&dir, &input, "ramp.exr");
    let e = exr.to_str().unwrap();
    let rgb = dir.path("rgb.exr");
    Cmd::new([
        "to-rgb",
        e,
        rgb.to_str().unwrap(),
        "--colorspace",
        "Linear Rec.709 (sRGB)",
    ])
    .ok();
    let png = dir.path("k0.png");
    let v = preview(&[e, "-o", png.to_str().unwrap()]);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(61), Some(47))
    );
    let pic = Picture::read(&png);
    assert_eq!((pic.width, pic.height), (61, 47));
    let reference = exr::prelude::read_first_rgba_layer_from_file(
        &rgb,
        |res, _| vec![[0f32; 3]; res.width() * res.height()],
        |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * 61 + pos.x()] = [r, g, b];
        },
    )
    .unwrap()
    .layer_data
    .channel_data
    .pixels;
    let encode = |v: f32| {
        let v = f64::from(v).clamp(0.0, 1.0);
        let e = if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round() as i32
    };
    let mut worst = 0;
    for y in 0..47 {
        for x in 0..61 {
            let want = reference[y * 61 + x].map(encode);
            let got = pic.at(x as u32, y as u32).map(i32::from);
            worst = worst.max((0..3).map(|k| (want[k] - got[k]).abs()).max().unwrap());
        }
    }
    // OCIO's XYZ → Rec.709 matrix and ours agree to 1e-4: at most one code value apart.
    assert!(worst <= 1, "{worst}");
    assert!(pic.distinct_colours() > 100);
}

#[test]
fn preview_bounces_darken_and_saturate_and_diff_rgb_measures_the_drift() {
    let dir = Scratch::new("preview-k");
    let grey = spectral(
        &dir,
        &linear_exr(&dir, "grey.exr", &[[0.3; 3]; 4]),
        "grey_s.exr",
    );
    let red = spectral(
        &dir,
        &linear_exr(&dir, "red.exr", &[[0.25, 0.06, 0.04], [0.5, 0.1, 0.1]]),
        "red_s.exr",
    );
    let decode = |c: u8| {
        let v = f64::from(c) / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    let look = |k: &str| {
        let png = dir.path(&format!("red{k}.png"));
        preview(&[
            red.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--bounces",
            k,
        ]);
        Picture::read(&png).at(0, 0).map(decode)
    };
    let saturation = |c: [f64; 3]| {
        let (lo, hi) = (
            c.iter().copied().fold(1.0, f64::min),
            c.iter().copied().fold(0.0, f64::max),
        );
        (hi - lo) / hi
    };
    let luminance = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let (k0, k2) = (look("0"), look("2"));
    assert!(luminance(k2) < 0.8 * luminance(k0), "{k0:?} {k2:?}");
    assert!(k0.iter().all(|&c| c > 0.0 && c < 1.0), "unclipped: {k0:?}");
    assert!(saturation(k2) > saturation(k0), "{k0:?} {k2:?}");

    let diff = |file: &Path, name: &str| {
        let png = dir.path(name);
        let v = preview(&[
            file.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--bounces",
            "3",
            "--diff-rgb",
        ]);
        let pic = Picture::read(&png);
        // The image and its colour bar.
        assert!(pic.width > 100 && pic.height >= 200);
        (
            v["delta_e_max"].as_f64().unwrap(),
            v["delta_e_mean"].as_f64().unwrap(),
            pic,
        )
    };
    let (grey_max, _, grey_pic) = diff(&grey, "grey_d.png");
    let (red_max, red_mean, red_pic) = diff(&red, "red_d.png");
    assert!(grey_max < 0.1, "{grey_max}");
    assert!(red_max > 1.0 && red_mean > 1.0, "{red_max} {red_mean}");
    // The map: a grey is black (no difference), the red is not.
    assert!(
        grey_pic.at(0, 0).iter().all(|&c| c < 40),
        "{:?}",
        grey_pic.at(0, 0)
    );
    assert!(red_pic.at(0, 0)[0] > 100, "{:?}", red_pic.at(0, 0));
    // Under another light a grey stays grey for the RGB renderer too.
    let png = dir.path("grey_a.png");
    let v = preview(&[
        grey.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--bounces",
        "3",
        "--diff-rgb",
        "--illuminant",
        "A",
    ]);
    // Not zero: the uplifted grey is a metamer, not a flat spectrum, and its bumps grow with
    // every bounce under A (0.59 with the default blend). Raising the light's colour to K+1
    // as well would turn the grey orange, many units of ΔE away.
    assert!(v["delta_e_max"].as_f64().unwrap() < 1.0, "{v}");
}

#[test]
fn preview_refuses_what_it_cannot_show() {
    let dir = Scratch::new("preview-bad");
    let rgb_exr = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images/half_scanline.exr");
    let out = dir.path("x.png");
    let o = out.to_str().unwrap();
    Cmd::new(["preview", rgb_exr.to_str().unwrap(), "-o", o]).fails(1, &["not a spectral EXR"]);
    let grey = spectral(
        &dir,
        &linear_exr(&dir, "grey.exr", &[[0.3; 3]]),
        "grey_s.exr",
    );
    let g = grey.to_str().unwrap();
    for k in ["101", "-1", "two"] {
        Cmd::new(["preview", g, "-o", o, "--bounces", k]).fails(2, &[k]);
    }
    Cmd::new(["preview", g, "-o", dir.path("x.jpg").to_str().unwrap()]).fails(2, &["*.png"]);
    Cmd::new(["preview", g, "-o", o]).ok();
    Cmd::new(["preview", g, "-o", o, "--bounces", "1"]).fails(2, &["exists", "--force"]);
    Cmd::new(["preview", g, "-o", g, "--force"]).fails(2, &["*.png"]);
    assert_eq!(dir.files(), ["grey.exr", "grey_s.exr", "x.png"]);
}
