//! The conversion as a library: what `specconv convert` does, for every front-end (the command
//! line, the Python package, a farm task) to do the same with the same bytes.
//!
//! - [`Options`]: a typed description of a conversion (colour, channels, method, model, grid,
//!   emission, samples, compression, tiles, MIP levels, threads), with the command line's
//!   defaults.
//! - [`Converter`]: built once from options, checked up front ([`Error`] by cause, with the
//!   [`Remedy`] that would fix it); [`Converter::convert`] returns a [`Report`] of that call
//!   alone — nothing is shared between calls.
//! - [`Plan`]: which file each input becomes ([`Outputs`]: files, a directory, a template;
//!   UDIM patterns), checked as a whole, split into shards, existing outputs refused per shard
//!   ([`plan`]).
//! - [`Batch`]: inputs in turn, with the up-to-date check (`-u`), cancellation and progress
//!   [`Event`]s.
//! - [`provenance`]: the `specconv*` attributes, written and read in one place.
//! - [`record`]: what every front-end says of each input (`convert --json`'s records).
//! - [`models`] and [`tables`]: the model and the Jakob 2019 table cache every front-end shares.
//! - [`describe`]: what a conversion would make of an image, without converting it (`info`);
//!   [`ColourConfig`]: the OCIO config, its colour spaces and routes to XYZ, as plain data.
//!
//! No type of the C++ libraries (OpenImageIO, OpenColorIO, Little CMS) is part of this API:
//! front-ends reach them only through it, and their errors are wrapped ([`ImageError`],
//! [`ColourError`]) with their messages kept.
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
mod colour_config;
pub mod compact;
mod converter;
pub mod cost;
mod describe;
mod error;
pub mod images;
pub mod models;
pub mod plan;
pub mod preview;
mod process;
pub mod provenance;
pub mod record;
pub mod tables;
pub mod to_rgb;

// The description of a conversion and the job, under their names in this crate.
pub use process::{exit_now, ignore_file_size_signal, settle_copies};
pub use specconv_description::{definition, layout, metadata, Definition, Flag, Takes, Value};
use specconv_description::{named, options, report};
use specconv_pipeline as pipeline;
use specconv_pipeline::wrapped;

pub use batch::{expansion_is_up_to_date, Batch, Event, Expansions, Summary};
pub use colour_config::{is_builtin_config, ColourConfig, ColourSpace, ConfigOrigin, XyzTransform};
pub use compact::{check_compact_header, expand, read_compact, spectral_read_error, CompactFacts};
pub use converter::{
    Advice, Converter, InMemory, Rule, Samples, Selection, Texels, TexelsMade, Warning,
};
pub use describe::{
    describe, Channel, ChannelChoice, ChannelReason, Inspection, ReadAs, SpectralFacts, Window,
};
pub use error::{message, remedy_of, Cause, ConversionError, Error, Remedy, Spelling};
pub use named::{Named, UnknownName};
pub use options::{
    About, Alpha, BadValue, Blocks, Compression, DataPolicy, Filter, Key, Layout, Mip, NonFinite,
    Options, Rounding, Sample, Wrap, WrapModes, WRAP_NAMES,
};
pub use pipeline::colour::Decoded;
pub use pipeline::expand::{CompactTexels, Expanded};
pub use pipeline::interop;
pub use pipeline::palette;
pub use pipeline::DataTexture;
pub use plan::{check_plan, Outputs, Plan};
pub use provenance::Provenance;
pub use report::{
    DataOutcome, Notice, NoticeCount, NoticeKind, Report, Role, Strength, DATA_MAP_RULE, PRECEDENCE,
};
pub use wrapped::{ColourError, ImageError};
