//! The conversion as a library: what `specconv convert` does, for every front-end (the command
//! line, the Python package, a farm task) to do the same with the same bytes.
//!
//! - [`Options`]: a typed description of a conversion (colour, channels, method, model, grid,
//!   emission, samples, compression, tiles, MIP levels, threads), with the command line's
//!   defaults.
//! - [`Converter`]: built once from options, checked up front ([`Error`] by cause, with the
//!   [`Remedy`] that would fix it); [`Converter::convert`] returns a [`Report`] of that call
//!   alone — nothing is shared between calls.
//! - [`Batch`]: inputs in turn, with the up-to-date check (`-u`), cancellation and progress
//!   [`Event`]s.
//! - [`provenance`]: the `specconv*` attributes, written and read in one place.
//! - [`record`]: what every front-end says of each input (`convert --json`'s records).
//! - [`models`] and [`tables`]: the model and the Jakob 2019 table cache every front-end shares.
//!
//! ```no_run
//! use specconv_conversion::{Converter, Options};
//! let mut options = Options::default();
//! options.colorspace = Some("ACEScg".into());
//! let report = Converter::new(options)?.convert("plate.exr".as_ref(), "plate_spectral.exr".as_ref())?;
//! assert_eq!(report.bands, 36);
//! # Ok::<(), specconv_conversion::Error>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod batch;
mod choices;
mod converter;
pub mod cost;
mod error;
pub mod images;
pub mod models;
mod named;
mod options;
mod pipeline;
pub mod preview;
pub mod provenance;
pub mod record;
mod report;
pub mod tables;
pub mod to_rgb;

pub use crate::pipeline::texture::parse_wrapmodes;
pub use crate::pipeline::DataTexture;
pub use batch::{check_plan, Batch, Event, Summary};
pub use converter::{Advice, Converter, Rule, Selection, Warning};
pub use error::{message, Cause, ConversionError, Error, Remedy};
pub use named::{Named, UnknownName};
pub use options::{
    About, Alpha, BadValue, Blocks, Compression, DataPolicy, Filter, Key, Mip, NonFinite, Options,
    Rounding, Sample, Wrap, WrapModes, WRAP_NAMES,
};
pub use provenance::Provenance;
pub use report::{DataOutcome, Report, Role};
/// Ends the process at once, without C++ static destructors: for a signal handler's thread
/// while the libraries may be in use (`specconv_oiio::exit_now`).
pub use specconv_oiio::exit_now;
pub use specconv_spectral::bounded::Counts;

/// The OpenColorIO configs and colour spaces every front-end reads colour through (the same
/// config rules as a conversion: `ocio`, else `$OCIO`, else the built-in ACES config).
pub mod ocio {
    pub use specconv_ocio::{is_builtin_name, ColorSpace, Config, ConfigSource, Error, Processor};
}
