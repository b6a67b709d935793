//! Why an asset cannot be read or planned: this crate's error.

use crate::file_names::RECORD;
use crate::interpreter::{install_line, PROTOCOL, PYTHON_VAR, TIMEOUT_VAR};
use std::ffi::OsString;
use std::path::PathBuf;

/// Why an asset cannot be read or planned. Nothing has been converted.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The interpreter cannot be started.
    #[error(
        "cannot run the Python interpreter '{}' ({source}): the USD reader is Pixar's usd-core \
         in Python 3; install it ({}) or name an interpreter that has it with {PYTHON_VAR}",
        python.to_string_lossy(), install_line(python)
    )]
    NoPython {
        /// The interpreter.
        python: OsString,
        /// Why it did not start.
        source: std::io::Error,
    },
    /// The interpreter has no usd-core.
    #[error(
        "the Python interpreter '{}' has no usd-core (the pxr module), which reads USD stages: \
         install it with `{}`, or name an interpreter that has it with {PYTHON_VAR}",
        python.to_string_lossy(), install_line(python)
    )]
    NoUsd {
        /// The interpreter.
        python: OsString,
    },
    /// `$SPECCONV_USD_TIMEOUT` is not a number of seconds.
    #[error("{TIMEOUT_VAR}={value:?} is not a positive number of seconds")]
    BadTimeout {
        /// Its value.
        value: String,
    },
    /// The stage is not a regular file (a FIFO, a device, a directory) or does not exist.
    #[error("the stage {}: {why}", stage.display())]
    NotAStage {
        /// The path given.
        stage: PathBuf,
        /// What it is instead.
        why: String,
    },
    /// The interpreter has no MaterialX, and a MaterialX document is to be read.
    #[error(
        "the Python interpreter '{}' has no MaterialX, which reads the MaterialX document {}: \
         install it with `{} -m pip install MaterialX`, or name an interpreter that has it \
         with {PYTHON_VAR}",
        python.to_string_lossy(), document.display(), python.to_string_lossy()
    )]
    NoMaterialX {
        /// The interpreter.
        python: OsString,
        /// The document.
        document: PathBuf,
    },
    /// usd-core could not open it.
    #[error("usd-core cannot open the stage: {detail}")]
    Open {
        /// usd-core's words.
        detail: String,
    },
    /// MaterialX could not read a document (or one it includes).
    #[error("{detail}")]
    Document {
        /// What MaterialX (or the check before it) said, naming the file.
        detail: String,
    },
    /// Composition failed somewhere: a texture may be missing from the list.
    #[error(
        "the stage {} does not compose: {first}{}; nothing is converted, since a texture \
         may be missing from what composed",
        stage.display(),
        if *more > 0 { format!(" (and {more} more)") } else { String::new() }
    )]
    Composition {
        /// The stage.
        stage: PathBuf,
        /// The first error, in usd-core's words.
        first: String,
        /// How many more.
        more: usize,
    },
    /// usd-core did not answer in time.
    #[error(
        "usd-core did not finish reading within {seconds} s (a layer that is a FIFO or a \
         device, or a very large stage; {TIMEOUT_VAR} sets the limit)"
    )]
    Timeout {
        /// The limit.
        seconds: u64,
    },
    /// The reader answered in another protocol than this program's (or in none).
    #[error(
        "the asset reader run by '{}' answered {}, and this specconv reads protocol \
         {PROTOCOL}: it is not the reader this specconv carries (a wrapper named by {PYTHON_VAR} \
         that runs another, or a specconv Python package whose compiled module and Python \
         files come from different versions); name a plain Python 3 with {PYTHON_VAR}, or \
         reinstall specconv",
        python.to_string_lossy(),
        match found { Some(v) => format!("in protocol {v}"), None => "with no protocol version".into() }
    )]
    Protocol {
        /// The interpreter.
        python: OsString,
        /// The version it answered in (its JSON text), if any.
        found: Option<String>,
    },
    /// The reader failed otherwise.
    #[error("reading the asset failed: {0}")]
    Reader(String),
    /// The layer exists and may not be replaced.
    #[error("{} exists: update (-u) or force replaces it", layer.display())]
    LayerExists {
        /// The layer.
        layer: PathBuf,
    },
    /// An output would be a file the stage reads (issue 57): never, whatever the flags.
    #[error(
        "{} is a file the stage reads: specconv asset never writes over what it reads, -u and \
         --force included; choose another -o DIR",
        output.display()
    )]
    WritesItsInput {
        /// The output.
        output: PathBuf,
    },
    /// An output exists that no asset run wrote ([`record`](crate::record)).
    #[error(
        "{} exists and specconv asset did not write it (it is not in the folder's {}): move it \
         away or choose another -o DIR; -u and --force replace only files the asset wrote",
        path.display(), RECORD
    )]
    NotWrittenByAsset {
        /// The file.
        path: PathBuf,
    },
    /// An output the asset wrote was changed since ([`record`](crate::record)).
    #[error(
        "{} changed since specconv asset wrote it: move it away to keep it, or delete it to \
         have it written again",
        path.display()
    )]
    ChangedSinceWritten {
        /// The file.
        path: PathBuf,
    },
    /// The record of what the asset wrote cannot be read or written.
    #[error(
        "{}: the record of what specconv asset wrote in this folder cannot be used ({why}); \
         without it no file here is replaced",
        path.display()
    )]
    Record {
        /// The record.
        path: PathBuf,
        /// Why.
        why: String,
    },
    /// The OCIO config cannot be used.
    #[error("{0}")]
    Config(Box<specconv_conversion::Error>),
    /// A folder or path under DIR.
    #[error("{}: {}", .0.display(), .1)]
    Io(PathBuf, std::io::Error),
    /// A folder below DIR that is a symbolic link, which would take outputs outside DIR.
    #[error(
        "{} is a symbolic link below the output folder {}: outputs are written only inside          it; remove the link or choose a fresh folder",
        link.display(),
        dir.display()
    )]
    LinkBelowDir {
        /// The link.
        link: PathBuf,
        /// The output folder.
        dir: PathBuf,
    },
}

impl Error {
    /// The caller's fault, found before anything was converted (a usage error): the stage is
    /// not a file, the layer exists, an output is an input or a file the asset did not write,
    /// the config or a setting cannot be used.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            Error::NotAStage { .. }
                | Error::LayerExists { .. }
                | Error::WritesItsInput { .. }
                | Error::NotWrittenByAsset { .. }
                | Error::ChangedSinceWritten { .. }
                | Error::Config(_)
                | Error::BadTimeout { .. }
                | Error::LinkBelowDir { .. }
        )
    }
}
