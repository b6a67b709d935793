//! What a front-end may ask of an image without converting it.

use std::path::Path;

pub use specconv_oiio::Error as ReadError;

/// Pixels of every level of an image (its weight in a farm's plan).
pub fn pixel_count(path: &Path) -> Result<u64, ReadError> {
    let reader = specconv_oiio::ImageReader::open(path)?;
    Ok(reader
        .info()
        .levels
        .iter()
        .map(|l| u64::from(l.width) * u64::from(l.height))
        .sum())
}

/// Reading images as a conversion reads them: the same subimage, channel and colour-space
/// rules, for front-ends that describe or sample an image (`info`, a scene's texture pixel).
pub use specconv_oiio::{ImageInfo, ImageReader, Region, Window};
pub use specconv_pipeline::input::{choose_channels, open_subimage, ChannelReason};
pub use specconv_pipeline::{colour_channels, colour_of, input_space, InputSpace};
