//! Every pixel of every testdata image and MIP level, read through the wrapper, equals what
//! `oiiotool --dumpdata` prints (openimageio-tools must be on PATH).

use std::path::{Path, PathBuf};
use std::process::Command;

use specconv_oiio::{ImageReader, PixelFormat};

fn images() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/images");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}; run testdata/make.sh", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(files.len() >= 10, "testdata/images looks incomplete");
    files
}

fn oiiotool(args: &[&str]) -> String {
    let out = Command::new("oiiotool")
        .args(args)
        .output()
        .expect("oiiotool not found on PATH (Debian: openimageio-tools)");
    assert!(
        out.status.success(),
        "oiiotool {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// One dumped pixel: its coordinates, the integer code values (integer files only) and the
/// float values.
struct Dumped {
    x: u32,
    y: u32,
    codes: Option<Vec<u64>>,
    values: Vec<f64>,
}

/// Parses lines like `Pixel (3, 0): 0 9 9 252 (0 0.035 0.035 0.988)` or
/// `Pixel (1, 0): -0.210571289 0.102661133 0.144165039`.
fn parse_dump(text: &str) -> Vec<Dumped> {
    text.lines()
        .filter_map(|line| line.trim().strip_prefix("Pixel ("))
        .map(|rest| {
            let (xy, vals) = rest.split_once("):").unwrap();
            let (x, y) = xy.split_once(", ").unwrap();
            let nums = |s: &str| -> Vec<f64> {
                s.split_whitespace().map(|v| v.parse().unwrap()).collect()
            };
            let (codes, values) = match vals.split_once('(') {
                Some((codes, floats)) => (
                    Some(
                        codes
                            .split_whitespace()
                            .map(|v| v.parse().unwrap())
                            .collect(),
                    ),
                    nums(floats.trim_end_matches(')')),
                ),
                None => (None, nums(vals)),
            };
            Dumped {
                x: x.parse().unwrap(),
                y: y.parse().unwrap(),
                codes,
                values,
            }
        })
        .collect()
}

fn compare(
    file: &Path,
    level: usize,
    format: &PixelFormat,
    dump: &[Dumped],
    got: &specconv_oiio::Pixels,
) {
    assert_eq!(
        dump.len(),
        (got.width * got.height) as usize,
        "{} level {level}: pixel count differs from oiiotool",
        file.display()
    );
    let max_code = match format {
        PixelFormat::U8 => 255.0,
        PixelFormat::U16 => 65535.0,
        _ => 0.0,
    };
    for d in dump {
        let ours = got.pixel(d.x, d.y);
        assert_eq!(ours.len(), d.values.len());
        for (c, (&a, &b)) in ours.iter().zip(&d.values).enumerate() {
            // oiiotool prints floats to 9 decimals, integer files' floats to 8 digits.
            let tol = if d.codes.is_some() { 1e-7 } else { 1e-9 };
            assert!(
                (a as f64 - b).abs() <= tol,
                "{} level {level} pixel ({}, {}) channel {c}: wrapper {a}, oiiotool {b}",
                file.display(),
                d.x,
                d.y
            );
            if let Some(codes) = &d.codes {
                assert_eq!(
                    (a as f64 * max_code).round() as u64,
                    codes[c],
                    "{} pixel ({}, {}) channel {c}: code value differs",
                    file.display(),
                    d.x,
                    d.y
                );
            }
        }
    }
}

#[test]
fn every_file_and_level_matches_oiiotool_dumpdata() {
    let tmp = std::env::temp_dir().join(format!("specconv-oiio-dump-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let mut levels_checked = 0;
    for file in images() {
        let mut reader = ImageReader::open(&file).unwrap();
        let info = reader.info().clone();
        let f = file.to_str().unwrap();
        for level in 0..info.levels.len() {
            let got = reader.read_level(level).unwrap();
            // The reader keeps straight alpha straight; so does oiiotool with this hint.
            let straight = ["--iconfig", "oiio:UnassociatedAlpha", "1"];
            let dump = if level == 0 {
                oiiotool(&[&straight[..], &["--dumpdata", f]].concat())
            } else {
                // --dumpdata only prints the top level; extract the level as float first.
                let out = tmp.join(format!("level{level}.exr"));
                let o = out.to_str().unwrap();
                oiiotool(
                    &[
                        &straight[..],
                        &[f, "--selectmip", &level.to_string(), "-d", "float", "-o", o],
                    ]
                    .concat(),
                );
                oiiotool(&["--dumpdata", o])
            };
            let format = if level == 0 {
                info.pixel_format().clone()
            } else {
                PixelFormat::Float
            };
            compare(&file, level, &format, &parse_dump(&dump), &got);
            levels_checked += 1;
        }
    }
    std::fs::remove_dir_all(&tmp).ok();
    // 11 single-level files and two .tx files with 6 levels each.
    assert!(levels_checked >= 20, "only {levels_checked} levels checked");
}

#[test]
fn header_matches_oiiotool_info() {
    let mut straight = 0;
    for file in images() {
        let reader = ImageReader::open(&file).unwrap();
        let info = reader.info();
        let text = oiiotool(&["--info", "-v", file.to_str().unwrap()]);
        let first = text.lines().find(|l| l.contains(" channel, ")).unwrap();
        // "name :   61 x   47, 4 channel, uint8 png"
        let dims = format!(
            "{:>4} x {:>4}, {} channel, {} {}",
            info.width(),
            info.height(),
            info.channels.len(),
            info.pixel_format(),
            info.format_name
        );
        assert!(
            first.contains(&dims),
            "{}: oiiotool says {first:?}, wrapper {dims:?}",
            file.display()
        );
        let names: Vec<_> = info.channels.iter().map(|c| c.name.as_str()).collect();
        assert!(
            text.contains(&format!("channel list: {}", names.join(", "))),
            "{}",
            file.display()
        );
        match info.tile_size() {
            Some((w, h)) => assert!(text.contains(&format!("tile size: {w} x {h}"))),
            None => assert!(!text.contains("tile size:")),
        }
        if info.levels.len() > 1 {
            let sizes: Vec<_> = info
                .levels
                .iter()
                .map(|l| format!("{}x{}", l.width, l.height))
                .collect();
            assert!(
                text.contains(&format!("MIP-map levels: {}", sizes.join(" "))),
                "{}",
                file.display()
            );
        }
        match &info.declared_color_space {
            Some(cs) => assert!(text.contains(&format!("oiio:ColorSpace: \"{cs}\""))),
            None => assert!(!text.contains("oiio:ColorSpace:")),
        }
        // Straight alpha, as oiiotool sees it when asked to keep it straight.
        let hinted = oiiotool(&[
            "--iconfig",
            "oiio:UnassociatedAlpha",
            "1",
            "--info",
            "-v",
            file.to_str().unwrap(),
        ]);
        assert_eq!(
            info.unassociated_alpha,
            info.alpha_channel.is_some() && hinted.contains("oiio:UnassociatedAlpha: 1"),
            "{}",
            file.display()
        );
        straight += usize::from(info.unassociated_alpha);
        // The same attribute through the numeric reader.
        let flag = reader.numeric_attribute("oiio:UnassociatedAlpha").unwrap();
        assert_eq!(
            flag.is_some(),
            hinted.contains("oiio:UnassociatedAlpha:"),
            "{}",
            file.display()
        );
    }
    // srgba8.png and rgba16.png.
    assert_eq!(straight, 2);
}
