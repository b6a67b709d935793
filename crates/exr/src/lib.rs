//! Spectral OpenEXR in the layout of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for
//! Spectral Images" (JCGT 10(3), 2021), on the `exr` crate.
//!
//! Reflective bands are channels `T.<wavelength>nm`, emissive bands `S0.<wavelength>nm` with an
//! `emissiveUnits` attribute; the wavelength is written with a comma as decimal separator and
//! six decimals (`T.380,000000nm`), and the header carries `spectralLayoutVersion` = "1.0".
//! Alpha passes through as `A`. OpenEXR sorts channels by name, so `T.1000,…` comes before
//! `T.380,…`: this crate maps bands to channels by name, never by position, in both directions.
//!
//! Writing streams: [`SpectralFile::blocks`] lists the file's tiles (or scanline blocks) of
//! every level; callers fill any block from any thread, [`SpectralFile::encode`] turns it into a
//! compressed chunk, and [`SpectralFile::write`] writes chunks as they come. Nothing holds the
//! whole image.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod attributes;
pub mod blocks;
mod channels;
pub mod check;
mod error;
mod limits;
pub mod quantize;
mod reader;
pub mod rgb;
mod spec;
mod writer;
pub mod zip;

pub use attributes::{
    colour_attributes, read_attributes, standard_attribute, text, text_string, ColourAttributes,
    MAX_NAME_BYTES,
};
pub use channels::{channel_name, parse_channel, parse_channel_name, Channel, ChannelKinds};
pub use error::{Error, Result};
pub use exr::block::chunk::Chunk;
pub use exr::compression::Compression;
pub use limits::{
    check_block, check_channels, BlockTooLarge, TooManyChannels, MAX_BLOCK_BYTES, MAX_CHANNELS,
};
pub use reader::{read, read_level, read_rgba, RgbaSamples, SpectralImage};
pub use spec::{Blocks, Kind, Sample, Spec, Windows, EXTENSIONS};
pub use writer::{check_wavelengths, Block, SpectralFile};
