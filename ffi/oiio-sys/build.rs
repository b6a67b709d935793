//! Builds the C++ shim as a shared object linked to the system OpenImageIO found by
//! pkg-config, `$OUT_DIR/libspecconv_oiio.so`, and copies it to where cargo puts programs
//! (`target/<profile>/`, its `deps/` and `examples/`: three folders up from OUT_DIR), where
//! `src/lib.rs` finds it beside the program at the first image read. The crate itself links
//! nothing of OpenImageIO. See `specconv_shim_build::Shim::build`.

fn main() {
    specconv_shim_build::OIIO.build();
}
