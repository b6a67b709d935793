//! Compiles the C++ shim and links it to the system OpenColorIO found by pkg-config.

fn main() {
    specconv_shim_build::Shim {
        name: "ocio",
        library: "OpenColorIO",
        min_version: "2.1",
        debian_package: "libopencolorio-dev",
    }
    .build();
}
