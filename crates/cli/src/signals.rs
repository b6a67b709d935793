//! SIGINT, SIGTERM and SIGHUP, from the start of `main` on, for every command.
//!
//! Until a command writes an output, a signal ends the process at once, whatever it is doing
//! (parsing, loading a model, building tables, reading a file): one line, exit status 130,
//! nothing written. While it writes ([`deferred`]), a signal only sets the writer's cancel
//! flag: a batch stops within a block (its output not published, its temporary file
//! removed) and ends with status 130 itself; a single write ([`writing`]) completes or fails
//! as it would have, then the command ends with status 130. A second signal to a writer that
//! has not stopped ends the process at once.
//!
//! The handler runs on ctrlc's own thread. It decides under the same lock that a writer takes
//! to start and to stop writing, so a signal never ends the process between "not yet
//! writing" and a temporary file being made.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// What a signal does now: `None` ends the process; `Some(flag)` sets the writer's flag.
static WRITER: Mutex<Option<Arc<AtomicBool>>> = Mutex::new(None);

/// The line every interrupted command ends with.
pub(crate) const LINE: &str = "interrupted; no partial output was left";

/// A signal came while an output was written; the command ends with status 130.
#[derive(Debug)]
pub(crate) struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(LINE)
    }
}

impl std::error::Error for Interrupted {}

fn writer() -> MutexGuard<'static, Option<Arc<AtomicBool>>> {
    WRITER.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Installs the handler; the first thing `main` does.
pub(crate) fn install() {
    // Without a handler (no thread could be made) the default action still ends the process
    // and leaves at most a temporary file, which the next conversion of that output removes.
    let _ = ctrlc::set_handler(|| {
        let writer = writer();
        match writer.as_ref() {
            // The first signal while writing stops the writer cleanly.
            Some(cancel) if !cancel.swap(true, Ordering::SeqCst) => {}
            // Before writing, or a second signal to a writer that does not stop (a read that
            // never ends): at once; as after SIGKILL, a temporary file may stay.
            _ => {
                crate::print_error(LINE);
                // Holding the lock: no write can start before the process is gone.
                specconv_oiio::exit_now(crate::exit::INTERRUPTED)
            }
        }
    });
}

/// Runs `f`, which writes outputs and stops when `cancel` is set, with signals setting
/// `cancel` instead of ending the process.
pub(crate) fn deferred<T>(cancel: &Arc<AtomicBool>, f: impl FnOnce() -> T) -> T {
    *writer() = Some(cancel.clone());
    let result = f();
    *writer() = None;
    result
}

/// Runs `f`, a write that cannot stop midway (an atomic write of a whole file), with
/// signals deferred: a signal during it gives [`Interrupted`] once it is done.
pub(crate) fn writing<T>(f: impl FnOnce() -> anyhow::Result<T>) -> anyhow::Result<T> {
    let cancel = Arc::new(AtomicBool::new(false));
    let result = deferred(&cancel, f);
    if cancel.load(Ordering::SeqCst) {
        return Err(Interrupted.into());
    }
    result
}
