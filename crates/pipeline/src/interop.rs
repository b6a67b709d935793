//! Color Interop Forum IDs: the colour-space names OpenImageIO 3 writes in OpenEXR's
//! `colorInteropID` attribute and OpenColorIO 2.5 gives colour spaces (`interop_id`), one
//! table ([`IDS`]) of what each means.
//!
//! Sources: ASWF Color Interop Forum, github.com/AcademySoftwareFoundation/ColorInterop,
//! "Color Space Encodings for Texture Assets and CG Rendering" v1.1.0 (2026-07-14, the
//! `*_scene` IDs, `data`, `unknown`) and "Color Space Encodings for Displays" v1.0.0
//! (2026-01-26, the `*_display` IDs); how a reader uses them: "An ID for Color Interop"
//! v1.0.0 (look the ID up as a name or alias of the config first) and "Identifying the Color
//! Space of OpenEXR Files" (draft 2026-05-18: `data` is not colour-managed, `unknown` says
//! nothing).
//!
//! OpenColorIO 2.1 cannot read a config's `interop_id`, so an ID the config does not know
//! as a name or alias is read by this table: primaries, white and transfer function, matched
//! to the config's colour space that converts the same way (as OpenEXR chromaticities are).
//! A display ID is read as the same encoding of colour (as a PNG's `sRGB` chunk is), not
//! through the inverse of a view transform.

use crate::transfer::Decode;
use specconv_colour::rgb::{self, RgbSpace};

/// The ID of data, not colour: what a data texture written through (`--data copy`) says in
/// its `colorInteropID`, so that every reader (specconv's `info` among them) sees data.
pub const DATA: &str = "data";

/// What an ID says about the pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Meaning {
    /// Colour in these primaries and white, stored with this transfer function.
    Rgb(RgbSpace, Decode),
    /// CIE XYZ with the D65 white as adopted white: the connection space itself.
    XyzD65,
    /// Numbers, not colour (`data`).
    Data,
    /// The writer did not know (`unknown`): no declaration.
    Unknown,
    /// An encoding specconv does not decode, and why.
    Unsupported(&'static str),
}

const LIN: Decode = Decode::Linear;
const SRGB: Decode = Decode::Srgb;
const fn power(exponent: f64) -> Decode {
    Decode::Power(exponent)
}
/// Adobe RGB (1998)'s exponent, 563/256.
const ADOBE: f64 = 563.0 / 256.0;
const HDR: &str = "an HDR display encoding (PQ or HLG) specconv does not decode";

/// Every Color Interop Forum ID of the sources above, with its meaning.
pub const IDS: [(&str, Meaning); 32] = [
    ("lin_ap1_scene", Meaning::Rgb(rgb::ACESCG, LIN)),
    ("lin_ap0_scene", Meaning::Rgb(rgb::ACES2065_1, LIN)),
    ("lin_rec709_scene", Meaning::Rgb(rgb::SRGB, LIN)),
    ("lin_p3d65_scene", Meaning::Rgb(rgb::P3_D65, LIN)),
    ("lin_rec2020_scene", Meaning::Rgb(rgb::REC2020, LIN)),
    ("lin_adobergb_scene", Meaning::Rgb(rgb::ADOBE_RGB, LIN)),
    ("lin_ciexyzd65_scene", Meaning::XyzD65),
    ("srgb_rec709_scene", Meaning::Rgb(rgb::SRGB, SRGB)),
    ("g24_rec709_scene", Meaning::Rgb(rgb::SRGB, power(2.4))),
    ("g22_rec709_scene", Meaning::Rgb(rgb::SRGB, power(2.2))),
    ("g18_rec709_scene", Meaning::Rgb(rgb::SRGB, power(1.8))),
    ("srgb_ap1_scene", Meaning::Rgb(rgb::ACESCG, SRGB)),
    ("g22_ap1_scene", Meaning::Rgb(rgb::ACESCG, power(2.2))),
    ("srgb_p3d65_scene", Meaning::Rgb(rgb::P3_D65, SRGB)),
    (
        "g22_adobergb_scene",
        Meaning::Rgb(rgb::ADOBE_RGB, power(ADOBE)),
    ),
    (DATA, Meaning::Data),
    ("unknown", Meaning::Unknown),
    ("srgb_rec709_display", Meaning::Rgb(rgb::SRGB, SRGB)),
    ("g24_rec709_display", Meaning::Rgb(rgb::SRGB, power(2.4))),
    ("srgb_p3d65_display", Meaning::Rgb(rgb::P3_D65, SRGB)),
    // Extended sRGB: the same curve continued above 1.
    ("srgbe_p3d65_display", Meaning::Rgb(rgb::P3_D65, SRGB)),
    ("pq_p3d65_display", Meaning::Unsupported(HDR)),
    ("pq_rec2020_display", Meaning::Unsupported(HDR)),
    ("hlg_rec2020_display", Meaning::Unsupported(HDR)),
    ("g22_rec709_display", Meaning::Rgb(rgb::SRGB, power(2.2))),
    (
        "g22_adobergb_display",
        Meaning::Rgb(rgb::ADOBE_RGB, power(ADOBE)),
    ),
    ("g26_p3d65_display", Meaning::Rgb(rgb::P3_D65, power(2.6))),
    (
        "g26_xyzd65_display",
        Meaning::Unsupported(
            "a cinema (DCDM) encoding with headroom scaling specconv does not decode",
        ),
    ),
    ("pq_xyzd65_display", Meaning::Unsupported(HDR)),
    ("lin_rec709_display", Meaning::Rgb(rgb::SRGB, LIN)),
    ("lin_p3d65_display", Meaning::Rgb(rgb::P3_D65, LIN)),
    ("lin_rec2020_display", Meaning::Rgb(rgb::REC2020, LIN)),
];

/// The meaning of the Color Interop Forum ID `id` (its case ignored, as OpenImageIO does);
/// `None` for any other name (a studio's `namespace:space` among them).
pub fn meaning(id: &str) -> Option<(&'static str, Meaning)> {
    IDS.iter()
        .find(|(known, _)| known.eq_ignore_ascii_case(id.trim()))
        .copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_id_is_once_in_the_table_and_lower_case() {
        for (i, (id, _)) in IDS.iter().enumerate() {
            assert_eq!(*id, id.to_ascii_lowercase());
            assert!(IDS[i + 1..].iter().all(|(other, _)| other != id), "{id}");
            assert_eq!(meaning(&id.to_ascii_uppercase()).map(|m| m.0), Some(*id));
        }
        assert_eq!(meaning("studio:lin_ap1_scene"), None);
    }
}
