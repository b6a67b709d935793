//! Library errors as the exceptions of `specconv.errors` (python/specconv/errors.py): each
//! kind a subclass of `ValueError` or `OSError`, with the library's message and, where the
//! library names a remedy, the keyword that applies it.

use pyo3::prelude::*;
use pyo3::types::PyType;
use specconv_conversion::{Cause, Error, Key, Remedy, Spelling};

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

/// A keyword of this package: the option's name ([`Key::about`]).
fn kw(key: Key) -> &'static str {
    key.about().name
}

/// What to pass to fix it, in this package's keywords: the library words it
/// ([`Remedy::advice`], spelt by [`Keywords`]); the package words the remedies that are its own.
fn hint(remedy: Option<Remedy>) -> String {
    let Some(remedy) = remedy else {
        return String::new();
    };
    let own = match remedy {
        Remedy::DropZipLevel => format!(
            "; drop {} or use {}=\"zip\"",
            kw(Key::ZipLevel),
            kw(Key::Compression)
        ),
        Remedy::NonEmptyTiles => format!(
            "; pass {0}=(W, H) of at least 1×1, or {0}=\"scanline\"",
            kw(Key::Tile)
        ),
        Remedy::SomeThreads => format!("; pass {}= at least 1", kw(Key::Threads)),
        Remedy::OneClusterModel => format!(
            "; pass {}= a model of one cluster (specconv.Model.train(..., clusters=1))",
            kw(Key::Model)
        ),
        Remedy::AlreadySpectral => {
            "; read it with specconv.read_spectral, or convert its colour source instead".into()
        }
        Remedy::ExpandCompact => {
            "; specconv.read_compact reads its texels, and `specconv expand` writes its spectra"
                .into()
        }
        Remedy::TileTemplate => ", or pass output_template= with {udim}".into(),
        // Looking at a spectral file under a light: not this package's.
        Remedy::DropIlluminant => String::new(),
        _ => return remedy.advice(&Keywords).unwrap_or_default(),
    };
    own
}

/// This package's spelling of the options a remedy names: its keywords.
struct Keywords;

impl Spelling for Keywords {
    fn option(&self, key: Key) -> String {
        format!("{}=", kw(key))
    }
    fn given(&self, key: Key, value: &str) -> String {
        format!("{}={}", kw(key), self.value(value))
    }
    fn value(&self, value: &str) -> String {
        format!("\"{value}\"")
    }
    fn on(&self, key: Key) -> String {
        format!("{}=True", kw(key))
    }
    fn update(&self) -> String {
        "update=True".into()
    }
}

/// A conversion error's message with the keyword that fixes it.
pub fn message(e: &Error) -> String {
    specconv_conversion::message(e) + &hint(e.remedy())
}

/// A conversion error as its exception.
pub fn conversion(e: Error) -> PyErr {
    kind(&e).err(message(&e))
}

/// Any other library error (a setting's) as an `OptionError`.
pub fn option(e: impl std::error::Error + 'static) -> PyErr {
    Kind::Option.err(specconv_conversion::message(&e))
}
