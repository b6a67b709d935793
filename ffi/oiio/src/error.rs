//! What can go wrong opening or reading an image: this crate's error and result.

use std::path::PathBuf;

use crate::LoadError;

/// What can go wrong opening or reading an image.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file does not exist (checked before OpenImageIO is asked).
    #[error("{}: no such file", path.display())]
    NotFound {
        /// The path asked for.
        path: PathBuf,
    },
    /// The file cannot be opened as an image or its header cannot be read: OpenImageIO fails
    /// to open it, it is a directory, its path holds a NUL byte, or it holds no image.
    #[error("{}: cannot be read as an image: {message}", path.display())]
    Open {
        /// The image's path.
        path: PathBuf,
        /// OpenImageIO's message, or specconv's where it refused the file itself.
        message: String,
    },
    /// A valid image of a kind specconv does not read: deep or volume (3D) images, or a MIP
    /// level without pixels or channels.
    #[error("{}: {message}", path.display())]
    Unsupported {
        /// The image's path.
        path: PathBuf,
        /// What the image is that cannot be read.
        message: String,
    },
    /// Pixel data cannot be read: a corrupt or truncated file, or an I/O error.
    #[error("{}: reading pixels failed (is the file truncated or corrupt?): {message}", path.display())]
    Read {
        /// The image's path.
        path: PathBuf,
        /// OpenImageIO's message.
        message: String,
    },
    /// The caller asked for what the image does not have: a subimage, MIP level, tile, rows
    /// or region outside it, or tiles of a scanline image.
    #[error("{}: {message}", path.display())]
    InvalidRequest {
        /// The image's path.
        path: PathBuf,
        /// What was asked for and what the image has, or the shim's message where it refused
        /// the call.
        message: String,
    },
    /// The buffer for a block of pixels cannot be allocated (or its size overflows `usize`).
    #[error("{}: {width}x{height}x{channels} pixels do not fit in memory", path.display())]
    TooLarge {
        /// The image's path.
        path: PathBuf,
        /// Width of the block, in pixels.
        width: u32,
        /// Height of the block, in pixels.
        height: u32,
        /// Channels per pixel (every channel of the image).
        channels: usize,
    },
    /// OpenImageIO raised a C++ exception (caught by the shim), or the shim failed in a way
    /// this crate does not expect there.
    #[error("{}: OpenImageIO failed unexpectedly: {message}", path.display())]
    Internal {
        /// The image's path.
        path: PathBuf,
        /// The shim's message (the exception's text, for an exception).
        message: String,
    },
    /// OpenImageIO's libraries could not be loaded (at the first image opened).
    #[error("{}: cannot be read: {source}", path.display())]
    Unavailable {
        /// The image's path.
        path: PathBuf,
        /// Why the shim or OpenImageIO could not be loaded.
        source: LoadError,
    },
}

/// A result whose error is, by default, this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
