//! The options of a conversion as the library defines them ([`Key`]): `-u` rebuilds an output
//! when any option that changes what is written changes, and skips it when the same options
//! are given again. Every option the library marks as changing the output is tried; a new one
//! cannot be added without a case here (the `match` below must cover it).

use specconv_conversion::Key;
use specconv_testkit::cmd::{Cmd, Scratch};

/// A value other than the default, as command-line words.
fn changed(key: Key) -> Vec<String> {
    let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ocio");
    let cg = shared.join("cg-config-v1.0.0_aces-v1.3_ocio-v2.1.ocio");
    let words: &[&str] = match key {
        Key::Ocio => return vec!["--ocio".into(), cg.display().to_string()],
        Key::Colorspace => &["--colorspace", "sRGB - Texture"],
        Key::Alpha => &["--alpha", "straight"],
        Key::Subimage => &["--subimage", "0"],
        Key::Channels => &["--channels", "R,G,B,A"],
        Key::Method => &["--method", "smits1999"],
        Key::Model => &["--model", "paper"],
        Key::Blend => &["--blend", "0"],
        Key::Bounded => &["--unbounded"],
        Key::Bands => &["--bands", "400:700:10"],
        Key::Emission => &["--emissive"],
        Key::Layout => &["--layout", "compact"],
        Key::Sample => &["-d", "float"],
        Key::Rounding => &["--half-rounding", "colour"],
        Key::Compression => &["--compression", "piz"],
        Key::ZipLevel => &["--zip-level", "9"],
        Key::Tile => &["--tile", "32", "16"],
        Key::Mip => &["--mip", "0"],
        Key::Filter => &["--filter", "lanczos3"],
        Key::Resize => &["--resize"],
        Key::Wrap => &["--wrap", "periodic"],
        Key::NonFinite => &["--fixnan", "box3"],
        Key::ConstantDetect => &["--constant-color-detect=false"],
        Key::OpaqueDetect => &["--opaque-detect=false"],
        Key::Data => &["--data", "copy"],
        Key::StripMetadata => &["--strip-metadata"],
        // They change no byte: `-u` need not rebuild (strict writes all or nothing).
        Key::Threads | Key::Overwrite | Key::TableDir | Key::Strict => &[],
    };
    words.iter().map(|w| w.to_string()).collect()
}

#[test]
fn update_rebuilds_when_any_option_that_changes_the_output_changes() {
    let dir = Scratch::new("options-update");
    let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata/images/srgba8.png");
    let out = dir.path("out.exr");
    let status = |extra: &[String]| {
        // The built-in config unless the case names another ($OCIO is the runner's).
        let ocio: &[&str] = if extra.iter().any(|w| w == "--ocio") {
            &[]
        } else {
            &["--ocio", "aces"]
        };
        let json = Cmd::new(["-u", "--json"])
            .args(ocio)
            .args(extra)
            .arg(&input)
            .arg(&out)
            .ok()
            .json();
        json["status"].as_str().unwrap().to_string()
    };
    assert_eq!(status(&[]), "ok");
    assert_eq!(status(&[]), "skipped", "the same options again");
    let mut tried = 0;
    for key in Key::ALL {
        let words = changed(key);
        if !key.about().changes_output {
            assert!(words.is_empty(), "{key:?}");
            continue;
        }
        assert!(
            !words.is_empty(),
            "{key:?} changes the output: give it a case"
        );
        assert_eq!(status(&words), "ok", "-u skipped after {words:?}");
        assert_eq!(status(&words), "skipped", "-u rebuilt {words:?} twice");
        assert_eq!(status(&[]), "ok", "-u skipped the defaults after {words:?}");
        tried += 1;
    }
    assert!(tried >= 20, "{tried}");
}
