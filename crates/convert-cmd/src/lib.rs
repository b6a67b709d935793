//! The convert command, which the command line's `convert`, `expand` and `asset` and the farm's
//! tasks all run (`convert`), and the ground every command of the program stands on: what it
//! prints, through `stdio` (never `println!`); how it fails, one line in this program's flags
//! (`errors`); its exit statuses (`exit`); the checks made once before the first input
//! (`checks`); progress, JSON records, `--shard` and signals. The cli and the farm command
//! (specconv-farm-cmd) sit on it; the work happens in the library crates.
#![forbid(unsafe_code)]

#[macro_use]
pub mod stdio;
pub mod checks;
pub mod convert;
pub mod errors;
pub mod exit;
pub mod progress;
pub mod records;
pub mod shard;
pub mod signals;
