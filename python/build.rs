//! Puts specconv's OpenImageIO shim, which oiio-sys's build script linked, in the package folder
//! `specconv/`, where the extension module goes too: `maturin develop` installs the package in
//! place from that folder, and `maturin build` (and `pip install ./python`) put it in the wheel
//! (pyproject.toml names the shim, which .gitignore would otherwise keep out). At the first image
//! read, oiio-sys opens the shim beside the module that holds its code (docs/install.md).

use std::path::{Path, PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let built = PathBuf::from(
        std::env::var_os("DEP_SPECCONV_OIIO_SHIM")
            .expect("oiio-sys (links = \"specconv_oiio\") says where it built the shim"),
    );
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let installed = dir
        .join("specconv")
        .join(built.file_name().expect("the shim's path names a file"));
    // The copy keeps the built object's time, so that these two lines rerun this script when
    // either is rebuilt or removed, and only then.
    specconv_shim_build::copy_replacing(&built, &installed);
    println!("cargo:rerun-if-changed={}", built.display());
    println!("cargo:rerun-if-changed={}", Path::new(&installed).display());
}
