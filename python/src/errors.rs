//! Library errors as the exceptions of `specconv.errors` (python/specconv/errors.py): each
//! kind a subclass of `ValueError` or `OSError`, with the library's message and, where the
//! library names a remedy, the keyword that applies it.

use pyo3::prelude::*;
use pyo3::types::PyType;
use specconv_conversion::{Cause, Error, Remedy};

/// The exception classes of `specconv.errors`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A setting is wrong (`OptionError`, a `ValueError`).
    Option,
    /// An input cannot be converted as asked (`InputError`, a `ValueError`).
    Input,
    /// A file cannot be read or written (`FileError`, an `OSError`).
    File,
    /// An output exists (`OutputExistsError`, a `FileExistsError`).
    Exists,
}

impl Kind {
    fn class(self) -> &'static str {
        match self {
            Kind::Option => "OptionError",
            Kind::Input => "InputError",
            Kind::File => "FileError",
            Kind::Exists => "OutputExistsError",
        }
    }

    /// The exception with `message`.
    pub fn err(self, message: impl Into<String>) -> PyErr {
        let message = message.into();
        Python::attach(|py| {
            let class = py
                .import("specconv.errors")
                .and_then(|m| m.getattr(self.class()))
                .and_then(|c| Ok(c.cast_into::<PyType>()?));
            match class {
                Ok(class) => PyErr::from_type(class, message),
                Err(e) => e,
            }
        })
    }
}

/// The kind of a conversion error, as the library sorts it.
pub fn kind(e: &Error) -> Kind {
    match e.cause() {
        Cause::Setting => Kind::Option,
        Cause::Input => Kind::Input,
        Cause::File => Kind::File,
        Cause::Exists => Kind::Exists,
        _ => Kind::Input,
    }
}

/// What to pass to fix it, in this package's keywords.
fn hint(remedy: Option<Remedy>) -> &'static str {
    match remedy {
        Some(Remedy::ReplaceOrSkip) => {
            "; pass overwrite=True to replace it (or update=True to skip outputs that are up to date)"
        }
        Some(Remedy::Replace) => "; pass overwrite=True to replace it",
        Some(Remedy::RepairNonFinite) => {
            "; repair them with non_finite=\"box3\" (or \"black\"), or write them as they are with non_finite=\"keep\""
        }
        Some(Remedy::RepairBlack) => "; repair them with non_finite=\"black\"",
        Some(Remedy::NameColourSpace) => "; pass colorspace=NAME",
        Some(Remedy::NameEncodingColourSpace) => {
            "; pass colorspace= the colour space the texture is encoded in"
        }
        Some(Remedy::NameChannelsOrLayer) => {
            "; choose with channels=\"LAYER\" or channels=\"NAME,NAME,NAME\""
        }
        Some(Remedy::NameLayer) => "; choose one with channels=\"LAYER\"",
        Some(Remedy::DropZipLevel) => "; drop zip_level or use compression=\"zip\"",
        Some(Remedy::DataTexture) => {
            "; data=\"skip\" leaves it out, data=\"copy\" writes it through as a data texture, and \
             colorspace=NAME reads it as colour if it is one"
        }
        Some(Remedy::AlreadySpectral) => {
            "; read it with specconv.read_spectral, or convert its colour source instead"
        }
        Some(Remedy::TileTemplate) => ", or pass output_template= with {udim}",
        _ => "",
    }
}

/// A conversion error's message with the keyword that fixes it.
pub fn message(e: &Error) -> String {
    specconv_conversion::message(e) + hint(e.remedy())
}

/// A conversion error as its exception.
pub fn conversion(e: Error) -> PyErr {
    kind(&e).err(message(&e))
}

/// Any other library error (a setting's) as an `OptionError`.
pub fn option(e: impl std::error::Error + 'static) -> PyErr {
    Kind::Option.err(specconv_conversion::message(&e))
}
