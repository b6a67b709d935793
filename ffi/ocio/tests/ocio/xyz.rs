//! XYZ from the processor equals what `ocioconvert` (opencolorio-tools) computes with the
//! same config, and white lands on OCIO's D65.

use std::path::{Path, PathBuf};
use std::process::Command;

use specconv_ocio::{Config, XyzRoute};
use specconv_oiio::ImageReader;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn aces_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("config/cg.ocio")
}

/// `|a - b| <= tol · max(1, |b|)`: absolute near zero, relative for the large values that
/// log encodings (ACEScct) decode to.
fn close(a: f32, b: f32, tol: f64) -> bool {
    (a as f64 - b as f64).abs() <= tol * (b as f64).abs().max(1.0)
}

#[test]
fn xyz_matches_ocioconvert_for_the_listed_spaces() {
    // Values from -0.4 to 4.4: negatives, mid-greys and over-range values.
    let input = root().join("testdata/images/float_scanline.exr");
    let mut reader = ImageReader::open(&input).unwrap();
    let source = reader.read_level(0).unwrap();
    assert_eq!(source.channels, 3);
    let config = Config::resolve_with_env(Some("aces"), None).unwrap();
    let tmp = std::env::temp_dir().join(format!("specconv-ocio-xyz-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    for space in [
        "sRGB - Texture",
        "ACEScg",
        "ACES2065-1",
        "ACEScct",
        "Linear Rec.2020",
    ] {
        let processor = config.processor_to_xyz(space).unwrap();
        assert_eq!(
            processor.route(),
            &XyzRoute::CieXyzD65Interchange("CIE-XYZ-D65".into())
        );
        let mut ours = source.data.clone();
        processor.apply_rgb(&mut ours).unwrap();

        let out = tmp.join("xyz.exr");
        let status = Command::new("ocioconvert")
            .env("OCIO", aces_file())
            .arg(&input)
            .arg(space)
            .arg(&out)
            .arg("cie_xyz_d65_interchange")
            .output()
            .expect("ocioconvert not found on PATH (Debian: opencolorio-tools)");
        assert!(
            status.status.success(),
            "ocioconvert failed for {space}: {}",
            String::from_utf8_lossy(&status.stderr)
        );
        let theirs = ImageReader::open(&out).unwrap().read_level(0).unwrap();
        assert_eq!(theirs.data.len(), ours.len());
        let mut worst = 0f64;
        for (i, (&a, &b)) in ours.iter().zip(&theirs.data).enumerate() {
            assert!(
                close(a, b, 1e-6),
                "{space}: value {i}: ours {a}, ocioconvert {b}"
            );
            worst = worst.max((a as f64 - b as f64).abs() / (b as f64).abs().max(1.0));
        }
        eprintln!("{space}: worst difference from ocioconvert {worst:e}");
    }
    std::fs::remove_dir_all(&tmp).ok();
}

#[test]
fn srgb_texture_white_is_d65() {
    let config = Config::builtin_aces().unwrap();
    let xyz = config
        .processor_to_xyz("sRGB - Texture")
        .unwrap()
        .convert([1.0, 1.0, 1.0])
        .unwrap();
    // OCIO's D65 is BT.709's xy (0.3127, 0.3290): X = x/y, Z = (1 - x - y)/y.
    let d65 = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];
    for c in 0..3 {
        assert!(close(xyz[c], d65[c] as f32, 1e-6), "{xyz:?} vs {d65:?}");
    }
    // The CIE 15 tabulated D65 white (0.9505, 1.0000, 1.0888) differs in Z by 2.6e-4
    // because its chromaticity is (0.31271, 0.32902); X and Y agree to 1e-4.
    assert!((xyz[0] - 0.9505).abs() < 1e-4 && (xyz[1] - 1.0).abs() < 1e-4);
    assert!((xyz[2] - 1.0888).abs() < 3e-4);
}

#[test]
fn every_rgb_space_maps_white_to_the_same_d65() {
    let config = Config::builtin_aces().unwrap();
    let reference = config
        .processor_to_xyz("ACES2065-1")
        .unwrap()
        .convert([1.0; 3])
        .unwrap();
    for space in [
        "ACEScg",
        "Linear Rec.709 (sRGB)",
        "Linear Rec.2020",
        "Linear P3-D65",
        "sRGB - Texture",
    ] {
        let xyz = config
            .processor_to_xyz(space)
            .unwrap()
            .convert([1.0; 3])
            .unwrap();
        for c in 0..3 {
            assert!(
                close(xyz[c], reference[c], 1e-6),
                "{space}: {xyz:?} vs {reference:?}"
            );
        }
    }
    // ACEScct encodes linear 1.0 as (log2(1) + 9.72) / 17.52.
    let one = 9.72f32 / 17.52;
    let xyz = config
        .processor_to_xyz("ACEScct")
        .unwrap()
        .convert([one; 3])
        .unwrap();
    for c in 0..3 {
        assert!(
            close(xyz[c], reference[c], 1e-5),
            "ACEScct: {xyz:?} vs {reference:?}"
        );
    }
}

#[test]
fn aces_interchange_route_agrees_with_the_xyz_role() {
    let only_aces =
        Config::from_file(root().join("testdata/ocio/aces_interchange_only.ocio")).unwrap();
    let via_aces = only_aces.processor_to_xyz("ACEScg").unwrap();
    assert_eq!(
        via_aces.route(),
        &XyzRoute::AcesInterchange("ACES2065-1".into())
    );
    let via_role = Config::builtin_aces()
        .unwrap()
        .processor_to_xyz("ACEScg")
        .unwrap();
    let mut pixels: Vec<f32> = (0..64).map(|i| (i as f32 - 8.0) * 0.07).collect();
    pixels.truncate(63);
    let mut a = pixels.clone();
    let mut b = pixels;
    via_aces.apply_rgb(&mut a).unwrap();
    via_role.apply_rgb(&mut b).unwrap();
    for (x, y) in a.iter().zip(&b) {
        assert!(close(*x, *y, 1e-6), "{x} vs {y}");
    }
}

#[test]
fn rgba_keeps_alpha_and_converts_rgb_like_rgb() {
    let p = Config::builtin_aces()
        .unwrap()
        .processor_to_xyz("sRGB - Texture")
        .unwrap();
    let mut rgba = [0.2f32, 0.5, 0.8, 0.25, 1.0, 0.0, 0.0, 1.0];
    p.apply_rgba(&mut rgba).unwrap();
    let rgb0 = p.convert([0.2, 0.5, 0.8]).unwrap();
    let rgb1 = p.convert([1.0, 0.0, 0.0]).unwrap();
    assert_eq!(&rgba[0..3], &rgb0);
    assert_eq!(&rgba[4..7], &rgb1);
    assert_eq!((rgba[3], rgba[7]), (0.25, 1.0));
    assert!(p.apply_rgb(&mut [0.0; 4]).is_err());
}

#[test]
fn processors_are_shared_across_threads() {
    let p = Config::builtin_aces()
        .unwrap()
        .processor_to_xyz("ACEScg")
        .unwrap();
    let expected = p.convert([0.18, 0.18, 0.18]).unwrap();
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| {
                for _ in 0..100 {
                    assert_eq!(p.convert([0.18, 0.18, 0.18]).unwrap(), expected);
                }
            });
        }
    });
}
