//! Compact textures (`--layout compact`, docs/compact.md) told apart from spectral files, by one
//! rule that every reader of spectral files follows: `describe` shows what a compact file
//! holds, and `to-rgb`, `preview` and Python's `read_spectral` refuse it naming `expand`,
//! instead of calling it a file with no bands. And a compact texture used: [`expand`] writes
//! it out in bands, [`read_compact`] reads its texels, [`check_compact_header`] checks the
//! header another reader read.

use crate::error::Error;
use crate::options::NonFinite;
use crate::pipeline;
use crate::pipeline::expand::{CompactTexels, Expanded};
use crate::pipeline::{COMPACT_ATTRIBUTE, COMPACT_CHANNELS, LAYOUT_ATTRIBUTE};
use specconv_oiio::ImageReader;
use std::collections::BTreeMap;
use std::path::Path;

/// What a compact texture holds, as `info` shows it: six values a texel and the model in its
/// header, which a renderer decodes per lookup and `expand` writes out as bands.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CompactFacts {
    /// Its `specconvLayout` attribute (`compact 2`); `None` where the texel's channels alone
    /// say it is compact.
    pub layout: Option<String>,
    /// The texel's channels the file has, in a texel's order (`R` … `UF.2`).
    pub texel_channels: Vec<String>,
    /// The texel's channels it lacks.
    pub missing_channels: Vec<String>,
    /// Wavelengths of the bands its header decodes to (nm); or why this version cannot
    /// decode it (what is missing or wrong).
    pub bands_nm: Result<Vec<f64>, String>,
    /// Its `specconv*` attributes but the decoding text (model, settings, provenance).
    pub specconv: BTreeMap<String, String>,
}

/// The compact facts of the image `reader` has open at `path`; `None` when it is not compact.
pub(crate) fn facts(path: &Path, reader: &ImageReader) -> Result<Option<CompactFacts>, Error> {
    let channels: Vec<&str> = reader
        .info()
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    let layout = reader.string_attribute(LAYOUT_ATTRIBUTE).map_err(oiio)?;
    if !crate::pipeline::expand::is_compact(layout.as_deref(), &channels) {
        return Ok(None);
    }
    // The text as its header holds it, not cut at a NUL (`expand::text_attributes`).
    let bands_nm = crate::pipeline::expand::text_attributes(path)
        .and_then(|(layout, text)| {
            crate::pipeline::expand::header(path, layout.as_deref(), text.as_deref(), &channels)
        })
        .map(|(compact, _)| compact.grid().wavelengths())
        .map_err(|e| match e {
            crate::pipeline::Error::NotCompact { why, .. } => why,
            e => e.to_string(),
        });
    let (texel_channels, missing_channels): (Vec<String>, Vec<String>) = COMPACT_CHANNELS
        .iter()
        .map(|c| c.to_string())
        .partition(|c| channels.contains(&c.as_str()));
    let mut specconv = BTreeMap::new();
    for name in reader.string_attribute_names().map_err(oiio)? {
        if name.starts_with("specconv") && name != COMPACT_ATTRIBUTE && name != LAYOUT_ATTRIBUTE {
            if let Some(value) = reader.string_attribute(&name).map_err(oiio)? {
                specconv.insert(name, value);
            }
        }
    }
    Ok(Some(CompactFacts {
        layout,
        texel_channels,
        missing_channels,
        bands_nm,
        specconv,
    }))
}

/// Writes the compact texture `input` (`--layout compact`) out in the spectral layout at
/// `output`, as a conversion with the same settings writes it (docs/compact.md): NaN and
/// infinite texels by `fixnan`, else by the rule the conversion recorded; `cancel` stops
/// it, leaving nothing.
pub fn expand(
    input: &std::path::Path,
    output: &std::path::Path,
    overwrite: bool,
    fixnan: Option<NonFinite>,
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<Expanded, Error> {
    Ok(pipeline::expand::expand(
        input, output, overwrite, fixnan, cancel,
    )?)
}

/// Reads MIP level `level` of the compact texture `input` (`--layout compact`) into memory:
/// its texels and decoding text, for a renderer that decodes spectra per lookup.
pub fn read_compact(input: &std::path::Path, level: usize) -> Result<CompactTexels, Error> {
    Ok(pipeline::expand::read_texels(input, level)?)
}

/// Whether a file another reader read (Mitsuba's) is a compact texture [`read_compact`] would
/// read, from its header: `attribute` gives a header attribute's text by name (this library
/// names the ones it needs), `channels` the channel names. Returns the decoding text as this
/// library writes it and the columns of the texel's stored channels (`R` … `UF.2`) among `channels`; otherwise
/// [`ConversionError::NotCompact`](crate::ConversionError::NotCompact), saying what is missing or
/// wrong (a text's line and reason).
pub fn check_compact_header(
    path: &std::path::Path,
    attribute: &dyn Fn(&str) -> Option<String>,
    channels: &[&str],
) -> Result<(String, [usize; specconv_spectral::compact::STORED]), Error> {
    use pipeline::{COMPACT_ATTRIBUTE, LAYOUT_ATTRIBUTE};
    let (layout, text) = (attribute(LAYOUT_ATTRIBUTE), attribute(COMPACT_ATTRIBUTE));
    let (compact, columns) =
        pipeline::expand::header(path, layout.as_deref(), text.as_deref(), channels)?;
    Ok((compact.to_text(), columns))
}

/// The error of a reader of spectral files that could not read `path` (`source`): when the
/// file is a compact texture, [`Error::CompactNotSpectral`], which says what it is and how to
/// get its bands; otherwise [`Error::Read`].
pub fn spectral_read_error(path: &Path, source: specconv_exr::Error) -> Error {
    // Only a regular file is opened again: a FIFO would block the reader.
    let compact = specconv_atomic_file::readable_file(path)
        .ok()
        .and_then(|_| ImageReader::open(path).ok())
        .and_then(|r| facts(path, &r).ok().flatten());
    match compact {
        Some(facts) => Error::CompactNotSpectral {
            path: path.to_path_buf(),
            layout: facts.layout.unwrap_or_else(|| "no layout attribute".into()),
        },
        None => Error::Read {
            path: path.to_path_buf(),
            source,
        },
    }
}

/// A reader's error as a conversion's.
fn oiio(e: specconv_oiio::Error) -> Error {
    crate::pipeline::Error::from(e).into()
}
