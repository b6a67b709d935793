//! The conversion job: file ──OIIO──▶ RGB strip ──OCIO──▶ XYZ ──uplift──▶ bands ──exr──▶ file.
//!
//! Work flows in strips: the blocks of the output that share a level and a row. A window of
//! strips is read from the input (one reader, in order, so scanline formats such as PNG decode
//! once) while the previous window's blocks are colour-converted, uplifted and compressed in
//! parallel; chunks are then written in file order. Memory is bounded by the window, whatever
//! the image height, and the output bytes do not depend on the number of threads. What a
//! window needs is estimated before the output exists, and a file that cannot fit is refused
//! with the figure ([`memory`]).
//!
//! The output is written to a temporary file beside the target and renamed into place only
//! when complete: a failed or cancelled job leaves nothing behind. Before it is created, an
//! OpenEXR input's header is checked against the file's size ([`specconv_exr::check`]) and the
//! first window of pixels is read, so a damaged input fails at once.
//!
//! The output keeps the input's data and display windows (OpenEXR gives every MIP level the
//! data window's origin). [`input`] chooses the subimage and the channels read.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod attributes;
mod blocks;
pub mod colour;
pub mod data;
mod data_texture;
mod error;
pub mod expand;
pub mod filter;
pub mod header;
pub mod in_memory;
pub mod input;
pub mod interop;
mod job;
pub mod memory;
mod mip;
mod opened;
pub mod palette;
pub mod png;
mod storage;
mod strips;
pub mod survey;
pub mod texture;
pub mod transfer;
mod uplift;
pub mod wrapped;
mod write;

// The description of a conversion, under its names in this crate.
use specconv_description::{
    choices, layout, metadata, options, report, DataPolicy, Filter, NonFinite, Options, Rounding,
};

pub use colour::{input_space, texture_space, DataTexture, InputSpace, Rule, ToXyz, Warning};
pub use error::{Error, Result};
pub use input::colour_channels;
pub use job::Job;
pub use opened::{open, source_hash, Opened};
pub use storage::{
    Storage, COMPACT_ATTRIBUTE, COMPACT_CHANNELS, EXPAND_ATTRIBUTE, LAYOUT_ATTRIBUTE,
};
pub use uplift::{colour_of, Reading, ABOVE_ONE};
pub use wrapped::{ColourError, ImageError};
