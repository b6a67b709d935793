//! The interpreter the reader runs and its time limit, as the environment names them, the
//! line that installs usd-core into it, and the version of the protocol the reader speaks.

use std::ffi::OsStr;

/// The environment variable naming the interpreter that has usd-core.
pub const PYTHON_VAR: &str = "SPECCONV_USD_PYTHON";
/// The environment variable bounding each run of usd-core, in seconds.
pub const TIMEOUT_VAR: &str = "SPECCONV_USD_TIMEOUT";
/// Seconds a run of usd-core may take when `$SPECCONV_USD_TIMEOUT` is not set.
pub const DEFAULT_TIMEOUT: u64 = 300;
/// The version of the reader's protocol, which its `protocol.py` says too (a test checks):
/// raised whenever a request or an answer changes shape.
pub const PROTOCOL: u64 = 1;
/// The command that installs usd-core for `python`.
pub fn install_line(python: &OsStr) -> String {
    format!("{} -m pip install usd-core", python.to_string_lossy())
}
