//! The output format of a picture, by the extension of the path a flag names.

use anyhow::{anyhow, Result};
use specconv_convert_cmd::errors::usage;

/// The output kind of a picture path, by its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    /// `option` names the flag in the error, `allowed` the formats it takes.
    pub fn of(path: &std::path::Path, option: &str, allowed: &[Format]) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = match ext.as_deref() {
            Some("svg") => Some(Format::Svg),
            Some("png") => Some(Format::Png),
            _ => None,
        };
        let names: Vec<&str> = allowed
            .iter()
            .map(|f| match f {
                Format::Svg => "*.svg",
                Format::Png => "*.png",
            })
            .collect();
        match format {
            Some(f) if allowed.contains(&f) => Ok(f),
            _ => Err(usage(anyhow!(
                "{option} {}: the format is chosen by the extension; name the file {}",
                path.display(),
                names.join(" or ")
            ))),
        }
    }
}
