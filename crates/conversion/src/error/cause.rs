//! Whose fault an error is: a setting, an input, a file, an existing output ([`Cause`]).

use super::{ConversionError, Error};
use crate::models::ModelError;
use crate::plan;
use crate::wrapped::ImageError;
use specconv_atomic_file::udim::UdimError;
use specconv_atomic_file::{PlanError, WriteError};

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
    /// What the error is about ([`Cause`]).
    pub fn cause(&self) -> Cause {
        use specconv_oiio::Error as Image;
        match self {
            Error::Plan(PlanError::Exists { .. })
            | Error::Model(ModelError::Save(WriteError::Plan(PlanError::Exists { .. })))
            | Error::Conversion(ConversionError::Plan(PlanError::Exists { .. }))
            | Error::Planning(
                plan::Error::Files(PlanError::Exists { .. })
                | plan::Error::NotMadeBySpecconv { .. },
            ) => Cause::Exists,
            // A pattern with no tiles is a missing input; one that cannot be listed, unreadable.
            Error::Planning(
                plan::Error::Files(_)
                | plan::Error::NoDirectory { .. }
                | plan::Error::Udim(UdimError::NoTiles { .. } | UdimError::List { .. }),
            ) => Cause::File,
            Error::Planning(_)
            | Error::Plan(PlanError::WrongExtension { .. })
            | Error::Model(ModelError::Save(WriteError::Plan(PlanError::WrongExtension {
                ..
            }))) => Cause::Setting,
            Error::Plan(_)
            | Error::Model(ModelError::Save(_))
            | Error::Input(_)
            | Error::Read { .. }
            | Error::Write { .. }
            | Error::Attributes(_)
            | Error::Model(ModelError::Read { .. } | ModelError::Spectra { .. }) => Cause::File,
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
            // As the blocks in flight ([`Error::TooMuchMemory`]): the settings ask too much.
            Error::Conversion(ConversionError::TooMuchMemory(_)) => Cause::Setting,
            Error::Conversion(_)
            | Error::EmissionIsItsOwnLight { .. }
            | Error::NotReflectance { .. }
            | Error::Bispectral { .. }
            | Error::CompactNotSpectral { .. }
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
