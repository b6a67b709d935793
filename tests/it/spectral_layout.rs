//! Spectral EXRs as the layout's reference implementation (afichet/spectral-exr) reads them:
//! tests/fichet_reference.py is its conversion to XYZ written independently (numpy on
//! colour-science's CIE 1931 table, the file read with OpenImageIO). Files of other writers are
//! made here with the `exr` crate, not with specconv's writer: uneven grids, other units,
//! bispectral and polarised channels, RGB beside the spectra. Also: the emission conventions,
//! and output names no command writes.

use crate::convert::testdata;
use crate::runner::*;
use exr::prelude::*;
use std::path::Path;

const REC709: &str = "Linear Rec.709 (sRGB)";
const XYZ: &str = "CIE-XYZ-D65";

/// Runs tests/fichet_reference.py with `args`; its JSON.
fn python(args: &[&str]) -> serde_json::Value {
    script_json("fichet_reference.py", args)
}

fn xyz_list(v: &serde_json::Value) -> Vec<[f64; 3]> {
    v["xyz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [0, 1, 2].map(|k| p[k].as_f64().unwrap()))
        .collect()
}

/// The reference's XYZ of every pixel of a spectral file.
fn reference(file: &Path) -> Vec<[f64; 3]> {
    xyz_list(&python(&[file.to_str().unwrap()]))
}

/// `to-rgb` of `file` into `colorspace`: its pixels, and what it said.
fn to_rgb(file: &Path, colorspace: &str) -> (Vec<[f64; 3]>, String) {
    let out = file.with_extension("back.exr");
    let run = Cmd::new([
        "to-rgb",
        "--force",
        "--colorspace",
        colorspace,
        file.to_str().unwrap(),
        out.to_str().unwrap(),
    ])
    .run();
    run.ok();
    let img = read_first_rgba_layer_from_file(
        &out,
        |res, _| (res.width(), vec![[0f64; 3]; res.width() * res.height()]),
        |(w, px): &mut (usize, Vec<[f64; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b].map(f64::from);
        },
    )
    .unwrap();
    (img.layer_data.channel_data.pixels.1, run.stderr)
}

/// Largest difference of `got` from `want`, relative to each pixel's largest component.
fn worst(got: &[[f64; 3]], want: &[[f64; 3]]) -> f64 {
    assert_eq!(got.len(), want.len());
    got.iter().zip(want).fold(0.0f64, |m, (g, w)| {
        let size = w.iter().fold(1e-6f64, |s, v| s.max(v.abs()));
        (0..3).fold(m, |m, k| m.max((g[k] - w[k]).abs() / size))
    })
}

/// Writes a `width`×`height` float EXR with these channels and text attributes, through the
/// `exr` crate alone (as another tool would write it).
fn write_exr(path: &Path, width: usize, channels: Vec<(String, Vec<f32>)>, attrs: &[(&str, &str)]) {
    let height = channels[0].1.len() / width;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, v)| AnyChannel::new(name.as_str(), FlatSamples::F32(v)))
        .collect();
    let mut layer = Layer::new(
        (width, height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    for (k, v) in attrs {
        layer
            .attributes
            .other
            .insert(Text::from(*k), AttributeValue::Text(Text::from(*v)));
    }
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// `value` with a comma as decimal separator, six decimals (as the reference writes).
fn num(value: f64) -> String {
    format!("{value:.6}").replace('.', ",")
}

/// Deterministic smooth-ish spectra: `pixels` of them at `wavelengths`, within [lo, hi].
fn spectra(wavelengths: &[f64], pixels: usize, lo: f32, hi: f32) -> Vec<Vec<f32>> {
    (0..pixels)
        .map(|p| {
            let (a, b, c) = (
                p as f64 * 0.37 + 0.1,
                p as f64 * 1.3 + 0.5,
                420.0 + 45.0 * p as f64,
            );
            wavelengths
                .iter()
                .map(|&l| {
                    let t = 0.5
                        + 0.3 * (l / 60.0 * b + a).sin()
                        + 0.2 * (-((l - c) / 40.0).powi(2)).exp();
                    lo + (hi - lo) * t.clamp(0.0, 1.0) as f32
                })
                .collect()
        })
        .collect()
}

/// Channels `prefix.<name(λ)>` holding band b of every pixel.
fn channels(prefix: &str, names: &[String], px: &[Vec<f32>]) -> Vec<(String, Vec<f32>)> {
    names
        .iter()
        .enumerate()
        .map(|(b, n)| (format!("{prefix}.{n}"), px.iter().map(|s| s[b]).collect()))
        .collect()
}

fn nm_names(wavelengths: &[f64]) -> Vec<String> {
    wavelengths
        .iter()
        .map(|&l| format!("{}nm", num(l)))
        .collect()
}

#[test]
fn emission_is_the_input_colour_by_the_reference_conversion() {
    let dir = Scratch::new("layout-emission");
    let input = testdata("sky.hdr");
    let want = xyz_list(&python(&["--rec709", input.to_str().unwrap()]));
    for (data_type, tolerance) in [("half", 1e-3), ("float", 1e-5)] {
        let out = dir.path(&format!("sky_{data_type}.exr"));
        Cmd::new([
            "--ocio",
            "aces",
            "--emissive",
            "--colorspace",
            REC709,
            "-d",
            data_type,
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ])
        .ok();
        let err = worst(&reference(&out), &want);
        assert!(err < tolerance, "-d {data_type}: {err} ≥ {tolerance}");
        let attrs = specconv_exr::read_attributes(&out).unwrap();
        assert!(attrs.contains(&("specconvEmissionUnits".into(), "reference".into())));
    }
}

#[test]
fn to_rgb_reads_a_file_in_the_reference_convention_as_the_reference_does() {
    let dir = Scratch::new("layout-reference-file");
    let wl: Vec<f64> = (0..=80).map(|i| 380.0 + 5.0 * i as f64).collect();
    let mut px = spectra(&wl, 5, 0.0, 0.02);
    // A flat spectrum, a line at 600 nm and a Gaussian at 550 nm beside the smooth ones.
    px.push(vec![0.01; wl.len()]);
    px.push(
        wl.iter()
            .map(|&l| if l == 600.0 { 1.0 } else { 0.0 })
            .collect(),
    );
    px.push(
        wl.iter()
            .map(|&l| (0.05 * (-((l - 550.0) / 20.0).powi(2)).exp()) as f32)
            .collect(),
    );
    let file = dir.path("reference.exr");
    write_exr(
        &file,
        4,
        channels("S0", &nm_names(&wl), &px),
        &[("emissiveUnits", "W.m^-2.sr^-1")],
    );
    let (got, said) = to_rgb(&file, XYZ);
    assert!(said.contains("reference units"), "{said}");
    let err = worst(&got, &reference(&file));
    assert!(err < 1e-5, "to-rgb differs from the reference by {err}");
}

#[test]
fn uneven_grids_coarse_grids_and_other_units_read_as_the_reference_reads_them() {
    let dir = Scratch::new("layout-grids");
    let uneven = [
        380.0, 400.0, 450.5, 455.0, 520.0, 600.0, 610.25, 700.0, 780.0,
    ];
    let coarse: Vec<f64> = (0..=6).map(|i| 400.0 + 50.0 * i as f64).collect();
    let hz: Vec<f64> = (0..=20).map(|i| 380.0 + 20.0 * i as f64).collect();
    let cases = [
        (
            "uneven.exr",
            "T",
            uneven.to_vec(),
            nm_names(&uneven),
            0.05,
            0.95,
        ),
        (
            "coarse_um.exr",
            "T",
            coarse.clone(),
            coarse
                .iter()
                .map(|l| format!("{}um", num(l / 1000.0)))
                .collect(),
            0.05,
            0.95,
        ),
        (
            "emissive_thz.exr",
            "S0",
            hz.clone(),
            // ν = c / λ, in THz.
            hz.iter()
                .map(|l| format!("{}THz", num(299_792_458.0 / (l * 1e-9) / 1e12)))
                .collect(),
            0.0,
            3.0,
        ),
    ];
    for (name, prefix, wl, names, lo, hi) in cases {
        let file = dir.path(name);
        let px = spectra(&wl, 6, lo, hi);
        write_exr(&file, 3, channels(prefix, &names, &px), &[]);
        let (got, _) = to_rgb(&file, XYZ);
        let err = worst(&got, &reference(&file));
        assert!(
            err < 5e-3,
            "{name}: to-rgb differs from the reference by {err}"
        );
    }
    let info = Cmd::new(["info", dir.path("uneven.exr").to_str().unwrap()]).run();
    assert!(
        info.ok()
            .contains("9, 380 to 780 nm, uneven: 380, 400, 450.5, 455"),
        "{}",
        info.stdout
    );
    let info = Cmd::new(["info", dir.path("coarse_um.exr").to_str().unwrap()]).run();
    assert!(info.ok().contains("every 50 nm"), "{}", info.stdout);
    assert!(!info.stdout.contains("colour space"), "{}", info.stdout);
}

#[test]
fn bispectral_files_use_the_whole_reradiation_matrix_and_rgb_beside_is_reported() {
    let dir = Scratch::new("layout-bispectral");
    let wl: Vec<f64> = (0..=6).map(|i| 400.0 + 50.0 * i as f64).collect();
    let n = wl.len();
    let diagonal = spectra(&wl, 4, 0.1, 0.6);
    // Re-radiation from band i to every longer band o: 0.02·(1 + i) per pixel p scaled.
    let rerad = |p: usize, i: usize, o: usize| 0.01 * (1 + i + p) as f32 / (1 + o - i) as f32;
    let mut ch = channels("T", &nm_names(&wl), &diagonal);
    for i in 0..n {
        for o in i + 1..n {
            ch.push((
                format!("T.{}nm.{}nm", num(wl[i]), num(wl[o])),
                (0..4).map(|p| rerad(p, i, o)).collect(),
            ));
        }
    }
    // An RGB image beside the spectra, as the reference's own writer stores one.
    for c in ["R", "G", "B"] {
        ch.push((c.into(), vec![7.0; 4]));
    }
    let file = dir.path("bispectral.exr");
    write_exr(&file, 2, ch, &[]);

    let info = Cmd::new(["info", file.to_str().unwrap()]).run();
    let text = info.ok();
    assert!(text.contains("bispectral"), "{text}");
    assert!(text.contains("21 channels T.λi.λo"), "{text}");
    assert!(text.contains("B, G, R (not used for colour)"), "{text}");
    let json: serde_json::Value = Cmd::new(["info", "--json", file.to_str().unwrap()])
        .ok()
        .json();
    assert_eq!(json["spectral"]["reradiation"], 21);
    assert_eq!(json["spectral"]["kind"], "bispectral");

    // Under D65 each band o sends back T(o)·I(o) + Σ_i<o T(i→o)·I(i): the reflectance that
    // sends back as much is T(o) + Σ T(i→o)·I(i)/I(o). D65 at 50 nm steps, CIE 15:2018.
    let d65 = [
        82.7549, 117.008, 109.354, 104.046, 90.0062, 80.0268, 71.6091,
    ];
    let effective: Vec<Vec<f32>> = (0..4)
        .map(|p| {
            (0..n)
                .map(|o| {
                    diagonal[p][o]
                        + (0..o)
                            .map(|i| rerad(p, i, o) * (d65[i] / d65[o]) as f32)
                            .sum::<f32>()
                })
                .collect()
        })
        .collect();
    let plain = dir.path("effective.exr");
    write_exr(&plain, 2, channels("T", &nm_names(&wl), &effective), &[]);
    let (got, said) = to_rgb(&file, XYZ);
    assert!(said.contains("with 21 re-radiation channels"), "{said}");
    assert!(said.contains("not used: B, G, R"), "{said}");
    let err = worst(&got, &reference(&plain));
    eprintln!("bispectral: to-rgb against the reference of its effective reflectance: {err:.1e}");
    assert!(err < 5e-3, "bispectral differs from the reference by {err}");
    // Not the diagonal alone: the re-radiated light is there.
    let diag = dir.path("diagonal.exr");
    write_exr(&diag, 2, channels("T", &nm_names(&wl), &diagonal), &[]);
    let (alone, _) = to_rgb(&diag, XYZ);
    assert!(worst(&alone, &got) > 0.05, "re-radiation left out");

    // preview cannot follow bounces through re-radiation, and says so.
    Cmd::new([
        "preview",
        file.to_str().unwrap(),
        "-o",
        dir.path("p.png").to_str().unwrap(),
    ])
    .fails(1, &["bispectral", "to-rgb"]);
}

#[test]
fn polarised_files_are_read_by_their_s0() {
    let dir = Scratch::new("layout-polarised");
    let wl: Vec<f64> = (0..=30).map(|i| 400.0 + 10.0 * i as f64).collect();
    let s0 = spectra(&wl, 4, 0.0, 2.0);
    let mut ch = channels("S0", &nm_names(&wl), &s0);
    for k in 1..=3 {
        ch.extend(channels(
            &format!("S{k}"),
            &nm_names(&wl),
            &spectra(&wl, 4, -1.0, 1.0),
        ));
    }
    let file = dir.path("polarised.exr");
    write_exr(&file, 2, ch, &[("emissiveUnits", "W.m^-2.sr^-1")]);
    let text = Cmd::new(["info", file.to_str().unwrap()]).ok().stdout;
    assert!(text.contains("emissive, polarised"), "{text}");
    assert!(text.contains("S3: 31 bands"), "{text}");
    let (got, said) = to_rgb(&file, XYZ);
    assert!(said.contains("S0 used, S1–S3 not"), "{said}");
    let err = worst(&got, &reference(&file));
    assert!(err < 1e-5, "{err}");
}

/// S0 of the pixel (x, y) of a spectral file.
fn s0(file: &Path, x: usize, y: usize) -> Vec<f32> {
    let img = specconv_exr::read(file).unwrap();
    img.bands.iter().map(|b| b[y * img.width + x]).collect()
}

#[test]
fn each_emission_convention_round_trips_and_normalised_is_flat() {
    let dir = Scratch::new("layout-units");
    let input = testdata("sky.hdr");
    let want = xyz_list(&python(&["--rec709", input.to_str().unwrap()]));
    let mut at = Vec::new();
    for units in ["reference", "normalised", "photometric"] {
        let out = dir.path(&format!("{units}.exr"));
        Cmd::new([
            "--ocio",
            "aces",
            "--emissive",
            "--emission-units",
            units,
            "--colorspace",
            REC709,
            "-d",
            "float",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
        ])
        .ok();
        let attrs = specconv_exr::read_attributes(&out).unwrap();
        assert!(attrs.contains(&("specconvEmissionUnits".into(), units.into())));
        let (back, said) = to_rgb(&out, XYZ);
        assert!(said.contains(&format!("{units} units (recorded")), "{said}");
        let err = worst(&back, &want);
        assert!(err < 1e-5, "{units}: round trip {err}");
        at.push(s0(&out, 10, 20));
    }
    // The factors between the conventions: ∫ ȳ dλ over 380–730 nm (the reference's sum at
    // 1 nm of colour-science's table), and 683 lm/W.
    let dense = python(&[dir.path("reference.exr").to_str().unwrap()]);
    assert_eq!(dense["kind"], "S0");
    let ybar_integral = {
        let flat = dir.path("flat_reference.exr");
        let wl = specconv_colour::Grid::PAPER.wavelengths();
        write_exr(
            &flat,
            1,
            channels("S0", &nm_names(&wl), &[vec![1.0; wl.len()]]),
            &[],
        );
        reference(&flat)[0][1]
    };
    let mut compared = 0;
    for ((r, n), p) in at[0].iter().zip(&at[1]).zip(&at[2]) {
        // A band the spectrum does not emit in is zero in every convention (the default
        // model's spectrum of this pixel has such bands): no factor to read there.
        if *r == 0.0 {
            assert_eq!((*n, *p), (0.0, 0.0));
            continue;
        }
        compared += 1;
        let normalised = *n as f64 / *r as f64;
        let photometric = *r as f64 / *p as f64;
        assert!(
            (normalised / ybar_integral - 1.0).abs() < 1e-5,
            "{normalised}"
        );
        assert!((photometric / 683.0 - 1.0).abs() < 1e-5, "{photometric}");
    }
    assert!(compared > at[0].len() / 2, "{compared} bands compared");
    eprintln!("normalised / reference = ∫ȳ dλ (380–730 nm) = {ybar_integral:.4}");

    // The flat check: S0 = 1 everywhere is Y = 1 when normalised, recorded or (an older
    // specconv file) implied; Y = ∫ ȳ dλ in the reference convention.
    let wl: Vec<f64> = (0..=40).map(|i| 380.0 + 10.0 * i as f64).collect();
    let flat = vec![vec![1.0f32; wl.len()]];
    for (name, attrs, y) in [
        (
            "recorded.exr",
            vec![("specconvEmissionUnits", "normalised")],
            1.0,
        ),
        (
            "older.exr",
            vec![("specconvSettings", "model=built-in")],
            1.0,
        ),
        ("other.exr", vec![], 0.0),
    ] {
        let file = dir.path(name);
        write_exr(&file, 1, channels("S0", &nm_names(&wl), &flat), &attrs);
        let (got, _) = to_rgb(&file, XYZ);
        let want = if y == 0.0 { reference(&file)[0][1] } else { y };
        assert!(
            (got[0][1] - want).abs() < 1e-5 * want,
            "{name}: Y = {}",
            got[0][1]
        );
    }
}

#[test]
fn outputs_no_command_writes_are_refused_with_one_line_and_nothing_written() {
    let dir = Scratch::new("layout-names");
    let png = testdata("srgb8.png");
    let spectral = dir.path("s.exr");
    Cmd::convert(&png, &spectral).ok();
    let s = spectral.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec![png.to_str().unwrap(), "-"],
        vec![png.to_str().unwrap(), "out.png"],
        vec!["convert", png.to_str().unwrap(), "out.tif"],
        vec!["to-rgb", s, "-"],
        vec!["to-rgb", s, "out.png"],
        vec!["preview", s, "-o", "-"],
        vec!["preview", s, "-o", "out.exr"],
        vec!["train", "--spectra", "x.csv", "-o", "model.txt"],
    ];
    for args in cases {
        // In the scratch directory: `-` would be a file there.
        let out = Cmd::new(&args).current_dir(&dir.0).refused(&dir, 2, &[]);
        let lines: Vec<&str> = out.stderr.lines().collect();
        assert!(
            lines[0].contains("give an output file ending in")
                || lines[0].contains("name the file"),
            "{args:?}: {}",
            out.stderr
        );
    }
}

#[test]
fn to_rgb_adds_no_channel() {
    let dir = Scratch::new("layout-channels");
    for (input, want) in [
        ("srgb8.png", vec!["B", "G", "R"]),
        ("float_tiled_alpha.exr", vec!["A", "B", "G", "R"]),
    ] {
        let spectral = dir.path("s.exr");
        let back = dir.path("back.exr");
        Cmd::new([
            "--force",
            testdata(input).to_str().unwrap(),
            spectral.to_str().unwrap(),
        ])
        .ok();
        Cmd::new([
            "to-rgb",
            "--force",
            spectral.to_str().unwrap(),
            back.to_str().unwrap(),
        ])
        .ok();
        let meta = exr::meta::MetaData::read_from_file(&back, false).unwrap();
        let names: Vec<String> = meta.headers[0]
            .channels
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(names, want, "{input}");
    }
}
