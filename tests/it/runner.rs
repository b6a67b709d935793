//! The test kit's command line and scratch directory ([`specconv_testkit::cmd`]), and the
//! measured spectra the tests give the binary.

pub use specconv_testkit::cmd::*;
use std::path::PathBuf;

/// `../shared` beside the checkout (or `$SPECCONV_SHARED`), joined with `rel`, which must exist.
pub fn shared(rel: &str) -> PathBuf {
    let p = specconv_testkit::shared().join(rel);
    assert!(
        p.exists(),
        "{} not found: tests need ../shared beside the checkout",
        p.display()
    );
    p
}

pub fn munsell() -> PathBuf {
    shared(&format!("spectra/{}", specconv_testkit::MUNSELL))
}

pub fn colorchecker() -> PathBuf {
    shared(&format!("spectra/{}", specconv_testkit::COLORCHECKER))
}

/// What specconv keeps in an output folder on purpose: a farm job's folder, and the record of
/// what `asset` wrote (`specconv_asset::record::RECORD`).
pub const KEPT: [&str; 2] = [".specconv-farm", ".specconv-asset.json"];

/// No temporary file (`.NAME.specconv-….tmp`, or any `.tmp`) anywhere under `dir`.
#[track_caller]
pub fn no_temporaries(dir: &std::path::Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            no_temporaries(&p);
        }
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            !(name.ends_with(".tmp")
                || (name.contains(".specconv-") && !KEPT.contains(&name.as_str()))),
            "left behind: {}",
            p.display()
        );
    }
}

/// A `size`² image of uniform noise in (0, 1), written by oiiotool in sample type `data_type`
/// (`uint8`, `half`, …) to `path` (its extension says the format).
pub fn noise(path: &std::path::Path, size: usize, data_type: &str) {
    tool(
        "oiiotool",
        &[
            "--pattern",
            "noise:min=0:max=1",
            &format!("{size}x{size}"),
            "3",
            "-d",
            data_type,
            "-o",
            path.to_str().unwrap(),
        ],
    );
}
