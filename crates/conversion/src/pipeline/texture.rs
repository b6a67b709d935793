//! What makes an output a texture a renderer's texture system reads as maketx's: wrap modes,
//! `textureformat`, `fovcot` (OpenImageIO's texture conventions, as maketx writes them).

use std::fmt;

/// What a lookup outside [0, 1] reads, per direction: OpenImageIO's wrap modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wrap {
    /// Black (zero) outside.
    Black,
    /// The edge texel repeated.
    Clamp,
    /// The texture repeated.
    Periodic,
    /// The texture mirrored at each edge.
    Mirror,
}

/// The names OpenImageIO spells wrap modes with, in `wrapmodes` and maketx's `--wrap`.
pub const WRAP_NAMES: [&str; 4] = ["black", "clamp", "periodic", "mirror"];

impl std::str::FromStr for Wrap {
    type Err = String;

    fn from_str(s: &str) -> Result<Wrap, String> {
        match s {
            "black" => Ok(Wrap::Black),
            "clamp" => Ok(Wrap::Clamp),
            "periodic" => Ok(Wrap::Periodic),
            "mirror" => Ok(Wrap::Mirror),
            _ => Err(format!(
                "'{s}' is not a wrap mode (one of {})",
                WRAP_NAMES.join(", ")
            )),
        }
    }
}

impl fmt::Display for Wrap {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let i = *self as usize;
        f.write_str(WRAP_NAMES[i])
    }
}

/// Wrap modes in s and t.
pub type WrapModes = (Wrap, Wrap);

/// maketx's default when neither the input nor the user names one.
pub const DEFAULT_WRAP: WrapModes = (Wrap::Black, Wrap::Black);

/// Parses `wrapmodes` as OpenImageIO writes it (`periodic,clamp`) or maketx's `--wrap` takes it
/// (one mode for both directions).
pub fn parse_wrapmodes(text: &str) -> Result<WrapModes, String> {
    let mut parts = text.split(',').map(str::trim);
    let s: Wrap = parts.next().unwrap_or_default().parse()?;
    let t = match parts.next() {
        Some(t) => t.parse()?,
        None => s,
    };
    if parts.next().is_some() {
        return Err(format!("'{text}' names more than two wrap modes"));
    }
    Ok((s, t))
}

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
