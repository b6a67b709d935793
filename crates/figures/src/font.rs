//! The font of every plot and picture. plotters (with `ab_glyph`) lays out and draws text only
//! with fonts registered at run time, and the repository ships none: the system's DejaVu Sans
//! (Debian: fonts-dejavu-core), or the TrueType file named by `SPECCONV_FONT`.

use crate::error::{Error, Result};
use plotters::style::FontStyle;
use std::path::PathBuf;
use std::sync::OnceLock;

/// The family every drawing asks for.
pub const FAMILY: &str = "sans-serif";

/// Where the font is looked for when `SPECCONV_FONT` is not set.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// Registers the font for [`FAMILY`] once per process; later calls return the first outcome.
pub fn ensure() -> Result<()> {
    static REGISTERED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| register(std::env::var_os("SPECCONV_FONT").map(PathBuf::from)))
        .clone()
        .map_err(Error::Font)
}

fn register(over: Option<PathBuf>) -> std::result::Result<(), String> {
    let from_env = over.is_some();
    let path = over.unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
    let bytes = std::fs::read(&path).map_err(|e| {
        if from_env {
            format!(
                "cannot read the font SPECCONV_FONT={} ({e}); point SPECCONV_FONT at a TrueType \
                 (.ttf) file, or unset it to use {DEFAULT_FONT}",
                path.display()
            )
        } else {
            format!(
                "cannot read the font {} ({e}) that plots and pictures need for their text; \
                 install it (Debian/Ubuntu: apt-get install fonts-dejavu-core) or set \
                 SPECCONV_FONT to any TrueType (.ttf) file",
                path.display()
            )
        }
    })?;
    // plotters keeps fonts for the life of the process; this runs once.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font(FAMILY, FontStyle::Normal, bytes).map_err(|_| {
        format!(
            "{} is not a TrueType or OpenType font; set SPECCONV_FONT to a .ttf file",
            path.display()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_or_bad_font_says_what_to_do() {
        let e = register(Some("/nonexistent/x.ttf".into())).unwrap_err();
        assert!(e.contains("SPECCONV_FONT=/nonexistent/x.ttf"), "{e}");
        let not_a_font = std::env::temp_dir().join(format!("specconv-font-{}", std::process::id()));
        std::fs::write(&not_a_font, b"not a font").unwrap();
        let e = register(Some(not_a_font.clone())).unwrap_err();
        let _ = std::fs::remove_file(&not_a_font);
        assert!(e.contains("not a TrueType"), "{e}");
    }
}
