//! SIGINT, SIGTERM and SIGHUP, from the start of `main` on, for every command; SIGXFSZ
//! ignored (a write past the file size limit fails with an error instead, nothing left).
//! SIGPIPE is ignored by Rust's runtime (a closed stdout is [`crate::stdio`]'s). Other signals
//! that end a process (SIGKILL, SIGXCPU past `ulimit -t`, SIGSEGV) may leave a temporary file,
//! never an output: the next writer of that output removes it.
//!
//! Until a command writes an output, a signal ends the process at once, whatever it is doing
//! (parsing, loading a model, building tables, reading a file): one line, exit status 130,
//! nothing written. From its first write on ([`deferred`]), a signal only sets the writer's
//! cancel flag: a batch, or `to-rgb`, stops within a block (its output not published, its
//! temporary file removed) and ends with status 130; a signal after the last output was
//! published stops nothing, and the command ends with the status of what it did. A signal to
//! a writer that has not stopped two seconds after the first ends the process at once.
//!
//! The handler runs on ctrlc's own thread. It decides under the same lock that a writer takes
//! to start and to stop writing, so a signal never ends the process between "not yet
//! writing" and a temporary file being made.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// What a signal does now: `None` ends the process; `Some` stops the writer.
static WRITER: Mutex<Option<Writer>> = Mutex::new(None);

/// A command writing outputs.
struct Writer {
    /// Set to stop it.
    cancel: Arc<AtomicBool>,
    /// When the first signal came.
    signalled: Option<Instant>,
}

/// How long a writer has to stop before another signal ends the process at once. Signals
/// that come together are one request: scancel signals both a task's script and the
/// conversion, and the script passes its signal on.
const PATIENCE: Duration = Duration::from_secs(2);

/// The line every interrupted command ends with.
pub(crate) const LINE: &str = "interrupted; no partial output was left";

/// A signal came while an output was written; the command ends with status 130.
#[derive(Debug)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(LINE)
    }
}

impl std::error::Error for Interrupted {}

fn writer() -> MutexGuard<'static, Option<Writer>> {
    WRITER.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Installs the handler; the first thing `main` does. SIGXFSZ (a write past `ulimit -f`) is
/// ignored, so that the write fails, is reported and its temporary removed.
pub fn install() {
    specconv_conversion::ignore_file_size_signal();
    // Without a handler (no thread could be made) the default action still ends the process
    // and leaves at most a temporary file, as SIGKILL would.
    let _ = ctrlc::set_handler(|| {
        let mut writer = writer();
        match writer.as_mut() {
            // While writing, signals stop the writer cleanly.
            Some(w) if w.signalled.is_none_or(|first| first.elapsed() < PATIENCE) => {
                w.signalled.get_or_insert_with(Instant::now);
                w.cancel.store(true, Ordering::SeqCst);
            }
            // Before writing, or again to a writer that has not stopped (a read that never
            // ends): at once; as after SIGKILL, a temporary file may stay.
            _ => {
                crate::errors::print_error(LINE);
                // Holding the lock: no write can start before the process is gone.
                specconv_conversion::exit_now(crate::exit::INTERRUPTED)
            }
        }
    });
}

/// [`deferred`] with a cancel flag of its own for one library call that writes one output:
/// a cancelled call is [`Interrupted`], any other error explained.
pub fn one_output<T>(
    f: impl FnOnce(&AtomicBool) -> Result<T, specconv_conversion::Error>,
) -> anyhow::Result<T> {
    let cancel = Arc::new(AtomicBool::new(false));
    match deferred(&cancel, || f(&cancel)) {
        Err(e) if e.is_cancelled() => Err(Interrupted.into()),
        r => r.map_err(|e| anyhow::anyhow!(crate::errors::explain(&e))),
    }
}

/// Runs `f`, which writes outputs and stops when `cancel` is set, with signals setting
/// `cancel` instead of ending the process. They still do once `f` has returned: what it wrote
/// is complete, and a signal that comes while the command reports it must not end the process
/// with "no partial output was left" and status 130 beside a published output (the command
/// ends with the status of what it did).
pub fn deferred<T>(cancel: &Arc<AtomicBool>, f: impl FnOnce() -> T) -> T {
    *writer() = Some(Writer {
        cancel: cancel.clone(),
        signalled: None,
    });
    f()
}
