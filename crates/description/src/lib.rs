//! What a conversion is, for the job that does it (`specconv-pipeline`) and the library every
//! front-end calls (`specconv-conversion`): its [`Options`], each [`Key`] defined once (names,
//! flags, value, default, help: [`Key::about`]), the choices and their names ([`Named`]), the
//! report a conversion returns ([`Report`]), the texture metadata an output carries
//! ([`metadata`]) and the channels it writes ([`layout`]). It knows no file, no image and no
//! C++ library: both layers above use it, it uses neither.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod choices;
pub mod definitions;
pub mod key;
pub mod layout;
pub mod metadata;
pub mod named;
pub mod options;
pub mod report;
pub mod wrap;

pub use choices::{Alpha, Compression, DataPolicy, Filter, Layout, Mip, NonFinite, Rounding};
pub use definitions::{definition, Definition, Flag, Takes, Value};
pub use named::{Named, UnknownName};
pub use options::{as_spectral, settings_tag, About, BadValue, Blocks, Key, Options, Resolved};
pub use report::{
    DataOutcome, Notice, NoticeCount, NoticeKind, Report, Role, Strength, DATA_MAP_RULE, PRECEDENCE,
};
pub use specconv_exr::Sample;
pub use wrap::{Wrap, WrapModes, WRAP_NAMES};
