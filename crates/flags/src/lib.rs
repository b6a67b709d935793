//! The command line's flags, each defined once. The conversion's options come from the
//! library's definitions ([`OptionArgs`]); every command's own flags are one table
//! ([`defs`]), and a command's arguments are a struct naming which it takes ([`args!`]). The
//! CLI declares no flag of its own: its tests list any.
#![forbid(unsafe_code)]

pub mod defs;
mod field;
mod flag;
mod options;

pub use field::{Field, Value};
pub use flag::{DefaultValue, Flag};
pub use options::{
    Blending, Configuring, Conversion, ConversionArgs, ForceArg, OptionArgs, Reading, Replacing,
    Stacking, Taken,
};
