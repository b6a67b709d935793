//! What a spectral file's bands are, as every writer of the layout names them: emission's
//! `S0.` channels in the layout's units, or reflectance's `T.` channels. Imports nothing of
//! this crate, so that the pipeline and the provenance both may use it.

use specconv_colour::EmissionUnits;

/// Units of `S0.` channels, as the layout names them: radiance; the scale is the convention
/// recorded in `specconvEmissionUnits` (the facade's `provenance`).
pub const EMISSIVE_UNITS: &str = "W.m^-2.sr^-1";

/// The bands of a file of emission in `units` (`S0.` channels, [`EMISSIVE_UNITS`]), or of
/// reflectance (`T.` channels); the facade's provenance records the convention. Every
/// writer of spectral files (a conversion, Python's `write_spectral`) takes them from here.
pub fn bands(emission: Option<EmissionUnits>) -> specconv_exr::Kind {
    match emission {
        Some(_) => specconv_exr::Kind::Emissive {
            units: EMISSIVE_UNITS.into(),
        },
        None => specconv_exr::Kind::Reflective,
    }
}
