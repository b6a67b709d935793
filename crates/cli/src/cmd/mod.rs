//! One module per subcommand: its clap arguments (whose doc comments are the help text and man
//! page) and its `run`; `convert` and `farm` are crates of their own (specconv-convert-cmd,
//! specconv-farm-cmd).
pub mod asset;
pub mod colorspaces;
pub mod completions;
pub mod eval;
pub mod expand;
pub mod info;
pub mod models;
pub mod preview;
pub mod report;
pub mod simulate;
pub mod to_rgb;
pub mod train;
