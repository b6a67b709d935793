//! Compiles the C++ shim and links it to the system OpenImageIO found by pkg-config.

fn main() {
    specconv_shim_build::Shim {
        name: "oiio",
        library: "OpenImageIO",
        min_version: "2.4",
        debian_package: "libopenimageio-dev",
    }
    .build();
}
