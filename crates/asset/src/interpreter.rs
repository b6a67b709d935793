//! The interpreter the reader runs and its time limit, as the environment names them, and the
//! line that installs usd-core into it.

use std::ffi::OsStr;

/// The environment variable naming the interpreter that has usd-core.
pub const PYTHON_VAR: &str = "SPECCONV_USD_PYTHON";
/// The environment variable bounding each run of usd-core, in seconds.
pub const TIMEOUT_VAR: &str = "SPECCONV_USD_TIMEOUT";
/// Seconds a run of usd-core may take when `$SPECCONV_USD_TIMEOUT` is not set.
pub const DEFAULT_TIMEOUT: u64 = 300;
/// The command that installs usd-core for `python`.
pub fn install_line(python: &OsStr) -> String {
    format!("{} -m pip install usd-core", python.to_string_lossy())
}
