//! Why a conversion failed ([`Error`], by cause), and the pipeline's [`Result`].

use crate::data_texture::DataTexture;
use crate::memory::Shortfall;
use std::path::PathBuf;

/// Why a conversion failed, by cause. Messages name no command-line option: a front-end adds
/// its own hint (the CLI's flags, the Python package's keywords).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be read.
    #[error(transparent)]
    Input(#[from] crate::wrapped::ImageError),
    /// The input's colour could not be managed.
    #[error(transparent)]
    Color(#[from] crate::wrapped::ColourError),
    /// The output could not be written.
    #[error(transparent)]
    Output(#[from] specconv_exr::Error),
    /// An OpenEXR input whose header does not match its size.
    #[error(transparent)]
    Damaged(#[from] specconv_exr::check::Problem),
    /// The channels asked for, or those found, cannot carry a colour.
    #[error("{}: {what}; its channels are {channels}", path.display())]
    Channels {
        /// The input.
        path: PathBuf,
        /// What is wrong with them.
        what: String,
        /// The channels the input has, and its layers.
        channels: String,
        /// What naming would settle it, where naming would.
        choose: Option<Choose>,
    },
    /// The format's default colour space cannot be reached in the config.
    #[error("{0}")]
    DefaultColourSpace(String),
    /// Pixels in memory that cannot be made texels as given ([`in_memory`](crate::in_memory)).
    #[error("{0}")]
    InMemory(String),
    /// NaN or infinite values in the channels read, refused.
    #[error(
        "{}: {pixels} pixel(s) of rows {}–{} have NaN or infinite values (the first at x {}, y {}); \
         every filter that reads them, MIP levels included, spreads them",
        input.display(), rows.0, rows.1 - 1, first.0, first.1
    )]
    NonFinite {
        /// The input.
        input: PathBuf,
        /// Such pixels found (the pass stops at the first rows that have any).
        pixels: u64,
        /// The first (x, y).
        first: (usize, usize),
        /// The rows read when they were found.
        rows: (usize, usize),
    },
    /// More non-finite pixels than box3 repairs.
    #[error(
        "{}: more than {limit} pixels have NaN or infinite values, more than a 3×3 repair keeps",
        input.display()
    )]
    TooManyNonFinite {
        /// The input.
        input: PathBuf,
        /// `survey::BOX3_LIMIT`.
        limit: u64,
    },
    /// The weights half rounding keeps the colour under are not on the method's grid.
    #[error("the XYZ weights have {have} bands where the method makes {want}")]
    Weights {
        /// Bands of the weights.
        have: usize,
        /// Bands of the method.
        want: usize,
    },
    /// The input is not a file (a directory, a device, a FIFO), or is missing.
    #[error(transparent)]
    NotAFile(#[from] specconv_atomic_file::ReadError),
    /// The output may not be written: it is the input, exists and may not be replaced, or has
    /// no directory.
    #[error(transparent)]
    Plan(#[from] specconv_atomic_file::PlanError),
    /// Writing the output failed.
    #[error("cannot write {}", path.display())]
    Io {
        /// The output.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Stopped through the job's cancel flag.
    #[error("cancelled")]
    Cancelled,
    /// The input is a compact spectral texture (`input::open`): its texels are spectra, not
    /// colours to uplift again.
    #[error(
        "{}: a compact spectral texture (specconv's compact layout): its spectra are not \
         uplifted again from its colour",
        path.display()
    )]
    Compact {
        /// The input.
        path: PathBuf,
    },
    /// The input is a spectral image already (`input::open`): it is not uplifted again.
    #[error(
        "{}: already a spectral image ({} bands of {}, {}–{} nm, the Fichet 2021 layout): \
         its spectra are not uplifted again from a colour",
        path.display(), bands, if *emissive { "emission" } else { "reflectance" }, range_nm.0, range_nm.1
    )]
    Spectral {
        /// The input.
        path: PathBuf,
        /// `S0.` channels (emission) rather than `T.` (reflectance).
        emissive: bool,
        /// Its bands.
        bands: usize,
        /// Its first and last wavelengths.
        range_nm: (f64, f64),
    },
    /// The input holds data, not colour (`colour::texture_space`): it is never uplifted.
    #[error(transparent)]
    Data(Box<DataTexture>),
    /// A file to expand that is not a compact texture this version reads.
    #[error("{}: not a compact texture: {why}", path.display())]
    NotCompact {
        /// The file.
        path: PathBuf,
        /// What is missing or wrong.
        why: String,
    },
    /// The file would need more memory at once than this process may use
    /// ([`memory`](crate::memory)): refused before the output exists.
    #[error("{0}")]
    TooMuchMemory(Shortfall),
    /// A warning, which the strict setting makes a failure: nothing was written.
    #[error(
        "{}: {warning}; in strict mode a warning fails the input, and nothing was written",
        input.display()
    )]
    Strict {
        /// The input.
        input: PathBuf,
        /// The warning ([`specconv_description::Notice`]'s words).
        warning: String,
    },
}

/// What a caller could name to settle which channels carry the colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choose {
    /// The channels, or a layer.
    ChannelsOrLayer,
    /// One of several layers.
    OneLayer,
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_oiio::Error> for Error {
    fn from(e: specconv_oiio::Error) -> Error {
        Error::Input(e.into())
    }
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_ocio::Error> for Error {
    fn from(e: specconv_ocio::Error) -> Error {
        Error::Color(e.into())
    }
}

// The memory rule knows nothing of the pipeline's error; its refusal becomes one here.
impl From<Shortfall> for Error {
    fn from(s: Shortfall) -> Error {
        Error::TooMuchMemory(s)
    }
}

/// The pipeline's results.
pub type Result<T> = std::result::Result<T, Error>;
