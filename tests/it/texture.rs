//! Texture prep (docs/guide.md, "Textures"): MIP maps made from the spectra, checked against
//! maketx and OpenImageIO's TextureSystem; wrap modes and texture attributes as maketx writes
//! them; NaN refused or repaired as OpenImageIO repairs them; constant and opaque textures;
//! `-u` by the hash of the source pixels.

use crate::runner::*;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// oiiotool's `--info -v` of a file.
fn info(p: &Path) -> String {
    tool("oiiotool", &["--info", "-v", s(p)])
}

/// The `MIP-map levels:` line oiiotool prints.
fn levels_line(p: &Path) -> String {
    info(p)
        .lines()
        .find(|l| l.contains("MIP-map levels"))
        .map(|l| l.trim().to_string())
        .unwrap_or_default()
}

/// The largest difference oiiotool's --diff reports between level `level` of two files.
fn max_difference(a: &Path, b: &Path, level: usize) -> f64 {
    let out = std::process::Command::new("oiiotool")
        .args([s(a), "--selectmip", &level.to_string(), s(b)])
        .args(["--selectmip", &level.to_string(), "--diff"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if text.contains("PASS") && !text.contains("Max error") {
        return 0.0;
    }
    let line = text
        .lines()
        .find(|l| l.contains("Max error"))
        .unwrap_or_else(|| panic!("no difference reported:\n{text}"));
    line.split('=')
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// A smooth linear float image of `w × h` in (0.1, 0.7): colours a reflectance has.
fn linear_image(path: &Path, w: usize, h: usize) {
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:type=uniform:min=0.1:max=0.7",
            &format!("{w}x{h}"),
            "3",
            "--blur",
            "3x3",
            "-d",
            "float",
            "-o",
            s(path),
        ],
    );
}

#[test]
fn mip_levels_are_maketx_filtering_the_spectra_with_maketx_sizes() {
    let dir = Scratch::new("texture-maketx");
    // Odd sizes: maketx samples bilinearly at each texel's centre there, a 2×2 box elsewhere.
    let input = dir.path("in.exr");
    linear_image(&input, 61, 47);
    let png = dir.path("in.png");
    tool("oiiotool", &[s(&input), "-d", "uint8", "-o", s(&png)]);
    let out = dir.path("out.exr");
    Cmd::convert(&input, &out).args(["-d", "float"]).ok();

    // The same level sizes as maketx makes of the same input, for a float EXR and a PNG.
    let tx = dir.path("in.tx");
    tool("maketx", &[s(&input), "-o", s(&tx)]);
    assert_eq!(levels_line(&out), levels_line(&tx));
    assert_eq!(
        levels_line(&out),
        "MIP-map levels: 61x47 30x23 15x11 7x5 3x2 1x1"
    );
    let png_out = dir.path("png.exr");
    Cmd::convert(&png, &png_out).ok();
    assert_eq!(levels_line(&png_out), levels_line(&out));

    // Level k is maketx's filter applied to our level 0's spectra: maketx itself, run on
    // level 0 extracted as a 36-channel float image, makes the same levels.
    let level0 = dir.path("level0.exr");
    tool("oiiotool", &[s(&out), "--selectmip", "0", "-o", s(&level0)]);
    let reference = dir.path("level0.tx");
    tool("maketx", &[s(&level0), "-o", s(&reference)]);
    for level in 1..6 {
        let d = max_difference(&out, &reference, level);
        assert!(d <= 1e-5, "level {level}: {d}");
    }
}

#[test]
fn the_texture_system_reads_box_filtered_spectra_at_each_footprint() {
    let dir = Scratch::new("texture-lookup");
    let input = dir.path("in.exr");
    linear_image(&input, 64, 32);
    let out = dir.path("out.exr");
    Cmd::convert(&input, &out).ok();
    let v = script_json("texture_lookup.py", [&out]);
    let levels = v["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 7, "{v}");
    for (k, l) in levels.iter().enumerate() {
        // Half samples: within half a unit in the last place of values below 1 (2^-11),
        // plus the rounding of every level on its own.
        let d = l["max_difference"].as_f64().unwrap();
        assert!(d <= 1e-3, "level {k}: {d} from level 0 box-filtered ({v})");
        if k > 0 {
            let moved = l["moved_from_level_0"].as_f64().unwrap();
            assert!(moved > 1e-2, "level {k} reads as level 0 does ({v})");
        }
    }
    // oiio:AverageColor is the mean of level 0 (half samples against the float sums).
    let avg = v["averagecolor_difference"].as_f64().unwrap();
    assert!(avg <= 1e-3, "{v}");
}

#[test]
fn wrap_modes_come_from_maketx_inputs_or_the_option() {
    let dir = Scratch::new("texture-wrap");
    let png = dir.path("in.png");
    noise(&png, 16, "uint8");
    let tx = dir.path("in.tx");
    tool("maketx", &["--wrap", "periodic", s(&png), "-o", s(&tx)]);
    let out = dir.path("tx.exr");
    let json = Cmd::convert(&tx, &out).arg("--json").ok().json();
    assert_eq!(json["wrap"], "periodic,periodic");
    let i = info(&out);
    assert!(i.contains("wrapmodes: \"periodic,periodic\""), "{i}");
    assert!(i.contains("textureformat: \"Plain Texture\""), "{i}");
    assert!(i.contains("fovcot: 1"), "{i}");

    let set = dir.path("set.exr");
    Cmd::convert(&tx, &set)
        .args(["--wrap", "clamp,mirror"])
        .ok();
    assert!(info(&set).contains("wrapmodes: \"clamp,mirror\""));
    // Without one from the input or the option: maketx's default.
    let plain = dir.path("plain.exr");
    Cmd::convert(&png, &plain).ok();
    assert!(info(&plain).contains("wrapmodes: \"black,black\""));
    Cmd::convert(&png, dir.path("x.exr"))
        .args(["--wrap", "repeat"])
        .fails(2, &["'repeat' is not a wrap mode", "periodic"]);
}

/// A linear float image with NaN and infinite values: oiiotool's square root of a picture
/// with negative squares, and an infinity from a division by zero.
fn image_with_nan(path: &Path) {
    python_output([
        "-c",
        "import sys, numpy as np, OpenImageIO as oiio\n\
         a = np.tile(np.linspace(0.1, 0.6, 24, dtype=np.float32)[None, :, None], (16, 1, 3))\n\
         a[3, 5, 1] = np.nan; a[3, 6, :] = np.nan; a[15, 23, 0] = np.inf; a[8, 0, 2] = -np.inf\n\
         o = oiio.ImageOutput.create(sys.argv[1])\n\
         o.open(sys.argv[1], oiio.ImageSpec(24, 16, 3, 'float')); o.write_image(a); o.close()",
        s(path),
    ]);
}

#[test]
fn nan_is_refused_by_default_and_repaired_as_openimageio_repairs_it() {
    let dir = Scratch::new("texture-nan");
    let input = dir.path("nan.exr");
    image_with_nan(&input);
    let before = std::fs::read(&input).unwrap();
    // maketx --checknan refuses the same file.
    let maketx = std::process::Command::new("maketx")
        .args(["--checknan", s(&input), "-o", s(&dir.path("x.tx"))])
        .output()
        .unwrap();
    assert!(!maketx.status.success());

    let out = dir.path("out.exr");
    Cmd::convert(&input, &out).fails(
        1,
        &["4 pixel(s)", "NaN or infinite", "x 5, y 3", "--fixnan box3"],
    );
    assert!(!out.exists());
    no_temporaries(&dir.0);
    Cmd::convert(&input, &out)
        .arg("--checknan")
        .fails(1, &["NaN or infinite"]);

    // Repaired as oiiotool --fixnan repairs (OpenImageIO's fixNonFinite): the same output as
    // converting oiiotool's repaired image.
    for how in ["box3", "black"] {
        let ours = dir.path(&format!("{how}.exr"));
        let json = Cmd::convert(&input, &ours)
            .args(["--fixnan", how, "--json"])
            .ok()
            .json();
        assert_eq!(json["non_finite_repaired"], 4, "{json}");
        assert_eq!(json["non_finite"], 0, "{json}");
        let fixed = dir.path(&format!("fixed-{how}.exr"));
        tool("oiiotool", &[s(&input), "--fixnan", how, "-o", s(&fixed)]);
        let theirs = dir.path(&format!("theirs-{how}.exr"));
        Cmd::convert(&fixed, &theirs).ok();
        for level in 0..5 {
            assert_eq!(
                max_difference(&ours, &theirs, level),
                0.0,
                "{how} level {level}"
            );
        }
    }
    // Kept when asked: the spectra of those pixels are NaN.
    let kept = dir.path("kept.exr");
    let json = Cmd::convert(&input, &kept)
        .args(["--fixnan", "none", "--json"])
        .ok()
        .json();
    assert_eq!(json["non_finite"], 4, "{json}");
    Cmd::convert(&input, dir.path("y.exr"))
        .args(["--fixnan", "box3", "--checknan"])
        .fails(2, &["--checknan"]);
    // A repair repairs what is read, never the file: the input is byte for byte as it was,
    // also when it is named as its own output.
    Cmd::convert(&input, &input)
        .args(["--fixnan", "box3", "--force"])
        .fails(2, &["is the input"]);
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn data_copies_meet_the_nan_rule_of_a_conversion() {
    // Issue 31, item 9: a Raw float EXR with NaN was written through by --data copy, exit 0.
    let dir = Scratch::new("texture-nan-copy");
    let input = dir.path("nan.exr");
    image_with_nan(&input);
    let copy = ["--colorspace", "Raw", "--data", "copy"];
    let out = dir.path("out.exr");
    // Refused by default, with a conversion's words, and nothing written.
    Cmd::convert(&input, &out).args(copy).fails(
        1,
        &["4 pixel(s)", "NaN or infinite", "x 5, y 3", "--fixnan box3"],
    );
    assert!(!out.exists());
    no_temporaries(&dir.0);
    // Repaired as a conversion repairs them: OpenImageIO's fixNonFinite, as oiiotool --fixnan.
    for how in ["box3", "black"] {
        let ours = dir.path(&format!("{how}.exr"));
        let json = Cmd::convert(&input, &ours)
            .args(copy)
            .args(["--fixnan", how, "--json"])
            .ok()
            .json();
        assert_eq!(json["status"], "copied", "{json}");
        let fixed = dir.path(&format!("fixed-{how}.exr"));
        tool("oiiotool", &[s(&input), "--fixnan", how, "-o", s(&fixed)]);
        assert_eq!(max_difference(&ours, &fixed, 0), 0.0, "{how}");
    }
    // Kept when asked.
    let json = Cmd::convert(&input, dir.path("kept.exr"))
        .args(copy)
        .args(["--fixnan", "none", "--json"])
        .ok()
        .json();
    assert_eq!(json["status"], "copied", "{json}");
    no_temporaries(&dir.0);
}

#[test]
fn constant_textures_are_one_tile_and_opaque_alpha_is_left_out() {
    let dir = Scratch::new("texture-constant");
    let input = dir.path("grey.exr");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "constant:color=0.2,0.4,0.3,1",
            "300x200",
            "4",
            "-d",
            "half",
            "-o",
            s(&input),
        ],
    );
    let out = dir.path("out.exr");
    let json = Cmd::convert(&input, &out).arg("--json").ok().json();
    assert_eq!(json["constant"], true);
    assert_eq!(json["alpha_dropped"], true);
    let i = info(&out);
    assert!(i.contains("64 x   64, 36 channel"), "{i}");
    assert!(i.contains("oiio:ConstantColor"), "{i}");
    assert!(!i.contains(" A,") && !i.contains("A, T."), "{i}");
    // The colour of the one tile is the input's: to-rgb reads it back as linear Rec.709.
    let back = dir.path("back.exr");
    Cmd::to_rgb(&out, &back)
        .args(["--colorspace", "Linear Rec.709 (sRGB)"])
        .ok();
    let stats = tool("oiiotool", &["--stats", s(&back)]);
    let avg = stats
        .lines()
        .find(|l| l.contains("Stats Avg"))
        .unwrap()
        .to_string();
    let v: Vec<f64> = avg
        .split(':')
        .nth(1)
        .unwrap()
        .split_whitespace()
        .filter_map(|t| t.parse().ok())
        .take(3)
        .collect();
    for (got, want) in v.iter().zip([0.2, 0.4, 0.3]) {
        assert!((got - want).abs() < 2e-3, "{avg}");
    }

    let full = dir.path("full.exr");
    let json = Cmd::convert(&input, &full)
        .args([
            "--constant-color-detect=false",
            "--opaque-detect=false",
            "--json",
        ])
        .ok()
        .json();
    assert_eq!(json["constant"], false);
    let i = info(&full);
    assert!(i.contains("300 x  200, 37 channel"), "{i}");
}

#[test]
fn update_rebuilds_a_source_replaced_by_another_image_with_an_older_time() {
    let dir = Scratch::new("texture-update");
    let out = dir.path("out");
    std::fs::create_dir(&out).unwrap();
    let input = dir.path("a.exr");
    linear_image(&input, 32, 32);
    let status = |json: serde_json::Value| json["status"].as_str().unwrap().to_string();
    let run = || {
        Cmd::new(["-u", s(&input), "-o", s(&out), "--json"])
            .ok()
            .json()
    };
    assert_eq!(status(run()), "ok");
    assert_eq!(status(run()), "skipped");
    // The same pixels in a new file with the same time (a library copied with cp -p or
    // rsync): still up to date, by the hash.
    let copy = dir.path("copy.exr");
    tool("cp", &["-p", s(&input), s(&copy)]);
    std::fs::rename(&copy, &input).unwrap();
    assert_eq!(status(run()), "skipped");
    // Another image with a time older than the output's: rebuilt (maketx -u rebuilds it too).
    let other = dir.path("other.exr");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "checker",
            "32x32",
            "3",
            "-d",
            "float",
            "-o",
            s(&other),
        ],
    );
    tool("touch", &["-d", "2001-01-01", s(&other)]);
    std::fs::rename(&other, &input).unwrap();
    assert_eq!(status(run()), "ok");
    assert_eq!(status(run()), "skipped");
}

#[test]
fn levels_filtered_from_spectra_keep_the_colour_of_level_0_uplifting_levels_does_not() {
    // docs/guide.md's measurement: an 8-bit sRGB .tx (maketx filters its encoded values) and
    // a linear float .tx (filtered linearly: what is left is the uplift's non-linearity).
    let dir = Scratch::new("texture-consistency");
    let linear = dir.path("linear.exr");
    linear_image(&linear, 64, 64);
    let png = dir.path("srgb.png");
    tool(
        "oiiotool",
        &[
            s(&linear),
            "--colorconvert",
            "linear",
            "sRGB",
            "-d",
            "uint8",
            "-o",
            s(&png),
        ],
    );
    for (name, source) in [("srgb8", &png), ("linear", &linear)] {
        let tx = dir.path(&format!("{name}.tx"));
        tool("maketx", &[s(source), "-o", s(&tx)]);
        let filtered = dir.path(&format!("{name}-filtered.exr"));
        Cmd::convert(&tx, &filtered).ok();
        let mut uplifted = Vec::new();
        for level in 0..7 {
            let extracted = dir.path(&format!("{name}-level{level}.exr"));
            tool(
                "oiiotool",
                &[
                    s(&tx),
                    "--selectmip",
                    &level.to_string(),
                    "-d",
                    "float",
                    "-o",
                    s(&extracted),
                ],
            );
            let out = dir.path(&format!("{name}-uplifted{level}.exr"));
            let cs = if name == "srgb8" {
                "sRGB - Texture"
            } else {
                "Linear Rec.709 (sRGB)"
            };
            Cmd::convert(&extracted, &out)
                .args(["--mip", "0", "--colorspace", cs])
                .ok();
            uplifted.push(out);
        }
        let args: Vec<&Path> = std::iter::once(filtered.as_path())
            .chain(uplifted.iter().map(|p| p.as_path()))
            .collect();
        let v = script_json("mip_consistency.py", &args);
        eprintln!("{name}: {v}");
        let rows = v.as_array().unwrap();
        assert_eq!(rows.len(), 7);
        let mut worst_uplifted: f64 = 0.0;
        for row in rows {
            for ill in ["D65", "A", "FL11"] {
                // Filtered spectra: the colour of level 0 averaged, under every light, but for
                // half rounding.
                let f = row[format!("filtered_{ill}")][1].as_f64().unwrap();
                assert!(f < 0.1, "{name} {ill}: {row}");
                worst_uplifted =
                    worst_uplifted.max(row[format!("uplifted_{ill}")][0].as_f64().unwrap());
            }
        }
        assert!(worst_uplifted.is_finite());
    }
}

/// tests/oiio_levels.py's `diff` of every level of `ours` against `theirs` (theirs clamped
/// into [0, 1] when `clamped`): per level, the sizes, the largest difference and the smallest
/// and largest of their values.
fn level_diff(ours: &Path, theirs: &Path, clamped: bool) -> Vec<serde_json::Value> {
    let mut args = vec!["diff", s(ours), s(theirs)];
    if clamped {
        args.extend(["0", "1"]);
    }
    script_json("oiio_levels.py", args)
        .as_array()
        .unwrap()
        .clone()
}

/// The largest difference over every level (each the same size in both files).
fn largest(diff: &[serde_json::Value]) -> f64 {
    diff.iter()
        .map(|l| {
            assert_eq!(l["size"], l["other"], "level sizes differ: {l}");
            l["max_difference"].as_f64().unwrap()
        })
        .fold(0.0, f64::max)
}

/// Level 0 of a converted texture as a plain float image, for maketx to filter.
fn level0(out: &Path, dir: &Scratch, name: &str) -> std::path::PathBuf {
    let level0 = dir.path(name);
    tool("oiiotool", &[s(out), "--selectmip", "0", "-o", s(&level0)]);
    level0
}

#[test]
fn every_maketx_filter_makes_the_levels_maketx_makes_of_our_level_0() {
    let dir = Scratch::new("texture-filters");
    // Odd sizes for the separable filters; a square for the radial ones, which maketx 2.4
    // aborts on when the two directions' filter radii differ.
    let odd = dir.path("odd.exr");
    linear_image(&odd, 61, 47);
    let square = dir.path("square.exr");
    linear_image(&square, 32, 32);
    for name in [
        "box",
        "triangle",
        "gaussian",
        "sharp-gaussian",
        "catmull-rom",
        "blackman-harris",
        "sinc",
        "lanczos3",
        "radial-lanczos3",
        "nuke-lanczos6",
        "mitchell",
        "bspline",
        "disk",
        "cubic",
        "keys",
        "simon",
        "rifman",
    ] {
        let input = if name.contains("radial") || name == "disk" {
            &square
        } else {
            &odd
        };
        let out = dir.path(&format!("{name}.exr"));
        let json = Cmd::convert(input, &out)
            .args(["-d", "float", "--filter", name, "--json"])
            .ok()
            .json();
        assert_eq!(json["filter"], name, "{json}");
        let reference = dir.path(&format!("{name}.tx"));
        let level0 = level0(&out, &dir, &format!("{name}-0.exr"));
        tool(
            "maketx",
            &["--filter", name, s(&level0), "-o", s(&reference)],
        );
        assert_eq!(levels_line(&out), levels_line(&reference), "{name}");
        let d = largest(&level_diff(&out, &reference, true));
        eprintln!("{name}: largest difference from maketx {d:.2e}");
        assert!(d <= 2e-6, "{name}: {d}");
    }
}

#[test]
fn negative_lobes_are_clamped_to_reflectance_and_otherwise_maketx_levels() {
    let dir = Scratch::new("texture-lobes");
    // Sharp edges between near-black and near-white: lanczos3 rings past both.
    let input = dir.path("checker.exr");
    tool(
        "oiiotool",
        &[
            "--pattern",
            "checker:width=3:height=3:color1=0.02,0.02,0.02:color2=0.95,0.95,0.95",
            "48x48",
            "3",
            "-d",
            "float",
            "-o",
            s(&input),
        ],
    );
    let out = dir.path("out.exr");
    let json = Cmd::convert(&input, &out)
        .args(["-d", "float", "--filter", "lanczos3", "--json"])
        .ok()
        .json();
    let clamped = json["clamped"].as_u64().unwrap();
    assert!(clamped > 0, "{json}");
    let reference = dir.path("ref.tx");
    let level0 = level0(&out, &dir, "level0.exr");
    tool(
        "maketx",
        &["--filter", "lanczos3", s(&level0), "-o", s(&reference)],
    );
    // maketx's own levels leave [0, 1]; ours are its levels clamped into it.
    let (below, above) = range(&level_diff(&out, &reference, false));
    let (our_min, our_max) = range(&level_diff(&reference, &out, false));
    let d = largest(&level_diff(&out, &reference, true));
    eprintln!(
        "lanczos3 on a checker: maketx's levels reach [{below:.4}, {above:.4}], ours \
         [{our_min:.4}, {our_max:.4}]; {clamped} pixels clamped; largest difference from \
         maketx's clamped {d:.2e}"
    );
    assert!(
        below < 0.0 && above > 1.0,
        "no ringing to clamp: [{below}, {above}]"
    );
    assert!(our_min >= 0.0 && our_max <= 1.0, "[{our_min}, {our_max}]");
    assert!(d <= 2e-6, "{d}");
}

/// The smallest and largest of the second file's values over its levels.
fn range(diff: &[serde_json::Value]) -> (f64, f64) {
    diff.iter().fold((f64::MAX, f64::MIN), |(lo, hi), l| {
        (
            lo.min(l["min"].as_f64().unwrap()),
            hi.max(l["max"].as_f64().unwrap()),
        )
    })
}

#[test]
fn resize_makes_maketx_power_of_two_levels_from_the_spectra() {
    let dir = Scratch::new("texture-resize");
    let input = dir.path("in.exr");
    linear_image(&input, 61, 47);
    // maketx --resize's level sizes for the same input.
    let tx = dir.path("in.tx");
    tool("maketx", &["--resize", s(&input), "-o", s(&tx)]);
    // The spectra at the input's size: the level 0 maketx resizes for reference.
    let plain = dir.path("plain.exr");
    Cmd::convert(&input, &plain).args(["-d", "float"]).ok();
    let level0 = level0(&plain, &dir, "level0.exr");
    for name in ["box", "lanczos3", "gaussian"] {
        let out = dir.path(&format!("{name}.exr"));
        let json = Cmd::convert(&input, &out)
            .args(["-d", "float", "--resize", "--filter", name, "--json"])
            .ok()
            .json();
        assert_eq!(json["levels"], 7, "{json}");
        assert_eq!(levels_line(&out), levels_line(&tx));
        assert_eq!(
            levels_line(&out),
            "MIP-map levels: 64x64 32x32 16x16 8x8 4x4 2x2 1x1"
        );
        let reference = dir.path(&format!("{name}.tx"));
        tool(
            "maketx",
            &[
                "--resize",
                "--filter",
                name,
                s(&level0),
                "-o",
                s(&reference),
            ],
        );
        let d = largest(&level_diff(&out, &reference, true));
        eprintln!("--resize --filter {name}: largest difference from maketx {d:.2e}");
        assert!(d <= 2e-6, "{name}: {d}");
    }
    // The filter and the resize are settings: -u rebuilds when either changes.
    let status = |args: &[&str]| {
        Cmd::convert(&input, dir.path("u.exr"))
            .args(["-u", "--json"])
            .args(args)
            .ok()
            .json()["status"]
            .as_str()
            .unwrap()
            .to_string()
    };
    assert_eq!(status(&[]), "ok");
    assert_eq!(status(&["--filter", "box"]), "skipped");
    assert_eq!(status(&["--filter", "lanczos3"]), "ok");
    assert_eq!(status(&["--filter", "lanczos3", "--resize"]), "ok");
    assert_eq!(status(&["--filter", "lanczos3", "--resize"]), "skipped");
}

#[test]
fn an_unknown_filter_is_a_usage_error_that_lists_them() {
    let dir = Scratch::new("texture-filter-name");
    let input = dir.path("in.exr");
    linear_image(&input, 8, 8);
    Cmd::convert(&input, dir.path("out.exr"))
        .args(["--filter", "lanczos"])
        .fails(2, &["lanczos3", "radial-lanczos3", "box", "mitchell"]);
    assert!(!dir.path("out.exr").exists());
}
