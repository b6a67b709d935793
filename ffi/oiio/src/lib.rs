//! Reading images through OpenImageIO: any format OIIO has a plugin for (OpenEXR, TIFF
//! and `.tx`, PNG, JPEG, Radiance HDR, ...), any MIP level, by tile or by rows, always
//! converted to `f32`.
//!
//! An [`ImageReader`] owns one OIIO `ImageInput`. It is `Send` but not `Sync`: each
//! worker opens its own (see [`ImageReader::reopen`]), so tiles decode in parallel
//! without contending for one file handle. The header (every MIP level's geometry,
//! channels, declared colour space) is read once at open and kept in [`ImageInfo`].
//!
//! Coordinates are pixel offsets from the data window origin of the level, so `(0, 0)` is
//! the first stored pixel whatever the file's data window is; [`Level::data`] and
//! [`Level::display`] say where that sits in the file's pixel space.
//!
//! Files with several subimages (OpenEXR parts) are read one subimage at a time: subimage 0
//! unless [`ImageReader::select_subimage`] picks another.
//!
//! All `unsafe` is in `reader.rs`, `texture.rs`, `shim.rs` and `process.rs`, and only calls the C
//! shim of `oiio-sys`, which catches every C++ exception and reports failures as status codes. The
//! shim, and OpenImageIO with it, is loaded when the first image is opened ([`oiio_sys::shim`]),
//! from the file installed beside the program or module, not when the program starts; where it
//! cannot be, opening says so, naming where it looked ([`Error::Unavailable`]).
#![warn(missing_docs)]

mod error;
mod info;
mod pixels;
mod process;
mod reader;
mod shim;
mod texture;

pub use error::{Error, Result};
pub use info::{describe_subimages, Channel, ImageInfo, Level, PixelFormat, Window};
pub use oiio_sys::LoadError;
pub use pixels::{Pixels, Region};
pub use process::{exit, exit_now, ignore_file_size_signal};
pub use reader::ImageReader;
pub use shim::oiio_version;
pub use texture::{make_texture, TextureSpec};
