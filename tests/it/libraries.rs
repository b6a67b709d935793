//! OpenImageIO's ≈260 libraries are loaded only by a command that reads an image (issue 19):
//! the binary has no link-time dependency on them, `--version`, `train` and `eval` never load
//! them, and a conversion, which does, still works.

use crate::convert::testdata;
use crate::runner::*;

/// The libraries the dynamic loader loaded while `cmd` ran (`LD_DEBUG=files`), after checking
/// that it succeeded.
fn loaded(cmd: Cmd) -> Vec<String> {
    let out = cmd.env("LD_DEBUG", "files").run();
    assert_eq!(out.code, 0, "{}", out.stderr);
    let mut libs: Vec<String> = out
        .stderr
        .lines()
        .filter_map(|l| l.split_once("file=")?.1.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    libs.sort();
    libs.dedup();
    assert!(
        libs.iter().any(|l| l.starts_with("libc.so")),
        "LD_DEBUG=files said nothing of libc: is this glibc's loader?\n{}",
        out.stderr
    );
    libs
}

fn openimageio(libs: &[String]) -> Vec<&String> {
    libs.iter()
        .filter(|l| l.contains("libOpenImageIO"))
        .collect()
}

#[test]
fn the_binary_does_not_link_openimageio() {
    let ldd = tool("ldd", &[binary().to_str().unwrap()]);
    assert!(ldd.contains("libc.so"), "{ldd}");
    assert!(
        !ldd.contains("libOpenImageIO"),
        "specconv depends on OpenImageIO when it starts again; only ffi/oiio-sys's embedded \
         shim may:\n{ldd}"
    );
}

#[test]
fn commands_that_read_no_image_do_not_load_openimageio() {
    let dir = Scratch::new("libraries-no-image");
    let model = dir.path("cc.json");
    for cmd in [
        Cmd::new(["--version"]),
        Cmd::train(colorchecker())
            .args(["--min-cluster-size", "4", "-o"])
            .arg(&model),
        Cmd::eval(colorchecker()),
    ] {
        let libs = loaded(cmd.clone());
        let oiio = openimageio(&libs);
        assert!(oiio.is_empty(), "{cmd:?} loaded {oiio:?}");
    }
    assert!(model.is_file());
}

#[test]
fn a_conversion_loads_openimageio_and_still_works() {
    let dir = Scratch::new("libraries-convert");
    let output = dir.path("out.exr");
    let libs = loaded(Cmd::convert(testdata("srgb8.png"), &output));
    // The check above sees OpenImageIO where it is loaded.
    assert!(!openimageio(&libs).is_empty(), "{libs:?}");
    let img = specconv_exr::read(&output).unwrap();
    assert_eq!(img.bands.len(), 36);
    assert!(img.bands.iter().flatten().all(|v| v.is_finite()));
}
