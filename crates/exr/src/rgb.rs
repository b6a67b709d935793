//! A plain RGB(A) OpenEXR, float samples, for what is integrated back to colour (`to-rgb`): no
//! channel the source did not have (A only with alpha).

use crate::Result;
use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
use std::io::{Seek, Write};

/// Writes `width × height` pixels of `rgb` (three values a pixel, row-major) and `alpha` (one a
/// pixel) to `out`, as OpenEXR's RGB(A) file writer does.
pub fn write_rgb(
    out: impl Write + Seek,
    (width, height): (usize, usize),
    rgb: &[f32],
    alpha: Option<&[f32]>,
) -> Result<()> {
    let px = |p: Vec2<usize>| {
        let i = p.y() * width + p.x();
        (rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2])
    };
    match alpha {
        Some(a) => Image::from_channels(
            (width, height),
            SpecificChannels::rgba(|p: Vec2<usize>| {
                let (r, g, b) = px(p);
                (r, g, b, a[p.y() * width + p.x()])
            }),
        )
        .write()
        .to_buffered(out)?,
        None => Image::from_channels((width, height), SpecificChannels::rgb(px))
            .write()
            .to_buffered(out)?,
    }
    Ok(())
}
