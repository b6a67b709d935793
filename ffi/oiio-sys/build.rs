//! Builds the C++ shim as a shared object linked to the system OpenImageIO found by
//! pkg-config, `$OUT_DIR/libspecconv_oiio.so`, which `src/lib.rs` embeds. The crate itself
//! links nothing of OpenImageIO.

fn main() {
    specconv_shim_build::OIIO.build();
}
