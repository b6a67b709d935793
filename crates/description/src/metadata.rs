//! The texture metadata an output carries from its input, as maketx carries it: every string
//! attribute of the input's header that says something of the texture (Copyright,
//! DocumentName, ImageDescription, Artist, a studio's own such as `studio:assetId`), and none
//! that describes the file it was read from (its format's and OpenImageIO's namespaces) or
//! that the writer makes itself (the software, the date, the texture's and specconv's own
//! attributes). One rule for `convert` (input to spectral EXR) and `to-rgb` (spectral EXR
//! back to RGB), so that metadata round-trips.

/// Namespaces (`NS:name`) of attributes that describe a file's format or how OpenImageIO read
/// it, not the texture: the formats', Exif's, IPTC's and XMP's, OpenImageIO's and maketx's.
const FILE_NAMESPACES: [&str; 22] = [
    "oiio",
    "openexr",
    "tiff",
    "png",
    "jpeg",
    "jpeg2000",
    "exif",
    "gps",
    "iptc",
    "xmp",
    "photoshop",
    "icc",
    "dpx",
    "targa",
    "bmp",
    "heif",
    "raw",
    "ffmpeg",
    "webp",
    "gif",
    "psd",
    "maketx",
];

/// Attributes without a namespace that the writer makes itself (the texture's description,
/// the spectral layout's, the software and date of this writing) or that say how the file was
/// stored.
const WRITTEN: [&str; 12] = [
    "Software",
    "DateTime",
    "HostComputer",
    "compression",
    "planarconfig",
    "textureformat",
    "wrapmodes",
    "fovcot",
    "spectralLayoutVersion",
    "emissiveUnits",
    "polarisationHandedness",
    "name",
];

/// Whether `name` is, or passes for, one of specconv's own provenance attributes: it starts
/// with `specconv` once case and every character but ASCII letters and digits are ignored
/// (`SpecconvModel`, `specconv:Source`, ` specconv_Model`, `SPEC-CONV…`).
pub fn reserved(name: &str) -> bool {
    let mut letters = name
        .chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase());
    "specconv".chars().all(|c| letters.next() == Some(c))
}

/// Whether an output carries the input's string attribute `name`.
pub fn carried(name: &str) -> bool {
    // specconv's own provenance is written anew by each conversion: no input attribute may
    // overwrite, shadow or imitate it.
    if reserved(name) || WRITTEN.contains(&name) {
        return false;
    }
    match name.split_once(':') {
        Some((space, _)) => !FILE_NAMESPACES.contains(&space.to_ascii_lowercase().as_str()),
        None => true,
    }
}

/// Of `attributes` (name, value), those an output carries ([`carried`]), in order.
pub fn of(attributes: impl IntoIterator<Item = (String, String)>) -> Vec<(String, String)> {
    attributes
        .into_iter()
        .filter(|(name, _)| carried(name))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_texture_s_metadata_is_carried_and_the_file_s_is_not() {
        for name in [
            "Copyright",
            "DocumentName",
            "ImageDescription",
            "Artist",
            "studio:assetId",
            "owner",
            "spec",
            "studio:specconvNote",
        ] {
            assert!(carried(name), "{name}");
        }
        for name in [
            "Software",
            "DateTime",
            "oiio:ColorSpace",
            "Exif:ImageHistory",
            "tiff:Compression",
            "png:sRGB",
            "specconvModel",
            "SpecconvModel",
            "SPECCONVSOURCE",
            "specconv:Source",
            " specconvSource",
            "spec_conv Commercial Use",
            "specconv\nModel",
            "wrapmodes",
            "spectralLayoutVersion",
        ] {
            assert!(!carried(name), "{name}");
        }
    }
}
