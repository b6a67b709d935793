//! Issue 55, decision 5: the numbers the C header shares with the library are generated from
//! the library's constants ([`specconv_spectral::c_header`]) between two marker lines of
//! include/specconv_spectrum.h, written there by `cargo run -p specconv-dev -- generate`
//! (whose `--check` fails when the header is stale).

use specconv_spectral::c_header::shared;

fn header_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../include/specconv_spectrum.h")
}

/// Each generated name is defined once in the whole header and used by its code: no second
/// copy of a number beside the generated one, and none generated for nothing.
#[test]
fn each_shared_constant_is_defined_once_and_used() {
    let header = std::fs::read_to_string(header_path()).unwrap();
    for s in shared() {
        let define = format!("#define {} ", s.c_name);
        assert_eq!(header.matches(&define).count(), 1, "{}", s.c_name);
        let uses = header
            .match_indices(s.c_name)
            .filter(|(i, _)| {
                let after = header[i + s.c_name.len()..].chars().next();
                !after.is_some_and(|ch| ch.is_ascii_alphanumeric() || ch == '_')
            })
            .count();
        assert!(uses >= 2, "{} is generated but not used", s.c_name);
    }
}
