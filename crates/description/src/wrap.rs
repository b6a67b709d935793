//! Wrap modes: what a texture lookup outside [0, 1] reads (OpenImageIO's names, maketx's `--wrap`).

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
