//! Issue 55, decision 5 (in part): the numbers the C header's encoder shares with the library
//! are the library's. Each `#define` of include/specconv_spectrum.h below is read as C reads
//! it (a literal, or a product of two) and compared with the constant it mirrors.

use specconv_colour::rgb::SRGB;
use specconv_spectral::bounded::{REGULARISATION, SAME_WHITE, WHITE_ROUNDING};

/// The value of `#define NAME …` in the header: a number, or `(a * b)`.
fn define(header: &str, name: &str) -> f64 {
    let line = header
        .lines()
        .find(|l| l.starts_with(&format!("#define {name} ")))
        .unwrap_or_else(|| panic!("the header defines no {name}"));
    let value = line[format!("#define {name} ").len()..].trim();
    let value = value.trim_start_matches('(').trim_end_matches(')');
    value
        .split('*')
        .map(|f| {
            f.trim()
                .parse::<f64>()
                .unwrap_or_else(|e| panic!("{name}: {f}: {e}"))
        })
        .product()
}

#[test]
fn the_c_header_s_shared_constants_are_the_library_s() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../include/specconv_spectrum.h");
    let header = std::fs::read_to_string(&path).unwrap();
    let pairs = [
        ("SCS_REGULARISATION_", REGULARISATION),
        ("SCS_WHITE_ROUNDING_", WHITE_ROUNDING),
        ("SCS_SAME_WHITE_", SAME_WHITE),
        ("SCS_D65_X_", SRGB.white[0]),
        ("SCS_D65_Y_", SRGB.white[1]),
    ];
    for (name, library) in pairs {
        let c = define(&header, name);
        assert_eq!(
            c.to_bits(),
            library.to_bits(),
            "{name}: {c} in C, {library} here"
        );
    }
}
