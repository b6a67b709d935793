//! What makes an output a texture a renderer's texture system reads as maketx's: wrap modes,
//! `textureformat`, `fovcot` (OpenImageIO's texture conventions, as maketx writes them).

pub use specconv_description::wrap::{parse_wrapmodes, Wrap, WrapModes, DEFAULT_WRAP, WRAP_NAMES};

/// The input's texture metadata an output carries and what it drops ([`crate::metadata::Carry`]),
/// in the header's order: each value's length checked against the bounds before it is
/// copied, its text decoded from the encoding the file declares (a PNG's chunk's, else
/// UTF-8). `path` is the file `reader` reads.
pub fn metadata(
    reader: &specconv_oiio::ImageReader,
    path: &std::path::Path,
) -> specconv_oiio::Result<crate::metadata::Carry> {
    use crate::metadata::{carried, fits, Carry, Encoding, Why};
    let encodings = crate::png::text_encodings(path);
    let encoding = |raw: &[u8]| {
        encodings
            .iter()
            .find(|(n, _)| n == raw)
            .map_or(Encoding::Utf8, |(_, e)| *e)
    };
    let mut carry = Carry::default();
    for raw in reader.string_attribute_names_raw()? {
        let Some(name) = encoding(&raw).decode(&raw) else {
            let shown = String::from_utf8_lossy(&raw).into_owned();
            if carried(&shown) {
                carry.refuse(&shown, Why::NotText(Encoding::Utf8));
            }
            continue;
        };
        // A PNG's own text under one of OpenEXR's names that the writer sets itself (`name`,
        // `compression`): the file's words, so dropped with a warning as OpenEXR's other names
        // are (issue 57, item 8); the reader's own attributes of those names go unsaid.
        let in_text = encodings.iter().any(|(n, _)| *n == raw);
        if !carried(&name) && in_text && fits(&name) == Err(Why::OpenExrName) {
            carry.refuse(&name, Why::OpenExrName);
            continue;
        }
        let Some(len) = reader.string_attribute_len(&raw)? else {
            continue;
        };
        if carry.admit(&name, len) {
            if let Some(value) = reader.string_attribute_bytes(&raw)? {
                carry.push(name, &value, encoding(&raw));
            }
        }
    }
    Ok(carry)
}

/// The wrap modes an input declares (a maketx texture's `wrapmodes`), if it declares valid ones.
pub fn declared(reader: &specconv_oiio::ImageReader) -> Option<WrapModes> {
    let text = reader.string_attribute("wrapmodes").ok().flatten()?;
    parse_wrapmodes(&text).ok()
}

/// The header attributes of a texture with `wrap`: its format and wrap modes.
pub fn attributes(wrap: WrapModes) -> Vec<(String, String)> {
    vec![
        ("textureformat".into(), "Plain Texture".into()),
        ("wrapmodes".into(), format!("{},{}", wrap.0, wrap.1)),
    ]
}

/// `fovcot`: the display window's aspect ratio (width over height), as maketx records it.
pub fn fovcot(width: usize, height: usize) -> f32 {
    width as f32 / height as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrapmodes_read_as_openimageio_writes_them() {
        assert_eq!(
            parse_wrapmodes("periodic,clamp"),
            Ok((Wrap::Periodic, Wrap::Clamp))
        );
        assert_eq!(parse_wrapmodes("mirror"), Ok((Wrap::Mirror, Wrap::Mirror)));
        assert!(parse_wrapmodes("repeat").unwrap_err().contains("periodic"));
        assert!(parse_wrapmodes("black,black,black").is_err());
    }
}
