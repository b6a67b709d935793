//! What makes an output a texture a renderer's texture system reads as maketx's: wrap modes,
//! `textureformat`, `fovcot` (OpenImageIO's texture conventions, as maketx writes them).

pub use specconv_description::wrap::{parse_wrapmodes, Wrap, WrapModes, DEFAULT_WRAP, WRAP_NAMES};

/// The input's texture metadata an output carries ([`crate::metadata::carried`]), in the
/// header's order.
pub fn metadata(
    reader: &specconv_oiio::ImageReader,
) -> specconv_oiio::Result<Vec<(String, String)>> {
    let mut carried = Vec::new();
    for name in reader.string_attribute_names()? {
        if crate::metadata::carried(&name) {
            if let Some(value) = reader.string_attribute(&name)? {
                carried.push((name, value));
            }
        }
    }
    Ok(carried)
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
