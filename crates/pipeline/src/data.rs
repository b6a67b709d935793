//! Data textures written through ([`copy`]): a texture that holds numbers (a roughness or
//! normal map, [`crate::colour::DataTexture`]) is never uplifted; asked to, it is written as
//! the tiled, MIP-mapped OpenEXR texture maketx would make of it, its values unconverted.
//!
//! A copy meets a conversion's rules although OpenImageIO's `make_texture` can neither be
//! stopped midway nor be trusted on a full disk (OpenEXR 3.1's tiled writer waits forever
//! after a failed write). So it runs on a thread of its own while the caller watches:
//!
//! - the cancel flag, every [`POLL`]: set before the output is published, the copy is
//!   abandoned at once, its files removed ([`Error::Cancelled`]); the decision is taken where
//!   the output is published, so a copy is either published and reported, or not there;
//! - a writer that stalls on a full file system: the copy fails naming the output
//!   ([`Error::Io`], `StorageFull`), its files emptied and removed;
//! - an abandoned writer that ends later removes what it made; one that never ends (the
//!   full disk) holds only an emptied, unnamed file until the process ends.

use crate::error::{Error, Result};
use specconv_atomic_file::{Pending, Replace};
use specconv_oiio::TextureSpec;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Condvar, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Cancelled copies whose writer still runs inside OpenImageIO, and the condition their end
/// is told by ([`settle`]).
static ABANDONED: (Mutex<usize>, Condvar) = (Mutex::new(0), Condvar::new());

/// Waits, at most `timeout`, for the writers of cancelled copies to end; whether none runs
/// now. A process that ends while one runs inside OpenImageIO runs the library's static
/// destructors under it (a crash): a front-end that cannot end with `_exit` (Python) calls this
/// at exit. A writer stalled on a full disk is not waited for (it never ends).
pub fn settle(timeout: Duration) -> bool {
    let (count, ended) = &ABANDONED;
    let count = count.lock().unwrap_or_else(PoisonError::into_inner);
    let (count, _) = ended
        .wait_timeout_while(count, timeout, |n| *n > 0)
        .unwrap_or_else(PoisonError::into_inner);
    *count == 0
}

/// Counts a cancelled copy's writer until it ends.
fn abandon(counted: &AtomicBool) {
    *ABANDONED.0.lock().unwrap_or_else(PoisonError::into_inner) += 1;
    counted.store(true, Ordering::SeqCst);
}

/// A counted writer has ended.
fn ended(counted: &AtomicBool) {
    if counted.load(Ordering::SeqCst) {
        let mut n = ABANDONED.0.lock().unwrap_or_else(PoisonError::into_inner);
        *n = n.saturating_sub(1);
        ABANDONED.1.notify_all();
    }
}

/// How often the caller looks at the cancel flag while the copy is written.
pub const POLL: Duration = Duration::from_millis(20);

/// How long the writer's file may stay the same size before the file system is asked
/// whether it is full.
const STALL: Duration = Duration::from_millis(300);

/// How [`copy`] writes.
#[derive(Debug, Clone)]
pub struct Copy<'a> {
    /// The subimage of the input to write through.
    pub subimage: u32,
    /// Tile width and height.
    pub tile: (u32, u32),
    /// OpenEXR compression, as OpenImageIO names it.
    pub compression: &'a str,
    /// Replace an existing output.
    pub overwrite: bool,
    /// Attributes recorded in the output (the caller's provenance).
    pub attributes: &'a [(String, String)],
    /// Set to stop the copy before its output is published.
    pub cancel: &'a AtomicBool,
}

/// Writes `input` through to `output` as a tiled, MIP-mapped data texture with OpenImageIO's
/// `make_texture` (box-filtered levels, the input's metadata and wrap modes kept), through a
/// temporary published only when complete; never over the input. Returns the levels written.
/// Stops within [`POLL`] of `how.cancel` being set, unless the output was already published.
pub fn copy(input: &Path, output: &Path, how: &Copy) -> Result<usize> {
    specconv_atomic_file::readable_file(input)?;
    specconv_atomic_file::check_plan(&[input], &[output], Replace::when(how.overwrite))?;
    let io = |source| Error::Io {
        path: output.to_path_buf(),
        source,
    };
    let mut pending = Pending::beside(output).map_err(io)?;
    let spec = TextureSpec {
        subimage: how.subimage,
        tile: how.tile,
        compression: how.compression.to_owned(),
        attributes: how.attributes.to_vec(),
    };
    // OpenImageIO writes its own temporary and renames it over the path it is given: a path
    // of the pending file's, which stays locked until the result is published.
    let written = pending.path_for_writer().to_path_buf();
    let writer = Writer {
        output: output.to_path_buf(),
        written: written.clone(),
    };
    let (done, result) = mpsc::channel();
    let counted = Arc::new(AtomicBool::new(false));
    {
        let (input, writer, counted) = (input.to_path_buf(), writer.clone(), counted.clone());
        std::thread::Builder::new()
            .name("specconv-copy".into())
            .spawn(move || {
                let made = specconv_oiio::make_texture(&input, &writer.written, &spec);
                // Nobody waits any more: the copy was abandoned; remove what it made.
                if done.send(made).is_err() {
                    writer.remove();
                    ended(&counted);
                }
            })
            .map_err(io)?;
    }
    if let Err(e) = watch(&writer, &pending, &result, how.cancel) {
        if matches!(e, Error::Cancelled) {
            abandon(&counted);
        }
        // Dropping `result` tells a writer still running that it was abandoned.
        writer.remove();
        return Err(e);
    }
    let levels = specconv_oiio::ImageReader::open(&written)?
        .info()
        .levels
        .len();
    // The decision: cancelled before this point, nothing is published.
    if how.cancel.load(Ordering::SeqCst) {
        return Err(Error::Cancelled);
    }
    pending.publish(Replace::when(how.overwrite)).map_err(io)?;
    Ok(levels)
}

/// Waits for the writer: its result, or the cancel flag, or a stall on a full file system.
fn watch(
    writer: &Writer,
    pending: &Pending,
    result: &mpsc::Receiver<specconv_oiio::Result<()>>,
    cancel: &AtomicBool,
) -> Result<()> {
    let mut size = (None, Instant::now());
    loop {
        if cancel.load(Ordering::SeqCst) {
            return Err(Error::Cancelled);
        }
        match result.recv_timeout(POLL) {
            Ok(Ok(())) => return Ok(()),
            // OpenImageIO says only that it failed: a full disk is told by the disk.
            Ok(Err(e)) => {
                return Err(match full(pending, writer.largest()) {
                    Some(source) => writer.io(source),
                    None => e.into(),
                })
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(writer.io(std::io::Error::other(
                    "the thread writing it ended without a result",
                )))
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        let now = writer.size();
        if now != size.0 {
            size = (now, Instant::now());
        } else if now.is_some() && size.1.elapsed() >= STALL {
            if let Some(source) = full(pending, writer.largest()) {
                return Err(writer.io(source));
            }
            size.1 = Instant::now();
        }
    }
}

/// Whether the file system refuses the writer more bytes (full, over quota, or past the
/// process's file size limit, `ulimit -f`): the error a small write into `pending` meets at
/// the writer's current size, `at` (the write is undone).
fn full(pending: &Pending, at: u64) -> Option<std::io::Error> {
    use std::os::unix::fs::FileExt;
    let file = pending.file();
    let wrote = file
        .write_all_at(&[0; 4096], at)
        .and_then(|()| file.sync_data());
    let _ = file.set_len(0);
    match wrote {
        Err(e) if is_full(&e) => Some(e),
        _ => None,
    }
}

/// ENOSPC, EDQUOT or EFBIG.
fn is_full(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::StorageFull
            | std::io::ErrorKind::QuotaExceeded
            | std::io::ErrorKind::FileTooLarge
    )
}

/// The files one copy writes: the path given to OpenImageIO and OpenImageIO's own temporary
/// of it.
#[derive(Debug, Clone)]
struct Writer {
    output: PathBuf,
    written: PathBuf,
}

impl Writer {
    /// This writer's files present now (never another writer's of the same output).
    fn files(&self) -> Vec<PathBuf> {
        let Some(stem) = self
            .written
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_suffix(".tmp"))
        else {
            return Vec::new();
        };
        let own = format!("{stem}.");
        specconv_atomic_file::leftovers(&self.output)
            .into_iter()
            .filter(|t| {
                t.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(&own))
            })
            .collect()
    }

    /// The size of its largest file now (0 when none): where a write past `ulimit -f` fails.
    fn largest(&self) -> u64 {
        self.files()
            .iter()
            .filter_map(|f| std::fs::symlink_metadata(f).ok())
            .map(|m| m.len())
            .max()
            .unwrap_or(0)
    }

    /// The bytes written so far; `None` until OpenImageIO has made its file.
    fn size(&self) -> Option<u64> {
        let files = self.files();
        (!files.is_empty()).then(|| {
            files
                .iter()
                .filter_map(|f| std::fs::symlink_metadata(f).ok())
                .map(|m| m.len())
                .sum()
        })
    }

    /// Empties and removes this writer's files (emptied first: a writer that never ends keeps
    /// its file open, and a removed file's blocks are freed only when it is closed).
    fn remove(&self) {
        for f in self.files().into_iter().chain([self.written.clone()]) {
            if let Ok(file) = std::fs::OpenOptions::new().write(true).open(&f) {
                let _ = file.set_len(0);
            }
            let _ = std::fs::remove_file(&f);
        }
    }

    /// A failed write of the output.
    fn io(&self, source: std::io::Error) -> Error {
        Error::Io {
            path: self.output.clone(),
            source: specconv_atomic_file::explained(source),
        }
    }
}
