//! Bad inputs and bad requests give errors that say what is wrong, never a panic or abort.

use std::path::{Path, PathBuf};

use specconv_oiio::{Error, ImageReader, Region};

fn testdata(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata")
        .join(rel)
}

#[test]
fn missing_file_is_not_found() {
    let err = ImageReader::open(testdata("images/no_such_file.exr")).unwrap_err();
    assert!(matches!(err, Error::NotFound { .. }), "{err:?}");
    assert!(
        err.to_string().contains("no_such_file.exr: no such file"),
        "{err}"
    );
}

#[test]
fn directory_is_refused() {
    let err = ImageReader::open(testdata("images")).unwrap_err();
    assert!(err.to_string().contains("directory"), "{err}");
}

#[test]
fn unknown_format_and_non_images_fail_to_open() {
    for name in ["broken/unknown.format", "broken/not_an_image.png"] {
        let err = ImageReader::open(testdata(name)).unwrap_err();
        assert!(matches!(err, Error::Open { .. }), "{name}: {err:?}");
        assert!(
            err.to_string().contains("cannot be read as an image"),
            "{err}"
        );
    }
}

#[test]
fn truncated_files_fail_on_open_or_read() {
    for name in ["broken/truncated.exr", "broken/truncated.png"] {
        let result = ImageReader::open(testdata(name)).and_then(|mut r| r.read_level(0));
        let err = result.expect_err(name);
        assert!(
            matches!(err, Error::Open { .. } | Error::Read { .. }),
            "{name}: {err:?}"
        );
        assert!(
            err.to_string().contains(name.rsplit('/').next().unwrap()),
            "{err}"
        );
    }
}

#[test]
fn out_of_range_requests_are_refused() {
    let mut tx = ImageReader::open(testdata("images/srgba8.tx")).unwrap();
    let err = tx.read_level(6).unwrap_err();
    assert!(
        err.to_string()
            .contains("MIP level 6 does not exist; the file has 6"),
        "{err}"
    );
    let err = tx.read_tile(0, 4, 0).unwrap_err();
    assert!(
        err.to_string()
            .contains("outside MIP level 0, which has 4x3 tiles"),
        "{err}"
    );
    let err = tx.read_scanlines(0, 40..48).unwrap_err();
    assert!(matches!(err, Error::InvalidRequest { .. }), "{err:?}");
    let err = tx
        .read_region(
            0,
            Region {
                x0: 10,
                y0: 0,
                x1: 10,
                y1: 5,
            },
        )
        .unwrap_err();
    assert!(matches!(err, Error::InvalidRequest { .. }), "{err:?}");

    let mut scan = ImageReader::open(testdata("images/half_scanline.exr")).unwrap();
    let err = scan.read_tile(0, 0, 0).unwrap_err();
    assert!(err.to_string().contains("stored as scanlines"), "{err}");
}

#[test]
fn the_runtime_openimageio_is_2_4_or_later() {
    // Loads OpenImageIO if no test of this binary has yet.
    let (major, minor, _) = specconv_oiio::oiio_version().unwrap();
    assert!((major, minor) >= (2, 4), "{major}.{minor}");
}
