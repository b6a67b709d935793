//! The header's attributes: text as OpenEXR stores it (UTF-8), the names free text may take,
//! written in name order, and read back without the pixels.

use crate::error::{Error, Result};
use crate::spec::{Kind, Spec};
use exr::math::Vec2;
use exr::meta::attribute::{AttributeValue, Text};
use exr::meta::header::Header;
use std::io::{Seek, Write};

/// Gives `header` the layout's attributes and `spec`'s own, text (UTF-8, [`text`]) and float;
/// refuses attribute names that are empty, longer than [`MAX_NAME_BYTES`] or OpenEXR's own
/// ([`standard_attribute`]): the callers' rules keep such names out.
pub(crate) fn set_attributes(header: &mut Header, spec: &Spec) -> Result<()> {
    let put = |header: &mut Header, name: &str, value: &str| {
        header
            .own_attributes
            .other
            .insert(text(name), AttributeValue::Text(text(value)));
    };
    match &spec.kind {
        Kind::Named(_) => {}
        Kind::Reflective => put(header, "spectralLayoutVersion", "1.0"),
        Kind::Emissive { units } => {
            put(header, "spectralLayoutVersion", "1.0");
            put(header, "emissiveUnits", units);
        }
    }
    for (k, v) in &spec.attributes {
        // The exr crate keeps `wrapmodes` (a texture's, OpenImageIO's name) in a field of its
        // own.
        if k == "wrapmodes" {
            header.own_attributes.wrap_mode_name = Some(text(v));
            continue;
        }
        check_name(k)?;
        put(header, k, v);
    }
    for (k, v) in &spec.float_attributes {
        check_name(k)?;
        header
            .own_attributes
            .other
            .insert(text(k), AttributeValue::F32(*v));
    }
    Ok(())
}

/// The longest attribute name OpenEXR writes (its long-name limit), in bytes.
pub const MAX_NAME_BYTES: usize = 255;

/// Whether `name` is one of OpenEXR's own attribute names (its required and standard
/// attributes, as the `exr` crate lists them): each has a type and a meaning of its own in
/// the file (`tiles`, `channels`, `view`, `owner`, …), so no free text may take it.
pub fn standard_attribute(name: &str) -> bool {
    exr::meta::header::standard_names::ALL.contains(&name.as_bytes())
}

/// Text for a header, as UTF-8 bytes: OpenEXR's strings are bytes, which OpenImageIO and
/// OpenEXR's own tools read as UTF-8 (the `exr` crate's `Text::new_or_none` writes Latin-1
/// and refuses anything past U+00FF).
pub fn text(s: &str) -> Text {
    Text::from_slice_unchecked(s.as_bytes())
}

/// A header's text as a string: UTF-8, or Latin-1 where the bytes are not UTF-8 (as specconv
/// wrote text before it wrote UTF-8, and as the `exr` crate writes it).
pub fn text_string(t: &Text) -> String {
    match std::str::from_utf8(t.as_slice()) {
        Ok(s) => s.to_owned(),
        Err(_) => t.as_slice().iter().map(|&b| char::from(b)).collect(),
    }
}

/// Refuses an attribute name OpenEXR cannot take as free text: empty, past
/// [`MAX_NAME_BYTES`], or OpenEXR's own ([`standard_attribute`]).
fn check_name(name: &str) -> Result<()> {
    if name.is_empty() || name.len() > MAX_NAME_BYTES || standard_attribute(name) {
        return Err(Error::Invalid(format!(
            "attribute name '{}' cannot be written: OpenEXR takes names of 1 to \
             {MAX_NAME_BYTES} bytes that are not its own attributes'",
            name.escape_debug()
        )));
    }
    Ok(())
}

/// Writes `header`'s attributes again over the header written, in name order: the `exr` crate
/// writes them in the order of a `HashMap`, which changes from run to run, and the same image
/// must give the same bytes. `header` has the length of the one written, so nothing moves.
pub(crate) fn sort_attributes(header: &Header, out: &mut (impl Write + Seek)) -> Result<()> {
    let mut written = Vec::new();
    header.write(&mut written)?;
    let mut attributes: Vec<_> = header.all_named_attributes().collect();
    attributes.sort_by(|a, b| a.0.cmp(b.0));
    let mut sorted = Vec::with_capacity(written.len());
    for (name, value) in &attributes {
        exr::meta::attribute::write(name, value, &mut sorted)?;
    }
    exr::meta::sequence_end::write(&mut sorted)?;
    if sorted.len() != written.len() {
        // Not the header the exr crate wrote: leave it as it is (a valid file, only its
        // attribute order unsorted) rather than write over what follows it.
        return Ok(());
    }
    // After the magic number and the version field.
    let mut rewrite = || -> std::io::Result<()> {
        out.seek(std::io::SeekFrom::Start(8))?;
        out.write_all(&sorted)?;
        out.seek(std::io::SeekFrom::End(0))?;
        out.flush()
    };
    Ok(rewrite().map_err(exr::error::Error::from)?)
}

/// What an OpenEXR file's first header says of its colour, read without its pixels: the
/// evidence a conversion weighs (docs/colour.md), as OpenImageIO reports it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ColourAttributes {
    /// `chromaticities`: red, green, blue and white x, y.
    pub chromaticities: Option<[f32; 8]>,
    /// `acesImageContainerFlag`, where it is a number.
    pub aces_container: Option<f64>,
    /// `colorInteropID`.
    pub interop_id: Option<String>,
    /// `oiio:ColorSpace`, a name a tool wrote.
    pub colour_space: Option<String>,
}

/// The first bytes of every OpenEXR file.
const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// The colour attributes of an OpenEXR file's first header, without reading its pixels;
/// `None` for a file that is not OpenEXR (its first bytes are not OpenEXR's magic number).
pub fn colour_attributes(path: &std::path::Path) -> Result<Option<ColourAttributes>> {
    use std::io::{Read, Seek};
    let mut file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let mut magic = [0u8; 4];
    if file.read_exact(&mut magic).is_err() || magic != MAGIC {
        return Ok(None);
    }
    file.rewind().map_err(exr::error::Error::from)?;
    let meta = exr::meta::MetaData::read_from_buffered(file, false)?;
    let Some(h) = meta.headers.first() else {
        return Ok(Some(ColourAttributes::default()));
    };
    let c = h.shared_attributes.chromaticities;
    let string = |name: &str| match h.own_attributes.other.get(&text(name)) {
        Some(AttributeValue::Text(t)) => Some(text_string(t)),
        _ => None,
    };
    let aces = match h.own_attributes.other.get(&text("acesImageContainerFlag")) {
        Some(AttributeValue::I32(v)) => Some(f64::from(*v)),
        Some(AttributeValue::F32(v)) => Some(f64::from(*v)),
        Some(AttributeValue::F64(v)) => Some(*v),
        _ => None,
    };
    Ok(Some(ColourAttributes {
        chromaticities: c.map(|c| {
            let xy = |v: Vec2<f32>| [v.x(), v.y()];
            let [r, g, b, w] = [c.red, c.green, c.blue, c.white].map(xy);
            [r[0], r[1], g[0], g[1], b[0], b[1], w[0], w[1]]
        }),
        aces_container: aces,
        interop_id: string("colorInteropID"),
        colour_space: string("oiio:ColorSpace"),
    }))
}

/// The text attributes of a file's first header, without reading its pixels.
pub fn read_attributes(path: &std::path::Path) -> Result<Vec<(String, String)>> {
    let file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let meta = exr::meta::MetaData::read_from_buffered(file, false)?;
    Ok(meta.headers.first().map_or_else(Vec::new, text_attributes))
}

/// A part's own text attributes, as (name, value).
pub(crate) fn text_attributes(h: &Header) -> Vec<(String, String)> {
    h.own_attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((text_string(k), text_string(t))),
            _ => None,
        })
        .collect()
}
