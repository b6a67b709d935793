//! A plain RGB(A) OpenEXR, float samples, for what is integrated back to colour (`to-rgb`): no
//! channel the source did not have (A only with alpha).

use crate::attributes::{standard_attribute, text, MAX_NAME_BYTES};
use crate::error::Result;
use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
use std::io::{Seek, Write};

/// Writes `width × height` pixels of `rgb` (three values a pixel, row-major) and `alpha` (one a
/// pixel) to `out`, as OpenEXR's RGB(A) file writer does.
pub fn write_rgb(
    out: impl Write + Seek,
    size: (usize, usize),
    rgb: &[f32],
    alpha: Option<&[f32]>,
) -> Result<()> {
    write_rgb_declared(out, size, rgb, alpha, &Declaration::default())
}

/// What an RGB file declares of its colour, so that other readers take its values as the
/// colour space they are in.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Declaration {
    /// `chromaticities`: red, green, blue and white x, y (linear values).
    pub chromaticities: Option<[f32; 8]>,
    /// `acesImageContainerFlag` = 1: ACES2065-1 (SMPTE ST 2065-4).
    pub aces_container: bool,
    /// A colour-space name as OpenImageIO's `oiio:ColorSpace` holds it.
    pub colorspace_name: Option<String>,
    /// More text attributes (name, value), such as the texture's metadata.
    pub text: Vec<(String, String)>,
}

/// [`write_rgb`] with the colour declared.
pub fn write_rgb_declared(
    out: impl Write + Seek,
    (width, height): (usize, usize),
    rgb: &[f32],
    alpha: Option<&[f32]>,
    declared: &Declaration,
) -> Result<()> {
    use exr::meta::attribute::{AttributeValue, Chromaticities, Text};
    let px = |p: Vec2<usize>| {
        let i = p.y() * width + p.x();
        (rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2])
    };
    let declare = |attributes: &mut exr::meta::header::ImageAttributes| {
        attributes.chromaticities = declared.chromaticities.map(|c| Chromaticities {
            red: Vec2(c[0], c[1]),
            green: Vec2(c[2], c[3]),
            blue: Vec2(c[4], c[5]),
            white: Vec2(c[6], c[7]),
        });
        if declared.aces_container {
            attributes
                .other
                .insert(Text::from("acesImageContainerFlag"), AttributeValue::I32(1));
        }
        // Names OpenEXR cannot take as free text are left out (the callers' metadata rule
        // keeps them out before).
        for (name, value) in &declared.text {
            if !name.is_empty() && name.len() <= MAX_NAME_BYTES && !standard_attribute(name) {
                attributes
                    .other
                    .insert(text(name), AttributeValue::Text(text(value)));
            }
        }
        if let Some(name) = declared.colorspace_name.as_deref() {
            if let Some(text) = Text::new_or_none(name) {
                attributes
                    .other
                    .insert(Text::from("oiio:ColorSpace"), AttributeValue::Text(text));
            }
        }
    };
    match alpha {
        Some(a) => {
            let mut image = Image::from_channels(
                (width, height),
                SpecificChannels::rgba(|p: Vec2<usize>| {
                    let (r, g, b) = px(p);
                    (r, g, b, a[p.y() * width + p.x()])
                }),
            );
            declare(&mut image.attributes);
            image.write().to_buffered(out)?
        }
        None => {
            let mut image = Image::from_channels((width, height), SpecificChannels::rgb(px));
            declare(&mut image.attributes);
            image.write().to_buffered(out)?
        }
    }
    Ok(())
}
