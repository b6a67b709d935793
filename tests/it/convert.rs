//! The main job, `specconv [convert] INPUT OUTPUT`, checked with real EXR readers: OpenEXR's
//! exrheader, oiiotool, colour-science's Fichet 2021 reader, and our own reader for values.

use crate::runner::*;
use std::path::{Path, PathBuf};

pub(crate) fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("testdata/images")
        .join(name)
}

/// Every readable test image.
fn textures() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
    v.sort();
    assert!(
        v.len() >= 10,
        "testdata/images is incomplete: run testdata/make.sh"
    );
    v
}

/// XYZ of every pixel of one level of an input, as the pipeline's colour management sees it.
fn input_xyz(input: &Path, level: usize) -> (usize, usize, Vec<[f32; 3]>) {
    let mut reader = specconv_oiio::ImageReader::open(input).unwrap();
    let info = reader.info().clone();
    // The colour space and alpha the library chooses; the route to XYZ is OpenColorIO's own.
    let options = specconv_conversion::Options::default();
    let config = specconv_conversion::ColourConfig::resolve(Some("aces")).unwrap();
    let d = specconv_conversion::describe(&config, input, &options).unwrap();
    let Ok(specconv_conversion::ReadAs::Colour { space, .. }) = &d.colour else {
        panic!("{} is not read as colour: {:?}", input.display(), d.colour)
    };
    let to_xyz = specconv_ocio::Config::resolve(Some("aces"))
        .unwrap()
        .processor_to_xyz(space)
        .unwrap();
    let premultiply = d.straight_alpha;
    let px = reader.read_level(level).unwrap();
    let colour: Vec<usize> = (0..px.channels)
        .filter(|&c| Some(c) != info.alpha_channel)
        .take(3)
        .collect();
    let mut rgb: Vec<f32> = px
        .data
        .chunks_exact(px.channels)
        .flat_map(|p| {
            if colour.len() == 3 {
                [p[colour[0]], p[colour[1]], p[colour[2]]]
            } else {
                [p[colour[0]]; 3]
            }
        })
        .collect();
    to_xyz.apply_rgb(&mut rgb).unwrap();
    if premultiply {
        let a = info.alpha_channel.unwrap();
        for (c, p) in rgb
            .chunks_exact_mut(3)
            .zip(px.data.chunks_exact(px.channels))
        {
            c.iter_mut().for_each(|v| *v *= p[a]);
        }
    }
    (
        px.width as usize,
        px.height as usize,
        rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    )
}

/// Largest error of XYZ integrated from the output's spectra against the input's XYZ,
/// relative to the pixel's largest XYZ component (absolute below 1e-3).
fn round_trip_error(input: &Path, output: &Path, level: usize) -> f64 {
    round_trip_error_on(
        input,
        output,
        level,
        specconv_spectral::Model::builtin().grid,
    )
}

/// As [`round_trip_error`] for an output on `grid` (CIE 1931, D65, as the built-in model).
fn round_trip_error_on(
    input: &Path,
    output: &Path,
    level: usize,
    grid: specconv_colour::Grid,
) -> f64 {
    let (w, h, want) = input_xyz(input, level);
    let img = specconv_exr::read(output).unwrap();
    assert_eq!((img.width, img.height), (w, h));
    assert_eq!(img.wavelengths, grid.wavelengths());
    // As every reader integrates (the layout's reference: interpolated onto the 1 nm table).
    let a = specconv_colour::Integration::reflectance(
        &grid.wavelengths(),
        specconv_colour::Observer::Cie1931,
        specconv_colour::Illuminant::D65,
    )
    .unwrap();
    let mut worst = 0.0f64;
    let mut r = vec![0.0; img.bands.len()];
    for (p, c) in want.iter().enumerate() {
        if !c.iter().all(|v| v.is_finite()) {
            continue;
        }
        r.iter_mut()
            .zip(&img.bands)
            .for_each(|(v, plane)| *v = plane[p] as f64);
        let got = a.xyz(&r);
        let scale = c.iter().fold(1e-3f64, |m, v| m.max(v.abs() as f64));
        for k in 0..3 {
            worst = worst.max((got[k] - c[k] as f64).abs() / scale);
        }
    }
    worst
}

#[test]
fn every_texture_converts_to_a_spectral_exr_that_real_readers_open_and_that_round_trips() {
    let dir = Scratch::new("convert-all");
    let names = regex::Regex::new(
        r"^((S([0-3]))|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$",
    )
    .unwrap();
    for input in textures() {
        for (data_type, tolerance) in [("half", 2e-3), ("float", 1e-5)] {
            let stem = input
                .file_name()
                .unwrap()
                .to_string_lossy()
                .replace('.', "_");
            let output = dir.path(&format!("{stem}_{data_type}.exr"));
            // The paper's raw output keeps every colour, HDR and wide gamut too; the bounded
            // default keeps those inside the object-colour solid (tested below).
            let run = Cmd::new([
                "--unbounded",
                "--ocio",
                "aces",
                "-d",
                data_type,
                input.to_str().unwrap(),
                output.to_str().unwrap(),
            ])
            .run();
            run.ok();
            assert!(
                run.stderr.contains("colour space "),
                "the colour space choice is reported: {}",
                run.stderr
            );

            let header = tool("exrheader", &[output.to_str().unwrap()]);
            assert!(
                header.contains("spectralLayoutVersion (type string): \"1.0\""),
                "{header}"
            );
            let info = tool("oiiotool", &["--info", "-v", output.to_str().unwrap()]);
            assert!(
                info.contains("37 channel") || info.contains("36 channel"),
                "{info}"
            );
            // Channel lines of exrheader: "    T.380,000000nm, 16-bit floating-point, …".
            let channels: Vec<&str> = header
                .lines()
                .skip_while(|l| !l.starts_with("channels"))
                .skip(1)
                .take_while(|l| l.starts_with("    "))
                .map(|l| l.trim().split(", ").next().unwrap())
                .collect();
            assert_eq!(
                channels.iter().filter(|c| c.starts_with("T.")).count(),
                36,
                "{input:?}"
            );
            for c in channels.iter().filter(|c| **c != "A") {
                assert!(
                    names.is_match(c),
                    "{c} does not match the reference reader's expression"
                );
            }
            let has_alpha = specconv_oiio::ImageReader::open(&input)
                .unwrap()
                .info()
                .alpha_channel
                .is_some();
            assert_eq!(
                channels.contains(&"A"),
                has_alpha,
                "{input:?}: alpha passes through as A"
            );

            let err = round_trip_error(&input, &output, 0);
            assert!(
                err <= tolerance,
                "{input:?} -d {data_type}: XYZ round trip error {err} > {tolerance}"
            );
        }
    }
    assert!(
        dir.files().iter().all(|f| !f.contains(".tmp")),
        "no temporary files left: {:?}",
        dir.files()
    );
}

#[test]
fn tiled_outputs_are_mip_maps_and_scanline_outputs_one_level() {
    // The levels themselves are checked against maketx and the TextureSystem in texture.rs.
    let dir = Scratch::new("convert-mip");
    for input in [testdata("srgba8.tx"), testdata("srgba8.png")] {
        let output = dir.path("out.exr");
        Cmd::convert(&input, &output)
            .args(["-d", "float", "--force"])
            .ok();
        let info = tool("oiiotool", &["--info", "-v", output.to_str().unwrap()]);
        assert!(
            info.contains("MIP-map levels: 61x47 30x23 15x11 7x5 3x2 1x1"),
            "{info}"
        );
        // Level 0 keeps the input's colour.
        let extracted = dir.path("level0.exr");
        tool(
            "oiiotool",
            &[
                output.to_str().unwrap(),
                "--selectmip",
                "0",
                "-o",
                extracted.to_str().unwrap(),
            ],
        );
        let err = round_trip_error(&input, &extracted, 0);
        assert!(err <= 1e-5, "{}: {err}", input.display());
    }
    let input = testdata("srgba8.tx");
    for args in [
        &["--mip", "0", "--scanline"][..],
        &["--scanline"],
        &["--mip", "0"],
    ] {
        let base = dir.path("base.exr");
        Cmd::convert(&input, &base).args(args).arg("--force").ok();
        let info = tool("oiiotool", &["--info", "-v", base.to_str().unwrap()]);
        assert!(!info.contains("MIP-map"), "{args:?}: {info}");
        assert_eq!(
            info.contains("tile size"),
            args.len() == 2,
            "{args:?}: {info}"
        );
    }
}

/// What colour-science's Fichet 2021 reader (tests/read_fichet2021.py) makes of `output`:
/// its layout, attributes and the spectra of pixel (x, y), as JSON.
pub(crate) fn read_fichet2021(output: &Path, x: usize, y: usize) -> serde_json::Value {
    let at = [x, y].map(|v| std::ffi::OsString::from(v.to_string()));
    script_json("read_fichet2021.py", [output.as_os_str(), &at[0], &at[1]])
}

#[test]
fn colour_science_reads_the_output() {
    let dir = Scratch::new("convert-colour");
    let input = testdata("float_tiled_alpha.exr");
    let output = dir.path("out.exr");
    Cmd::convert(&input, &output).args(["-d", "float"]).ok();
    let v = read_fichet2021(&output, 7, 5);
    let t = &v["T"];
    let wl: Vec<f64> = t["wavelengths"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_f64().unwrap())
        .collect();
    assert_eq!(wl, specconv_colour::Grid::PAPER.wavelengths());
    assert_eq!(t["shape"], serde_json::json!([47, 61, 36]));
    let ours = specconv_exr::read(&output).unwrap();
    for (b, plane) in ours.bands.iter().enumerate() {
        assert_eq!(
            t["pixel"][b].as_f64().unwrap() as f32,
            plane[5 * 61 + 7],
            "band {b}"
        );
    }
}

#[test]
fn to_rgb_integrates_back_to_the_input_colours() {
    let dir = Scratch::new("to-rgb");
    let input = testdata("float_scanline.exr");
    let spectral = dir.path("s.exr");
    // Unbounded: its colours outside the object-colour solid come back too. OpenEXR without
    // chromaticities is linear Rec.709 (D65), so that is what to-rgb must give back.
    Cmd::convert(&input, &spectral)
        .args(["-d", "float", "--unbounded"])
        .ok();
    let back = dir.path("back.exr");
    Cmd::to_rgb(&spectral, &back)
        .args(["--colorspace", "lin_rec709"])
        .ok();
    let mut a = specconv_oiio::ImageReader::open(&input).unwrap();
    let mut b = specconv_oiio::ImageReader::open(&back).unwrap();
    let (pa, pb) = (a.read_level(0).unwrap(), b.read_level(0).unwrap());
    let mut worst = 0.0f32;
    for y in 0..pa.height {
        for x in 0..pa.width {
            for c in 0..3 {
                let (u, v) = (pa.pixel(x, y)[c], pb.pixel(x, y)[c]);
                worst = worst.max((u - v).abs() / u.abs().max(1e-2));
            }
        }
    }
    assert!(
        worst < 1e-4,
        "linear Rec.709 → spectra → linear Rec.709 differs by {worst}"
    );
    Cmd::to_rgb(&spectral, &back).fails(2, &["exists; pass --force"]);
    Cmd::to_rgb(&input, dir.path("c.exr")).fails(1, &["not a spectral EXR"]);
}

#[test]
fn failures_leave_nothing_behind_and_say_what_to_do() {
    let dir = Scratch::new("convert-fail");
    let good = testdata("srgb8.png");
    let out = dir.path("out.exr");
    Cmd::new(["/nonexistent/in.png", out.to_str().unwrap()])
        .fails(1, &["specconv: error: /nonexistent/in.png"]);
    let broken = Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/broken");
    for f in std::fs::read_dir(&broken).unwrap() {
        let f = f.unwrap().path();
        Cmd::convert(&f, &out).fails(1, &["specconv: error:"]);
    }
    Cmd::convert(&good, dir.path("missing/out.exr"))
        .fails(2, &["output directory", "does not exist"]);
    // The input is never written over, even when named as the output.
    let copy = dir.path("in.png");
    std::fs::copy(&good, &copy).unwrap();
    // (A .png output is refused by its name first, as a usage error.)
    Cmd::convert(&copy, &copy).fails(2, &["ending in .exr"]);
    assert_eq!(std::fs::read(&copy).unwrap(), std::fs::read(&good).unwrap());
    let exr = testdata("float_scanline.exr");
    let copy = dir.path("in.exr");
    std::fs::copy(&exr, &copy).unwrap();
    Cmd::convert(&copy, &copy).fails(2, &["is the input"]);
    assert_eq!(std::fs::read(&copy).unwrap(), std::fs::read(&exr).unwrap());
    // An existing output needs --force.
    std::fs::write(&out, b"keep me").unwrap();
    Cmd::convert(&good, &out).fails(2, &["exists; pass --force"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"keep me");
    Cmd::convert(&good, &out).arg("--force").ok();
    Cmd::convert(&good, &out)
        .args(["--force", "--colorspace", "Raw", "--data", "fail"])
        .fails(2, &["holds data, not colour"]);
    Cmd::convert(&good, &out)
        .args(["--force", "--colorspace", "srgb_txt"])
        .fails(2, &["unknown colour space"]);
    Cmd::new([good.to_str().unwrap()]).fails(2, &["give INPUT OUTPUT"]);
    assert_eq!(dir.files(), vec!["in.exr", "in.png", "out.exr"]);
    assert!(tool("exrheader", &[out.to_str().unwrap()]).contains("spectralLayoutVersion"));
}

#[test]
fn batches_convert_the_good_inputs_report_each_and_exit_1_for_the_bad() {
    let dir = Scratch::new("convert-batch");
    let outdir = dir.path("out");
    std::fs::create_dir(&outdir).unwrap();
    let missing = dir.path("gone.png");
    let list = format!(
        "{}\n{}\n",
        testdata("srgb8.png").display(),
        missing.display()
    );
    let input = testdata("rgb16.tif");
    let out = Cmd::new([
        "-",
        input.to_str().unwrap(),
        "-o",
        outdir.to_str().unwrap(),
        "--json",
    ])
    .stdin(list)
    .run();
    assert_eq!(out.code, 1);
    let reports = out.json_lines();
    assert_eq!(reports.len(), 3);
    assert_eq!(reports[0]["status"], "ok");
    assert!(reports[0]["pixels"].as_u64().unwrap() >= 61 * 47);
    assert_eq!(reports[1]["status"], "failed");
    // The error says what went wrong; the record's input says where (not twice).
    assert!(reports[1]["input"].as_str().unwrap().ends_with("gone.png"));
    let error = reports[1]["error"].as_str().unwrap();
    assert!(
        error.contains("no such file") && !error.contains("gone.png"),
        "{error}"
    );
    assert_eq!(reports[2]["status"], "ok");
    let mut made: Vec<String> = std::fs::read_dir(&outdir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    made.sort();
    assert_eq!(made, vec!["rgb16_spectral.exr", "srgb8_spectral.exr"]);

    // -u skips what is up to date with the same settings, and redoes it with other settings.
    let again = Cmd::new([
        testdata("srgb8.png").to_str().unwrap(),
        "-o",
        outdir.to_str().unwrap(),
        "-u",
        "--json",
    ])
    .run();
    assert!(
        again.ok().contains("\"status\":\"skipped\""),
        "{}",
        again.stdout
    );
    let other = Cmd::new([
        testdata("srgb8.png").to_str().unwrap(),
        "-o",
        outdir.to_str().unwrap(),
        "-u",
        "--json",
        "-d",
        "float",
    ])
    .run();
    assert!(other.ok().contains("\"status\":\"ok\""), "{}", other.stdout);
    let templated = Cmd::new([
        testdata("srgb8.png").to_str().unwrap(),
        "--output-template",
        &format!("{}/{{stem}}.spec.exr", outdir.display()),
    ])
    .run();
    templated.ok();
    assert!(outdir.join("srgb8.spec.exr").exists());
}

#[test]
fn sigterm_mid_write_leaves_no_partial_file() {
    let dir = Scratch::new("convert-term");
    let big = dir.path("big.exr");
    noise(&big, 3000, "half");
    let out = dir.path("out.exr");
    let child = Cmd::convert(&big, &out)
        .args(["-j", "1"])
        .command()
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the temporary file exists, then terminate.
    let start = std::time::Instant::now();
    while !dir.files().iter().any(|f| f.ends_with(".tmp")) {
        assert!(
            start.elapsed().as_secs() < 60,
            "the conversion never started writing"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    tool("kill", &["-TERM", &child.id().to_string()]);
    let result = child.wait_with_output().unwrap();
    assert_ne!(
        result.status.code(),
        Some(0),
        "a terminated run must not report success"
    );
    assert!(String::from_utf8_lossy(&result.stderr).contains("interrupted"));
    assert_eq!(
        dir.files(),
        vec!["big.exr"],
        "no output and no temporary file"
    );
}

#[test]
fn shell_completions_name_the_commands() {
    for shell in ["bash", "zsh", "fish"] {
        let out = Cmd::new(["completions", shell]).run();
        let script = out.ok();
        for word in ["train", "eval", "to-rgb", "colorspace"] {
            assert!(script.contains(word), "{shell} completion lacks {word}");
        }
    }
    Cmd::new(["completions", "tcsh"]).fails(2, &["invalid value"]);
}

/// Reflectances are bounded by default: every band in [0, 1], the colours inside the
/// object-colour solid kept exactly; the summary and --json count what was moved;
/// --unbounded gives the method's raw spectra.
#[test]
fn convert_bounds_reflectances_by_default_and_unbounded_gives_the_raw_spectra() {
    let dir = Scratch::new("convert-bounded");
    let worst = |path: &Path| {
        specconv_exr::read(path)
            .unwrap()
            .bands
            .iter()
            .flatten()
            .fold(0.0f32, |w, &v| w.max(-v).max(v - 1.0))
    };
    // 8-bit sRGB: every colour is inside the solid, so XYZ is kept; --bounded is accepted.
    let input = testdata("srgb8.png");
    for flags in [&[][..], &["--bounded"], &["--unbounded", "--bounded"]] {
        let out = dir.path("srgb.exr");
        let mut args = vec![
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "-d",
            "float",
            "--force",
        ];
        args.extend_from_slice(flags);
        let run = Cmd::new(args).run();
        run.ok();
        assert!(
            run.stderr
                .contains("pixels projected into [0, 1], 0 outside"),
            "{}",
            run.stderr
        );
        assert!(
            worst(&out) <= 1e-6,
            "{flags:?}: a band {} outside [0, 1]",
            worst(&out)
        );
        let attrs = specconv_exr::read_attributes(&out).unwrap();
        assert!(attrs.contains(&("specconvMethod".into(), "otsu2018+bounded".into())));
        let err = round_trip_error(&input, &out, 0);
        assert!(err <= 1e-5, "{flags:?}: round trip {err}");
    }
    let plain = dir.path("plain.exr");
    Cmd::convert(&input, &plain)
        .args(["-d", "float", "--unbounded"])
        .ok();
    assert!(
        worst(&plain) > 1e-3,
        "the test image's raw uplift leaves [0, 1]"
    );

    // ACEScg floats, many outside the solid: in [0, 1] all the same, counted in --json.
    let input = testdata("float_scanline.exr");
    let out = dir.path("aces.exr");
    let run = Cmd::convert(&input, &out)
        .args(["-d", "float", "--json"])
        .run();
    let report: serde_json::Value = serde_json::from_str(run.ok().trim()).unwrap();
    let (projected, outside) = (
        report["bounded"]["projected"].as_u64().unwrap(),
        report["bounded"]["outside_solid"].as_u64().unwrap(),
    );
    assert!(projected > 0 && outside > 0, "{report}");
    assert!(projected + outside <= report["pixels"].as_u64().unwrap());
    assert!(worst(&out) <= 1e-6, "a band {} outside [0, 1]", worst(&out));
    let raw = dir.path("aces_raw.exr");
    let run = Cmd::convert(&input, &raw)
        .args(["-d", "float", "--json", "--unbounded"])
        .run();
    let report: serde_json::Value = serde_json::from_str(run.ok().trim()).unwrap();
    assert!(report["bounded"].is_null(), "{report}");
    assert!(worst(&raw) > 1e-3);
}

#[test]
fn baseline_methods_convert_too() {
    let dir = Scratch::new("convert-methods");
    let input = testdata("srgb8.png");
    let meng = dir.path("meng.exr");
    Cmd::convert(&input, &meng)
        .args(["-d", "float", "--method", "meng2015"])
        .ok();
    assert!(
        round_trip_error(&input, &meng, 0) <= 1e-5,
        "meng2015 keeps XYZ exactly"
    );
    let attrs = specconv_exr::read_attributes(&meng).unwrap();
    assert!(
        attrs.contains(&("specconvMethod".into(), "meng2015+bounded".into())),
        "{attrs:?}"
    );
    Cmd::convert(&input, dir.path("x.exr"))
        .args(["--method", "pca"])
        .fails(2, &["one-cluster model"]);
    Cmd::convert(&input, dir.path("y.exr"))
        .args(["--method", "rgb"])
        .fails(2, &["--method"]);
}

#[test]
fn bands_put_the_spectra_on_another_grid_with_their_colour() {
    let dir = Scratch::new("convert-bands");
    let input = testdata("float_tiled_alpha.exr");
    for (bands, count) in [("400:700:5", 61), ("380:780:20", 21)] {
        let output = dir.path(&format!("{count}.exr"));
        Cmd::convert(&input, &output)
            .args(["-d", "float", "--bands", bands, "--unbounded"])
            .ok();
        let grid: specconv_colour::Grid = bands.parse().unwrap();
        assert_eq!(grid.len(), count);
        let err = round_trip_error_on(&input, &output, 0, grid);
        assert!(err <= 1e-5, "--bands {bands}: round trip {err}");
    }
    Cmd::convert(&input, dir.path("x.exr"))
        .args(["--bands", "300:700:10"])
        .fails(2, &["does not cover"]);
}

/// `--half-rounding nearest` (the default) stores each band as the nearest half of the float
/// spectrum; `colour` keeps the colour: every band within one half step, and XYZ closer.
#[test]
fn half_rounding_nearest_rounds_each_band_and_colour_keeps_xyz_closer() {
    let dir = Scratch::new("convert-half-rounding");
    let input = testdata("srgb8.png");
    let convert = |name: &str, flags: &[&str]| {
        let out = dir.path(name);
        let mut args = vec![input.to_str().unwrap(), out.to_str().unwrap(), "--mip", "0"];
        args.extend_from_slice(flags);
        Cmd::new(args).ok();
        specconv_exr::read(&out).unwrap()
    };
    let float = convert("float.exr", &["-d", "float"]);
    let nearest = convert("nearest.exr", &[]);
    let colour = convert("colour.exr", &["--half-rounding", "colour"]);
    // The colour the output keeps: as every reader integrates it.
    let a = specconv_colour::Integration::reflectance(
        &specconv_colour::Grid::new(380.0, 730.0, 10.0)
            .unwrap()
            .wavelengths(),
        specconv_colour::Observer::Cie1931,
        specconv_colour::Illuminant::D65,
    )
    .unwrap();
    let pixels = float.width * float.height;
    let spectrum = |img: &specconv_exr::SpectralImage, p: usize| -> Vec<f64> {
        img.bands.iter().map(|b| b[p] as f64).collect()
    };
    let (mut worst_nearest, mut worst_colour) = (0.0f64, 0.0f64);
    for p in 0..pixels {
        for (b, plane) in float.bands.iter().enumerate() {
            let v = plane[p];
            let n = half::f16::from_f32(v).to_f32();
            assert_eq!(nearest.bands[b][p], n, "pixel {p} band {b}");
            // Colour-keeping: the nearest half or its neighbour on the other side of the value.
            let c = colour.bands[b][p];
            let bits = |x: f32| half::f16::from_f32(x).to_bits() as i32;
            assert_eq!(half::f16::from_f32(c).to_f32(), c);
            assert!(
                c == n || ((c - v) * (n - v) <= 0.0 && (bits(c) - bits(n)).abs() == 1),
                "band {v}: nearest {n}, colour-keeping {c}"
            );
        }
        let exact = a.xyz(&spectrum(&float, p));
        let err = |img: &specconv_exr::SpectralImage| {
            let got = a.xyz(&spectrum(img, p));
            (0..3).fold(0.0f64, |m, k| m.max((got[k] - exact[k]).abs()))
        };
        worst_nearest = worst_nearest.max(err(&nearest));
        worst_colour = worst_colour.max(err(&colour));
    }
    assert!(
        worst_colour < worst_nearest,
        "colour-keeping {worst_colour:e}, nearest {worst_nearest:e}"
    );
}
