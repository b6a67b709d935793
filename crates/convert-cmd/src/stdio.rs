//! Everything the program prints goes through here, never through `println!` or `eprintln!`,
//! which panic when the stream is closed or full (clippy.toml forbids them in the crates that print: this one, the farm command's and the cli).
//!
//! Standard output is what scripts read, so a write that fails there stops the command: its
//! error, [`StdoutFailed`], travels up with `?` (a batch sets its cancel flag and stops after
//! the current input). A closed pipe (`| head -1`) ends the command quietly with exit status
//! 141, what a shell reports for a process killed by SIGPIPE, so that `set -o pipefail` sees
//! it; any other failure (`> /dev/full`) is one error line and exit status 1. Standard error
//! is for people: a write that fails there is ignored (there is nowhere left to say it).

use std::fmt;
use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// A write to standard output failed; the command stops.
#[derive(Debug)]
pub struct StdoutFailed(std::io::Error);

impl fmt::Display for StdoutFailed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot write to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutFailed {}

impl StdoutFailed {
    /// The failure of a write to standard output made elsewhere (clap's help).
    pub fn new(e: std::io::Error) -> StdoutFailed {
        StdoutFailed(e)
    }

    /// The exit status: [`crate::exit::PIPE`] when the reader went away, else
    /// [`crate::exit::FAILED`].
    pub fn status(&self) -> i32 {
        if self.closed() {
            crate::exit::PIPE
        } else {
            crate::exit::FAILED
        }
    }

    /// The reader closed the pipe (EPIPE): the command ends without a word, as it would
    /// have by SIGPIPE.
    pub fn closed(&self) -> bool {
        self.0.kind() == ErrorKind::BrokenPipe
    }

    /// The failure anywhere in `e`'s chain of causes.
    pub fn in_chain(e: &anyhow::Error) -> Option<&StdoutFailed> {
        e.chain().find_map(|c| c.downcast_ref::<StdoutFailed>())
    }
}

/// A batch's records on standard output: the first write that fails cancels the batch (the
/// input being converted ends as usual; no later input starts) and is kept for the batch's
/// ending to report.
pub struct BatchOutput<'a> {
    cancel: &'a AtomicBool,
    failed: Option<StdoutFailed>,
}

impl<'a> BatchOutput<'a> {
    /// Records for the batch that `cancel` stops.
    pub fn new(cancel: &'a AtomicBool) -> BatchOutput<'a> {
        BatchOutput {
            cancel,
            failed: None,
        }
    }

    /// Takes the outcome of one record's write.
    pub fn said(&mut self, written: Result<(), StdoutFailed>) {
        if let Err(e) = written {
            self.cancel.store(true, Ordering::SeqCst);
            self.failed.get_or_insert(e);
        }
    }

    /// The first failed write, if any.
    pub fn failed(self) -> Option<StdoutFailed> {
        self.failed
    }
}

/// Writes `args` to standard output and flushes, so that a failure shows here, not at exit.
pub fn out(args: fmt::Arguments) -> Result<(), StdoutFailed> {
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(args)
        .and_then(|()| stdout.flush())
        .map_err(StdoutFailed)
}

/// Writes `bytes` to standard output (a generated script, completions).
pub fn out_bytes(bytes: &[u8]) -> Result<(), StdoutFailed> {
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(bytes)
        .and_then(|()| stdout.flush())
        .map_err(StdoutFailed)
}

/// Writes `args` to standard error; a failure is ignored.
pub fn err(args: fmt::Arguments) {
    let _ = std::io::stderr().lock().write_fmt(args);
}

/// `println!` that returns [`StdoutFailed`] instead of panicking.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::stdio::out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::stdio::out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that returns [`StdoutFailed`] instead of panicking.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdio::out(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics.
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::stdio::err(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprint!` that never panics.
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => {
        $crate::stdio::err(format_args!($($arg)*))
    };
}

/// Paths in JSON records, written losslessly (the conversion library's rule, docs/json.md).
pub use specconv_conversion::record::serialize_path;

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    use std::path::Path;

    /// Python's json and os.fsencode give back the exact bytes: the escaping is the one a
    /// script can undo (the test kit's Python: $SPECCONV_PYTHON, else python3).
    #[test]
    fn python_decodes_the_escaped_path_to_the_same_bytes() {
        let bytes: &[u8] = b"/t/caf\xe9 \"\xff\xfe\"/\xc3\xa9\xed\xa0\x80.png";
        #[derive(serde::Serialize)]
        struct Record<'a> {
            #[serde(serialize_with = "serialize_path")]
            input: &'a Path,
        }
        let record = serde_json::to_string(&Record {
            input: Path::new(OsStr::from_bytes(bytes)),
        })
        .unwrap();
        let decoded = specconv_testkit::cmd::python_output([
            "-c",
            "import json, os, sys; sys.stdout.buffer.write(os.fsencode(json.loads(sys.argv[1])['input']))",
            &record,
        ]);
        assert_eq!(decoded, bytes, "{record}");
    }
}
