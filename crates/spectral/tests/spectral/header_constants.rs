//! Issue 55, decision 5: the numbers the C header shares with the library are generated from
//! the library's constants ([`specconv_spectral::c_header`]) between two marker lines of
//! include/specconv_spectrum.h. Stale: `scripts/generate.sh` (or
//! `SPECCONV_UPDATE_GENERATED=1 cargo test -p specconv-spectral --test spectral header`).

use specconv_spectral::c_header::{generated, replaced, shared};

fn header_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../include/specconv_spectrum.h")
}

#[test]
fn the_c_header_s_shared_constants_are_generated_from_the_library() {
    let path = header_path();
    let header = std::fs::read_to_string(&path).unwrap();
    let made =
        replaced(&header, &generated()).expect("the header has the generated part's markers");
    if made != header {
        if std::env::var_os("SPECCONV_UPDATE_GENERATED").is_some() {
            std::fs::write(&path, made).unwrap();
        } else {
            panic!("the header's shared constants are stale: run scripts/generate.sh");
        }
    }
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
