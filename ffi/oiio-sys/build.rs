//! Compiles the C++ shim and links it to the system OpenImageIO found by pkg-config.

fn main() {
    specconv_shim_build::OIIO.build();
}
