//! Compiles the C++ shim and links it to the system OpenColorIO found by pkg-config.

fn main() {
    specconv_shim_build::OCIO.build();
}
