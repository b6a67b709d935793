//! Why a conversion could not be set up or failed, by cause. Messages name no option of any
//! front-end; [`Error::remedy`] says which setting would fix it, and each front-end names that
//! setting its own way (the CLI's flags, the Python package's keywords).

use crate::models::ModelError;
use crate::options::Compression;
use crate::wrapped::{ColourError, ImageError};
use specconv_atomic_file::PlanError;
use std::path::PathBuf;

pub use crate::pipeline::Error as ConversionError;

/// Why a [`crate::Converter`] could not be built, or one conversion failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A deflate level was given with a compression that does not deflate.
    #[error("a deflate level applies to zip and zips only; compression {compression} has none")]
    ZipLevelWithoutZip {
        /// The compression asked for.
        compression: Compression,
    },
    /// A deflate level above 9.
    #[error("deflate level {level} is not one of 0 to 9")]
    ZipLevel {
        /// The level asked for.
        level: u8,
    },
    /// Tiles of no width or height.
    #[error("tiles must be at least 1×1 (asked for {width}×{height})")]
    EmptyTile {
        /// Width asked for.
        width: usize,
        /// Height asked for.
        height: usize,
    },
    /// Tiles larger than OpenEXR's readers accept, at the method's band count.
    #[error(transparent)]
    TileTooLarge(#[from] specconv_exr::BlockTooLarge),
    /// Blocks in flight that need more memory than the machine has.
    #[error("the blocks in flight would need {} MiB, more than this machine's {} MiB; use fewer bands, smaller tiles or fewer worker threads", needed >> 20, have >> 20)]
    TooMuchMemory {
        /// Bytes needed.
        needed: u64,
        /// Bytes the machine has.
        have: u64,
    },
    /// More worker threads than the limit.
    #[error("{threads} worker threads asked for; at most {limit} are started (this machine has {cores} cores)")]
    TooManyThreads {
        /// Threads asked for.
        threads: usize,
        /// The limit.
        limit: usize,
        /// Cores of this machine.
        cores: usize,
    },
    /// Zero worker threads.
    #[error("the conversion needs at least one worker thread")]
    NoThreads,
    /// The worker threads could not be started.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
    /// The OCIO config, or a colour space named in the options, cannot be used.
    #[error(transparent)]
    Colour(#[from] ColourError),
    /// The model cannot be used.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The method cannot be built with these options and this model.
    #[error(transparent)]
    Method(#[from] specconv_spectral::Error),
    /// One conversion failed (the input, its colour, the output; see [`ConversionError`]).
    #[error(transparent)]
    Conversion(#[from] ConversionError),
    /// An input or output of a command other than a conversion may not be used (the output
    /// is an input, exists and may not be replaced, has no directory).
    #[error(transparent)]
    Plan(#[from] specconv_atomic_file::PlanError),
    /// Existing files at outputs' paths that specconv did not make: updating replaces only
    /// specconv's own outputs.
    #[error("{} exists and is not a specconv output{}, which updating never replaces", output.display(), if *more > 0 { format!(" (and {more} more)") } else { String::new() })]
    NotMadeBySpecconv {
        /// The first such output.
        output: PathBuf,
        /// How many more.
        more: usize,
    },
    /// An input is not a file, or is missing.
    #[error(transparent)]
    Input(#[from] specconv_atomic_file::ReadError),
    /// An emissive file was asked to be lit by an illuminant.
    #[error("{} is an emission (S0 channels): it is its own light", input.display())]
    EmissionIsItsOwnLight {
        /// The file.
        input: PathBuf,
    },
    /// The OCIO config lacks a role that is needed.
    #[error("the OCIO config has no {role} role{purpose}")]
    NoRole {
        /// The role.
        role: &'static str,
        /// What it was needed for (with a leading space), or nothing.
        purpose: &'static str,
    },
    /// A spectral EXR cannot be read.
    #[error("cannot read {}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: specconv_exr::Error,
    },
    /// A file cannot be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: specconv_exr::Error,
    },
    /// A `specconv*` attribute of a file does not parse.
    #[error("in {}", path.display())]
    BadProvenance {
        /// The file.
        path: PathBuf,
        /// The attribute and why.
        source: crate::provenance::BadAttribute,
    },
    /// A file of emission where reflectances are needed.
    #[error(
        "{} holds emission (S0 channels), not reflectances: it has no colour to bounce; \
         preview reflectance files (T channels)",
        input.display()
    )]
    NotReflectance {
        /// The file.
        input: PathBuf,
    },
    /// A bispectral file where plain reflectances are needed.
    #[error(
        "{} is bispectral (re-radiation channels): its bounces need the whole re-radiation \
         matrix, which preview does not follow; `to-rgb` shows its colour",
        input.display()
    )]
    Bispectral {
        /// The file.
        input: PathBuf,
    },
    /// A measurement cannot be set up.
    #[error(transparent)]
    Study(#[from] specconv_study::Error),
    /// Colorimetry on a file's bands cannot be set up (an observer or illuminant that does not
    /// cover them).
    #[error(transparent)]
    Colorimetry(specconv_colour::Error),
    /// A spectral EXR's attributes cannot be read ([`crate::describe`]).
    #[error(transparent)]
    Attributes(specconv_exr::Error),
    /// A `specconv*` attribute of a described file does not parse ([`crate::describe`]).
    #[error(transparent)]
    Provenance(crate::provenance::BadAttribute),
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_ocio::Error> for Error {
    fn from(e: specconv_ocio::Error) -> Error {
        Error::Colour(e.into())
    }
}

/// The setting that would fix an error; a front-end says it in its own words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Remedy {
    /// Replace the existing output, or skip outputs that are up to date.
    ReplaceOrSkip,
    /// Repair NaN and infinite input values, or keep them.
    RepairNonFinite,
    /// Repair NaN and infinite input values with black (too many for a 3×3 repair).
    RepairBlack,
    /// Name the input's colour space.
    NameColourSpace,
    /// Name the colour space the texture is encoded in (the file's is a data space).
    NameEncodingColourSpace,
    /// Name the channels or the layer that carry the colour.
    NameChannelsOrLayer,
    /// Name one of several layers.
    NameLayer,
    /// Drop the deflate level, or choose a compression that deflates.
    DropZipLevel,
    /// Replace the existing output.
    Replace,
    /// Drop the illuminant (emission is its own light).
    DropIlluminant,
    /// A data texture: skip it, write it through as data, or name its colour space if it is
    /// colour.
    DataTexture,
    /// A spectral image as input: use it as it is, integrate it to colour, or convert its
    /// colour source on the grid wanted; channels of a colour preview can be named.
    AlreadySpectral,
}

/// What an error is about, for a front-end that sorts errors by kind (the Python package's
/// exception classes): decided here, once, from the typed cause.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Cause {
    /// A setting is wrong (a colour space, a model, a grid, a tile size).
    Setting,
    /// An input cannot be converted as asked (NaN pixels, a data texture, channels to choose).
    Input,
    /// A file cannot be read or written, or may not be (missing, not an image, unreadable, an
    /// output that is an input).
    File,
    /// An output exists and replacing it was not asked for.
    Exists,
}

impl Error {
    /// The setting that would fix it, when one would.
    pub fn remedy(&self) -> Option<Remedy> {
        match self {
            Error::ZipLevelWithoutZip { .. } => Some(Remedy::DropZipLevel),
            Error::Plan(PlanError::Exists { .. }) | Error::NotMadeBySpecconv { .. } => {
                Some(Remedy::Replace)
            }
            Error::EmissionIsItsOwnLight { .. } => Some(Remedy::DropIlluminant),
            Error::NoRole {
                role: "scene_linear",
                ..
            } => Some(Remedy::NameColourSpace),
            Error::Colour(e) => colour_remedy(e),
            Error::Conversion(e) => match e {
                ConversionError::Plan(PlanError::Exists { .. }) => Some(Remedy::ReplaceOrSkip),
                ConversionError::NonFinite { .. } => Some(Remedy::RepairNonFinite),
                ConversionError::TooManyNonFinite { .. } => Some(Remedy::RepairBlack),
                ConversionError::Channels { choose, .. } => choose.map(|c| match c {
                    crate::pipeline::input::Choose::ChannelsOrLayer => Remedy::NameChannelsOrLayer,
                    crate::pipeline::input::Choose::OneLayer => Remedy::NameLayer,
                }),
                ConversionError::Color(e) => colour_remedy(e),
                ConversionError::Data(_) => Some(Remedy::DataTexture),
                ConversionError::Spectral { .. } => Some(Remedy::AlreadySpectral),
                _ => None,
            },
            _ => None,
        }
    }

    /// What the error is about ([`Cause`]).
    pub fn cause(&self) -> Cause {
        use specconv_oiio::Error as Image;
        match self {
            Error::Plan(PlanError::Exists { .. })
            | Error::Conversion(ConversionError::Plan(PlanError::Exists { .. }))
            | Error::NotMadeBySpecconv { .. } => Cause::Exists,
            Error::Plan(_)
            | Error::Input(_)
            | Error::Read { .. }
            | Error::Write { .. }
            | Error::Attributes(_)
            | Error::Model(ModelError::Read { .. }) => Cause::File,
            Error::Conversion(
                ConversionError::Plan(_)
                | ConversionError::Output(_)
                | ConversionError::NotAFile(_)
                // Missing, not an image, unreadable: as Python's own image readers say it.
                | ConversionError::Input(ImageError(
                    Image::NotFound { .. } | Image::Open { .. } | Image::Read { .. },
                )),
            ) => Cause::File,
            Error::Conversion(c) if io_in_chain(c) => Cause::File,
            Error::Conversion(_)
            | Error::EmissionIsItsOwnLight { .. }
            | Error::NotReflectance { .. }
            | Error::Bispectral { .. }
            | Error::Provenance(_) => Cause::Input,
            _ => Cause::Setting,
        }
    }

    /// Whether the output was left alone because the run was cancelled.
    pub fn is_cancelled(&self) -> bool {
        matches!(self, Error::Conversion(ConversionError::Cancelled))
    }
}

/// Whether an I/O error is among the causes of `e`.
fn io_in_chain(e: &(dyn std::error::Error + 'static)) -> bool {
    std::iter::successors(Some(e), |c| c.source()).any(|c| c.is::<std::io::Error>())
}

/// The colour-management error that naming the colour space fixes: a data space.
fn colour_remedy(e: &ColourError) -> Option<Remedy> {
    e.is_data_space().then_some(Remedy::NameEncodingColourSpace)
}

/// An error and its causes on one line, each cause once (`cannot read F: why`), as every
/// front-end says it before naming its own remedy ([`Error::remedy`]).
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    single_line(&chain(e))
}

/// A message of several lines (a TOML error's source snippet, a tool's standard error) on one
/// line: its lines joined by `; `, without the snippet's `N | …` and `| ^` lines.
fn single_line(text: &str) -> String {
    let snippet = |l: &str| {
        l.trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start()
            .starts_with('|')
    };
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !snippet(l))
        .collect::<Vec<_>>()
        .join("; ")
}

/// The cause chain of `e`.
fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut line = e.to_string();
    for cause in std::iter::successors(e.source(), |c| c.source()) {
        let cause = cause.to_string();
        if line.contains(&cause) {
            continue;
        }
        if let Some((head, rest)) = cause.split_once(": ") {
            if line.ends_with(head) {
                line = format!("{line}: {rest}");
                continue;
            }
        }
        // `cannot read F` and `F is not a spectral EXR`: the cause, naming the same file
        // first, says it all.
        let (before, last) = line.rsplit_once(": ").unwrap_or(("", &line));
        let named = last.split_whitespace().last().unwrap_or_default();
        let a_path = named.len() > 1 && named.contains(['/', '.']);
        line = if a_path && cause.starts_with(named) {
            if before.is_empty() {
                cause
            } else {
                format!("{before}: {cause}")
            }
        } else {
            format!("{line}: {cause}")
        };
    }
    line
}
