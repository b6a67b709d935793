//! What can go wrong with colour management: this crate's error, with the wording its messages
//! share, and its result.

use std::path::PathBuf;

/// What can go wrong with colour management.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// There is no config file at the path (nothing there, or not a regular file: a device or
    /// FIFO would block or never end); checked before OpenColorIO is asked.
    #[error("OCIO config {}: {}", path.display(), match kind {
        specconv_atomic_file::Kind::Missing => "no such file".to_string(),
        k => format!("{k}, not a config file"),
    })]
    ConfigNotFound {
        /// The config's path.
        path: PathBuf,
        /// What is there instead.
        kind: specconv_atomic_file::Kind,
    },
    /// An `ocio://` name that picks no built-in config.
    #[error(
        "unknown built-in OCIO config '{name}'; pass a config file or one of the built-in \
         configs: {}",
        quote_list(known)
    )]
    UnknownBuiltinConfig {
        /// The name given.
        name: String,
        /// Every name that picks a built-in config ([`BUILTIN_NAMES`](crate::BUILTIN_NAMES)).
        known: Vec<String>,
    },
    /// OpenColorIO cannot read, parse or validate the config, or fails to answer a question
    /// about it (its colour spaces, roles, lists, file rules).
    #[error("OCIO config {origin} failed to load: {message}")]
    ConfigLoad {
        /// Where the config came from, as [`ConfigSource`](crate::ConfigSource) displays it.
        origin: String,
        /// OpenColorIO's message, through the shim.
        message: String,
    },
    /// The config has no colour space, alias or role of that name.
    #[error(
        "unknown colour space '{name}' in OCIO config {origin}; {}",
        suggest(close)
    )]
    UnknownColorSpace {
        /// The name asked for.
        name: String,
        /// Where the config came from, as [`ConfigSource`](crate::ConfigSource) displays it.
        origin: String,
        /// The config's colour spaces with names close to it
        /// ([`Config::close_names`](crate::Config::close_names));
        /// empty when none is close.
        close: Vec<String>,
    },
    /// The config has neither role that leads to CIE XYZ
    /// ([`Config::processor_to_xyz`](crate::Config::processor_to_xyz)).
    #[error(
        "OCIO config {origin} has neither a cie_xyz_d65_interchange nor an aces_interchange \
         role, so there is no way to CIE XYZ; add one of them to the config's roles"
    )]
    NoInterchangeRole {
        /// Where the config came from, as [`ConfigSource`](crate::ConfigSource) displays it.
        origin: String,
    },
    /// The colour space is a data space
    /// (`Raw`, [`ColorSpace::is_data`](crate::ColorSpace::is_data)), which is not converted to
    /// CIE XYZ.
    #[error("colour space '{name}' holds data, not colour, and cannot be uplifted to a spectrum")]
    DataColorSpace {
        /// The colour space's canonical name.
        name: String,
    },
    /// OpenColorIO cannot build a processor, or apply one.
    #[error("OpenColorIO could not convert '{src}' to '{dst}': {message}")]
    Processor {
        /// The source colour space (canonical name).
        src: String,
        /// The destination: a colour space, `DISPLAY / VIEW` for a view, or `CIE XYZ (D65)`
        /// when an XYZ processor fails to apply.
        dst: String,
        /// OpenColorIO's message, through the shim.
        message: String,
    },
    /// An argument that cannot be passed on or that the shim refused: a string with a NUL
    /// byte, pixel data that is not whole pixels; holds the reason.
    #[error("invalid argument: {0}")]
    Argument(String),
}

fn suggest(close: &[String]) -> String {
    if close.is_empty() {
        "run `specconv colorspaces` to list the config's colour spaces".into()
    } else {
        format!("did you mean {}?", quote_list(close))
    }
}

fn quote_list(names: &[String]) -> String {
    names
        .iter()
        .map(|n| format!("'{n}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A result whose error is, by default, this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
