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
