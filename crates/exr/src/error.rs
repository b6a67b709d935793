//! What can go wrong writing or reading a spectral file, and this crate's result.

use crate::limits::{BlockTooLarge, TooManyChannels};

/// What can go wrong writing or reading a spectral file.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Something the layout or this crate does not allow, named in the text: an empty image, no
    /// bands, two bands with one channel name, bad tile size, windows beyond 32-bit coordinates, a
    /// non-text attribute name, a file without spectral channels, or re-radiation without its
    /// bands.
    #[error("{0}")]
    Invalid(String),
    /// A block larger than OpenEXR's readers accept.
    #[error(transparent)]
    BlockTooLarge(#[from] BlockTooLarge),
    /// More channels than OpenEXR's readers accept.
    #[error(transparent)]
    TooManyChannels(#[from] TooManyChannels),
    /// An error of the `exr` crate: I/O, or a file it cannot read or write.
    #[error("OpenEXR: {0}")]
    Exr(#[from] exr::error::Error),
    /// A path to read that is no regular file (a FIFO, a device, a directory) or is missing:
    /// refused by kind, without blocking.
    #[error(transparent)]
    File(#[from] specconv_atomic_file::ReadError),
}

impl Error {
    /// The I/O error of the file system underneath (a full disk, a file size limit), if that is
    /// what this is; else the error itself.
    pub fn into_io(self) -> std::result::Result<std::io::Error, Error> {
        match self {
            Error::Exr(exr::error::Error::Io(e)) => Ok(e),
            e => Err(e),
        }
    }
}

/// This crate's result, with [`enum@Error`].
pub type Result<T> = std::result::Result<T, Error>;
