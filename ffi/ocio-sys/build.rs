//! Compiles the C++ shim and links it to the system OpenColorIO found by pkg-config.

use std::process::exit;

const LIBRARY: &str = "OpenColorIO";
const MIN_VERSION: &str = "2.1";
const DEBIAN_PACKAGE: &str = "libopencolorio-dev";

fn main() {
    println!("cargo:rerun-if-changed=shim/specconv_ocio.h");
    println!("cargo:rerun-if-changed=shim/specconv_ocio.cpp");

    let lib = match pkg_config::Config::new()
        .atleast_version(MIN_VERSION)
        .probe(LIBRARY)
    {
        Ok(lib) => lib,
        Err(e) => {
            // A bare pkg-config failure does not say what to install; this does.
            eprintln!(
                "error: {LIBRARY} >= {MIN_VERSION} was not found through pkg-config.\n\
                 On Debian/Ubuntu install it with:\n    \
                 sudo apt-get install {DEBIAN_PACKAGE} pkg-config\n\
                 Elsewhere, point PKG_CONFIG_PATH at the directory holding {LIBRARY}.pc.\n\
                 pkg-config said: {e}"
            );
            exit(1);
        }
    };
    println!("cargo:version={}", lib.version);

    let mut build = cc::Build::new();
    build
        .cpp(true)
        .std("c++17")
        .file("shim/specconv_ocio.cpp")
        .include("shim")
        .warnings(true);
    for dir in &lib.include_paths {
        build.include(dir);
    }
    for (name, value) in &lib.defines {
        build.define(name, value.as_deref());
    }
    build.compile("specconv_ocio_shim");
}
