//! What OpenEXR's readers accept, checked before a file is written: the largest block and the
//! most channels.

use crate::spec::Sample;

/// The largest uncompressed block (a tile, or a block of scanlines) OpenEXR's readers accept:
/// its size in bytes is a signed 32-bit integer. Measured with oiiotool 2.4 on 36 half
/// channels: 5000×5000 tiles (1.8 GB) open, 6000×6000 (2.6 GB) fail with "Tile size too large
/// for OpenEXR format".
pub const MAX_BLOCK_BYTES: u64 = i32::MAX as u64;

/// A tile or scanline block over [`MAX_BLOCK_BYTES`]: a file no reader would open.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "a block of {width}×{height} pixels with {channels} channels of {bytes_per_sample} bytes is {bytes} bytes; OpenEXR readers accept at most {} bytes per block: use smaller tiles or fewer bands",
    MAX_BLOCK_BYTES
)]
pub struct BlockTooLarge {
    /// Block width in pixels.
    pub width: u64,
    /// Block height in pixels.
    pub height: u64,
    /// Channels per pixel.
    pub channels: u64,
    /// Bytes per sample.
    pub bytes_per_sample: u64,
    /// The block's size.
    pub bytes: u128,
}

/// Refuses a block of `width`×`height` pixels of `channels` samples of `sample` over
/// [`MAX_BLOCK_BYTES`] (as the file declares it: tiles at their full size, even where the image
/// is smaller).
pub fn check_block(
    width: usize,
    height: usize,
    channels: usize,
    sample: Sample,
) -> std::result::Result<(), BlockTooLarge> {
    let bytes_per_sample = match sample {
        Sample::Half => 2,
        Sample::Float => 4,
    };
    let bytes = width as u128 * height as u128 * channels as u128 * bytes_per_sample as u128;
    if bytes <= MAX_BLOCK_BYTES as u128 {
        return Ok(());
    }
    Err(BlockTooLarge {
        width: width as u64,
        height: height as u64,
        channels: channels as u64,
        bytes_per_sample,
        bytes,
    })
}

/// The most channels (bands and alpha) a spectral file may have for readers to read it:
/// OpenImageIO 2.4 reads 32,767 channels and aborts on 32,768 (`std::bad_alloc`; measured with
/// oiiotool 2.4.7 reading files of 16×16 tiles, whose blocks are small, and of 64×64 tiles).
/// OpenImageIO's `limits:channels` attribute (1024 by default) is checked by its TIFF reader
/// only, not by its OpenEXR reader, in 2.4.
pub const MAX_CHANNELS: usize = 32_767;

/// A file of more than [`MAX_CHANNELS`] channels: one OpenImageIO would not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{bands} bands{} would be {} channels; OpenEXR readers (OpenImageIO) read at most {MAX_CHANNELS} ({} bands and alpha): use fewer bands, with a coarser step or a shorter range",
    if *alpha { " and alpha" } else { "" },
    bands + usize::from(*alpha),
    MAX_CHANNELS - 1
)]
pub struct TooManyChannels {
    /// The bands.
    pub bands: usize,
    /// Whether alpha is one more channel.
    pub alpha: bool,
}

/// Refuses a file of `bands` bands (and alpha, when `alpha`) over [`MAX_CHANNELS`] channels.
pub fn check_channels(bands: usize, alpha: bool) -> std::result::Result<(), TooManyChannels> {
    if bands + usize::from(alpha) <= MAX_CHANNELS {
        Ok(())
    } else {
        Err(TooManyChannels { bands, alpha })
    }
}
