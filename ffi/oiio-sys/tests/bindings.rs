//! Fails when the committed `src/bindings.rs` no longer matches what bindgen makes of the
//! shim header. Run `ffi/regenerate-bindings.sh` (sets SPECCONV_REGENERATE_BINDINGS=1) to
//! rewrite them.

#[test]
fn committed_bindings_match_the_header() {
    specconv_shim_build::OIIO.check_bindings(std::path::Path::new(env!("CARGO_MANIFEST_DIR")));
}
