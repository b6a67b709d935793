//! Pictures: plotters drawings rendered to 8-bit RGB and PNG encoding, in memory, so that the
//! caller writes the file atomically (no partial PNG on any error).

use crate::error::{Error, Result};
use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A bitmap to draw on.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
/// What a drawing function returns.
pub type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Draws with `draw` on a blank `width`×`height` RGB bitmap and returns its PNG bytes.
pub fn render_png(
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> DrawResult<BitMapBackend<'static>>,
) -> Result<Vec<u8>> {
    encode_png(&render(size, draw)?, size.0, size.1)
}

/// Draws with `draw` on a blank `width`×`height` bitmap: 8-bit RGB, row-major.
pub fn render(
    (width, height): (u32, u32),
    draw: impl FnOnce(&Area) -> DrawResult<BitMapBackend<'static>>,
) -> Result<Vec<u8>> {
    crate::font::ensure()?;
    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        draw(&root).map_err(drawing_failed)?;
        root.present().map_err(drawing_failed)?;
    }
    Ok(rgb)
}

/// PNG bytes of 8-bit RGB pixels, row-major.
pub fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgb, width, height, image::ColorType::Rgb8)
        .map_err(|e| Error::Png(e.to_string()))?;
    Ok(png)
}

/// A plotters error as ours: they come from the font or the backend, never from the data.
pub fn drawing_failed(e: impl std::fmt::Display) -> Error {
    Error::Drawing(e.to_string())
}
