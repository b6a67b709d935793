//! What specconv may write and how it writes it; the rules every command that writes shares.
//!
//! - [`Pending`]: a file is written into a temporary file beside its target and renamed over it
//!   only when complete. A failed, cancelled or killed writer leaves no partial target, and
//!   readers of the target see the old file or the new one, never half of either.
//! - Temporary names cannot collide: they carry a random part and are created with `O_EXCL`,
//!   so writers in other PID namespaces (containers, nodes on one shared file system) never
//!   share one. Each writer holds a lock on its temporary for as long as it lives; when no
//!   temporary of a target is held, they all belong to dead writers, and the next writer of
//!   that target removes them ([`remove_stale`]; beside a held one nothing is removed, since a
//!   writer given a path, [`Pending::path_for_writer`], has files it cannot lock). While one
//!   writer is live, a second writer of the same target is refused ([`Busy`]) instead of both
//!   succeeding and one silently replacing the other.
//! - [`Pending::commit_new`] publishes only if the target does not exist (a hard link, which
//!   fails on an existing name), so two conversions without `--force` cannot both succeed;
//!   [`Pending::commit`] replaces the target and keeps its mode and, where permitted, its owner.
//! - [`plan`]: the files of a whole job checked before the first write, compared as files
//!   (device and inode, and the directory entry for outputs that do not exist yet), never as
//!   path strings; [`kind`]: special files refused before any read, side files read bounded.
//! - [`shown`]: text from users and input files (names, attributes, licences) is shown one
//!   value to a line, its control characters escaped.
//! - [`shards`]: which files of a job each of N runs converts, one split for the conversion
//!   library's `--shard` and the farm's tasks.
//!
//! ```
//! use std::io::Write;
//! let dir = std::env::temp_dir().join(format!("atomic-file-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let target = dir.join("out.txt");
//! let pending = specconv_atomic_file::Pending::beside(&target)?;
//! writeln!(pending.file(), "whole or nothing")?;
//! assert!(!target.exists());
//! pending.commit_new()?;
//! assert_eq!(std::fs::read_to_string(&target)?, "whole or nothing\n");
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod kind;
mod names;
pub mod outputs;
pub mod plan;
pub mod shards;
pub mod shown;
pub mod udim;

pub use kind::{
    create_own, open_file, open_own, read_bounded, read_bounded_own, readable_file, Kind, ReadError,
};
pub use plan::{
    check as check_plan, check_extension, has_extension, link_below, Place, Places, PlanError,
    Replace, Target,
};

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};

/// A file being written for `target`: commit it to rename it into place; drop it to remove it.
#[derive(Debug)]
pub struct Pending {
    target: PathBuf,
    temporary: Option<PathBuf>,
    file: File,
    /// The path given to a writer that writes by path ([`Pending::path_for_writer`]): the
    /// file to publish instead of `temporary`, which stays locked meanwhile.
    companion: Option<PathBuf>,
}

/// Another writer is writing the same target now (its temporary is locked).
#[derive(Debug, thiserror::Error)]
#[error(
    "another specconv is writing {} now (its temporary file {}); wait for it to finish or choose another output",
    target.display(), other.display()
)]
pub struct Busy {
    /// The target.
    pub target: PathBuf,
    /// The other writer's temporary file.
    pub other: PathBuf,
}

impl Pending {
    /// Creates a new temporary file beside `target` (same directory, so the rename stays on
    /// one file system) and removes the temporaries of dead writers of `target`. Fails with
    /// [`io::ErrorKind::ResourceBusy`] (carrying [`Busy`]) while another writer of `target`
    /// is live.
    pub fn beside(target: &Path) -> io::Result<Pending> {
        let mut attempts = 0;
        let pending = loop {
            // A name or lock lost to another process is rare and passes; a thousand in a row
            // is a file system that never gives one.
            attempts += 1;
            if attempts > 1000 {
                return Err(io::Error::other(format!(
                    "cannot create and lock a temporary file beside {}",
                    target.display()
                )));
            }
            let temporary = names::temporary(target);
            let file = match File::options()
                .read(true)
                .write(true)
                .create_new(true)
                .open(&temporary)
            {
                Ok(f) => f,
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            };
            let pending = Pending {
                target: target.to_path_buf(),
                temporary: Some(temporary),
                file,
                companion: None,
            };
            // Locked and still ours: a cleaner that found it in the instant before the lock
            // may have removed it; then take a new name. A file system without locks gives
            // no way to tell live writers from dead ones: the file is written unlocked.
            match pending.file.try_lock() {
                Ok(()) if pending.is_still_named() => break pending,
                Err(std::fs::TryLockError::Error(_)) => break pending,
                _ => continue,
            }
        };
        // One look at the directory, after ours is locked: of two writers that start at once,
        // at least the later one sees the other. A live writer's unlocked files (those of a
        // writer by path) are only safe while nothing is removed beside a held one.
        let others: Vec<PathBuf> = names::temporaries_of(target)
            .into_iter()
            .filter(|other| Some(other) != pending.temporary.as_ref())
            .collect();
        if let Some(other) = others.iter().find(|other| held(other) == Some(true)) {
            return Err(io::Error::new(
                io::ErrorKind::ResourceBusy,
                Busy {
                    target: target.to_path_buf(),
                    other: other.clone(),
                },
            ));
        }
        for other in others {
            if held(&other) == Some(false) {
                let _ = std::fs::remove_file(&other);
            }
        }
        Ok(pending)
    }

    /// The temporary file to write into (`&File` is `Write`).
    pub fn file(&self) -> &File {
        &self.file
    }

    /// A path for a writer that can only be given one and that may rename a file of its own
    /// over it (OpenImageIO's `make_texture`): another temporary name of the target, not
    /// created here. What the writer leaves at this path is what gets published. Meanwhile
    /// this temporary stays locked, so other writers of the target are refused and nothing of
    /// this writer's (not even the writer's own temporary) is taken for a dead writer's; a
    /// killed writer's files are all temporaries of the target, removed by the next writer.
    pub fn path_for_writer(&mut self) -> &Path {
        let target = &self.target;
        self.companion
            .get_or_insert_with(|| names::temporary(target))
    }

    /// The file to publish and its path, taken so that drop leaves it: the writer by path's
    /// (which must exist), else the temporary.
    fn take_published(&mut self) -> io::Result<(PathBuf, File)> {
        if let Some(companion) = &self.companion {
            // What the writer by path left: a regular file, not a link or FIFO put there.
            let file = kind::open_own(companion, false).map_err(ReadError::into_io)?;
            return Ok((self.companion.take().expect("just seen"), file));
        }
        let file = self.file.try_clone()?;
        let temporary = self
            .temporary
            .take()
            .expect("a pending file has its temporary until published");
        Ok((temporary, file))
    }

    /// Whether the temporary's name still names this file.
    fn is_still_named(&self) -> bool {
        use std::os::unix::fs::MetadataExt;
        let (Some(path), Ok(ours)) = (&self.temporary, self.file.metadata()) else {
            return false;
        };
        std::fs::symlink_metadata(path)
            .is_ok_and(|m| m.dev() == ours.dev() && m.ino() == ours.ino())
    }

    /// Renames the temporary file over the target, which keeps the replaced file's mode and,
    /// where the process may set it, its owner.
    pub fn commit(mut self) -> io::Result<()> {
        let (temporary, file) = self.take_published()?;
        let renamed = file
            .sync_all()
            .and_then(|()| self.keep_mode_and_owner(&file))
            .and_then(|()| std::fs::rename(&temporary, &self.target));
        if renamed.is_err() {
            let _ = std::fs::remove_file(&temporary);
        }
        // Drop removes the locked temporary of a writer by path, now that its file is out.
        renamed
    }

    /// Publishes the temporary file as the target only if no file has that name: fails with
    /// [`io::ErrorKind::AlreadyExists`] otherwise (another writer finished first), leaving
    /// the existing file as it was.
    pub fn commit_new(mut self) -> io::Result<()> {
        let (temporary, file) = self.take_published()?;
        if let Err(e) = file.sync_all() {
            let _ = std::fs::remove_file(&temporary);
            return Err(e);
        }
        // A hard link is created only where no name is: the check and the publishing are one
        // step. File systems without hard links fall back to a check, then a rename.
        let published = match std::fs::hard_link(&temporary, &self.target) {
            Err(e) if e.kind() != io::ErrorKind::AlreadyExists => {
                if std::fs::symlink_metadata(&self.target).is_ok() {
                    Err(io::Error::from(io::ErrorKind::AlreadyExists))
                } else {
                    std::fs::rename(&temporary, &self.target)
                }
            }
            linked => linked,
        };
        let _ = std::fs::remove_file(&temporary);
        published
    }

    /// [`Pending::commit`] when `replace` allows it, else [`Pending::commit_new`].
    pub fn publish(self, replace: Replace) -> io::Result<()> {
        match replace {
            Replace::Allowed => self.commit(),
            Replace::Never => self.commit_new(),
        }
    }

    /// Gives the temporary the mode and owner of the file it replaces.
    fn keep_mode_and_owner(&self, file: &File) -> io::Result<()> {
        use std::os::unix::fs::MetadataExt;
        let Ok(old) = std::fs::metadata(&self.target) else {
            return Ok(());
        };
        if !old.is_file() {
            return Ok(());
        }
        // Not permitted (another user's file, not root): the file becomes ours, as cp's.
        let _ = std::os::unix::fs::fchown(file, Some(old.uid()), Some(old.gid()));
        file.set_permissions(old.permissions())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        // The locked one last: until it goes, other writers keep away from the rest.
        for t in [self.companion.take(), self.temporary.take()]
            .into_iter()
            .flatten()
        {
            let _ = std::fs::remove_file(t);
        }
    }
}

/// An I/O error met while writing, with what it means said plainly where the system's words
/// are terse: a write past the file size limit (`EFBIG`: `ulimit -f`, which Slurm passes on
/// from the submitting shell; SIGXFSZ is ignored so that the write fails instead of killing
/// the process), a full disk (`ENOSPC`), a disk quota (`EDQUOT`). Others pass unchanged.
pub fn explained(e: io::Error) -> io::Error {
    let what = match e.raw_os_error() {
        Some(libc::EFBIG) => {
            "larger than this process's file size limit allows (ulimit -f; a Slurm job inherits \
             the submitting shell's): raise the limit or write a smaller file"
        }
        Some(libc::ENOSPC) => "the disk is full: free some space or write elsewhere",
        Some(libc::EDQUOT) => "the disk quota is used up: free some space or write elsewhere",
        _ => return e,
    };
    io::Error::new(e.kind(), format!("{what} ({e})"))
}

/// Writes `bytes` to `target` through a [`Pending`] file, replacing it if it exists.
pub fn write(target: &Path, bytes: &[u8]) -> io::Result<()> {
    use std::io::Write;
    let pending = Pending::beside(target)?;
    pending.file().write_all(bytes).map_err(explained)?;
    pending.commit()
}

/// Writes `bytes` to `target` for a command that read `inputs`: the plan checked
/// ([`check_plan`]: never over an input, an existing target only when `replace` allows), then
/// written through a [`Pending`] file.
pub fn write_checked(
    target: &Path,
    bytes: &[u8],
    inputs: &[&Path],
    replace: Replace,
) -> Result<(), WriteError> {
    use std::io::Write;
    check_plan(inputs, &[target], replace)?;
    let io = |source| WriteError::Io {
        path: target.to_path_buf(),
        source,
    };
    let pending = Pending::beside(target).map_err(io)?;
    pending
        .file()
        .write_all(bytes)
        .map_err(|e| io(explained(e)))?;
    pending.publish(replace).map_err(|e| match e.kind() {
        io::ErrorKind::AlreadyExists => WriteError::Plan(PlanError::Exists {
            output: target.to_path_buf(),
            more: 0,
        }),
        _ => io(e),
    })
}

/// Why [`write_checked`] wrote nothing.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The target may not be written.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// Writing failed.
    #[error("cannot write {}", path.display())]
    Io {
        /// The target.
        path: PathBuf,
        /// Why.
        #[source]
        source: io::Error,
    },
}

/// Every temporary file of `target` present now, live or left by a killed writer.
pub fn leftovers(target: &Path) -> Vec<PathBuf> {
    names::temporaries_of(target)
}

/// Removes the temporary files of `target` left by writers killed before they could remove
/// them (SIGKILL, a lost node) and returns them: all of them when no live writer holds one,
/// else none (a live writer by path has files it cannot lock, [`Pending::path_for_writer`]).
pub fn remove_stale(target: &Path) -> Vec<PathBuf> {
    let all = names::temporaries_of(target);
    if all.iter().any(|t| held(t) == Some(true)) {
        return Vec::new();
    }
    all.into_iter()
        .filter(|t| held(t) == Some(false) && std::fs::remove_file(t).is_ok())
        .collect()
}

/// Whether a writer holds `temporary` (its lock); `None` when it cannot be told (gone, not ours
/// to open, or not a regular file: a FIFO or link named like a temporary is nobody's, kept,
/// and never opened in a way that could block).
fn held(temporary: &Path) -> Option<bool> {
    let f = kind::open_own(temporary, false).ok()?;
    match f.try_lock_shared() {
        Ok(()) => Some(false),
        Err(std::fs::TryLockError::WouldBlock) => Some(true),
        Err(std::fs::TryLockError::Error(_)) => None,
    }
}

/// Whether two paths name the same existing file, compared as files (device and inode), not as
/// path strings: links, `..`, bind mounts and other aliases are seen through.
pub fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::FileTypeExt;

    pub(crate) fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("atomic-file-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_dropped_file_leaves_nothing_and_a_committed_one_replaces_the_target() {
        let d = scratch("drop");
        let target = d.join("t.exr");
        std::fs::write(&target, b"old").unwrap();
        {
            let p = Pending::beside(&target).unwrap();
            std::io::Write::write_all(&mut p.file(), b"half").unwrap();
            assert_eq!(leftovers(&target).len(), 1);
        }
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert!(leftovers(&target).is_empty());
        write(&target, b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn a_second_live_writer_of_one_target_is_refused_and_a_dead_ones_file_is_removed() {
        let d = scratch("two");
        let target = d.join("t.exr");
        let a = Pending::beside(&target).unwrap();
        let e = Pending::beside(&target).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::ResourceBusy);
        assert!(e.to_string().contains("another specconv is writing"), "{e}");
        assert_eq!(
            leftovers(&target).len(),
            1,
            "the refused writer left nothing"
        );
        drop(a);
        // A killed writer's file (no lock held), in this version's names and the old ones.
        let dead = names::temporary(&target);
        std::fs::write(&dead, b"theirs").unwrap();
        let old_style = d.join(".t.exr.specconv-4242-0.tmp");
        std::fs::write(&old_style, b"older").unwrap();
        let c = Pending::beside(&target).unwrap();
        assert!(
            !dead.exists() && !old_style.exists(),
            "stale temporaries removed"
        );
        c.commit_new().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"");
        assert!(leftovers(&target).is_empty());
        std::fs::remove_dir_all(d).unwrap();
    }

    /// What OpenImageIO's `make_texture` does with a path it is given: writes
    /// `STEM.XXXXXXXX.temp.tmp` beside it, then renames that over the path.
    fn write_as_make_texture(path: &Path, bytes: &[u8]) -> PathBuf {
        let name = path.file_name().unwrap().to_str().unwrap();
        let own = path.with_file_name(name.replace(".tmp", ".5bce1f2c.temp.tmp"));
        std::fs::write(&own, bytes).unwrap();
        own
    }

    #[test]
    fn a_writer_by_path_keeps_others_out_and_what_it_leaves_is_published() {
        let d = scratch("by-path");
        let target = d.join("t.exr");
        std::fs::write(&target, b"old").unwrap();
        let mut a = Pending::beside(&target).unwrap();
        let path = a.path_for_writer().to_path_buf();
        assert_eq!(a.path_for_writer(), path, "one path per pending file");
        let own = write_as_make_texture(&path, b"new");
        // Mid-write: the writer's own temporary is not locked, yet it is not a dead writer's.
        assert_eq!(leftovers(&target).len(), 2);
        assert!(remove_stale(&target).is_empty());
        let e = Pending::beside(&target).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::ResourceBusy);
        assert!(own.exists(), "the refused writer removed nothing");
        std::fs::rename(&own, &path).unwrap();
        assert!(Pending::beside(&target).is_err());
        a.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert!(leftovers(&target).is_empty());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);

        // Publishing what the writer did not leave fails, and leaves nothing either.
        let mut b = Pending::beside(&target).unwrap();
        b.path_for_writer();
        assert_eq!(b.commit_new().unwrap_err().kind(), io::ErrorKind::NotFound);
        let mut c = Pending::beside(&target).unwrap();
        let path = c.path_for_writer().to_path_buf();
        std::fs::write(&path, b"newer").unwrap();
        drop(c);
        assert!(leftovers(&target).is_empty());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");

        // A killed writer by path leaves three unlocked files; the next writer removes them.
        let dead = [names::temporary(&target), names::temporary(&target)];
        std::fs::write(&dead[0], b"").unwrap();
        let own = write_as_make_texture(&dead[1], b"half");
        assert_eq!(leftovers(&target).len(), 2);
        std::fs::write(&dead[1], b"whole").unwrap();
        assert_eq!(leftovers(&target).len(), 3);
        // Names that only look alike are another target's or nobody's: kept.
        let alike = [
            ".t.exr.specconv-12ab.x.temp.tmp",
            ".t.exr.specconv-.1234.temp.tmp",
        ];
        for n in alike {
            std::fs::write(d.join(n), b"").unwrap();
        }
        Pending::beside(&target).unwrap().commit().unwrap();
        assert!(!own.exists() && !dead[0].exists() && !dead[1].exists());
        assert!(leftovers(&target).is_empty());
        assert!(alike.iter().all(|n| d.join(n).exists()));
        std::fs::remove_dir_all(d).unwrap();
    }

    /// Runs `f` on a thread of its own; fails the test if it has not returned after 10 s (it
    /// blocked, as opening a FIFO does), instead of hanging.
    pub(crate) fn within_bound<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(f()));
        rx.recv_timeout(std::time::Duration::from_secs(10))
            .expect("blocked: still running after 10 s")
    }

    pub(crate) fn mkfifo(path: &Path) {
        let made = std::process::Command::new("mkfifo").arg(path).status();
        assert!(made.unwrap().success(), "mkfifo {}", path.display());
    }

    #[test]
    fn special_files_named_like_temporaries_never_block_a_writer_and_are_kept() {
        // Anyone who may write to a shared output folder can plant these (issue 31, case 1).
        let d = scratch("planted");
        let target = d.join("ff.exr");
        let fifo = d.join(".ff.exr.specconv-2222222222222222.tmp");
        mkfifo(&fifo);
        let zero = d.join(".ff.exr.specconv-3333333333333333.tmp");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let victim = d.join("victim.png");
        std::fs::write(&victim, b"theirs").unwrap();
        let link = d.join(".ff.exr.specconv-4444444444444444.tmp");
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        let t = target.clone();
        within_bound(move || write(&t, b"whole")).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"whole");
        let t = target.clone();
        assert!(within_bound(move || remove_stale(&t)).is_empty());
        // Nobody's temporaries: neither removed nor followed.
        assert_eq!(leftovers(&target).len(), 3);
        assert!(std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo());
        assert_eq!(std::fs::read(&victim).unwrap(), b"theirs");
        let t = target.clone();
        within_bound(move || write(&t, b"again")).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"again");
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn commit_new_never_replaces_and_commit_keeps_the_mode() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("new");
        let target = d.join("t.exr");
        std::fs::write(&target, b"first").unwrap();
        let p = Pending::beside(&target).unwrap();
        std::io::Write::write_all(&mut p.file(), b"second").unwrap();
        assert_eq!(
            p.commit_new().unwrap_err().kind(),
            io::ErrorKind::AlreadyExists
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"first");
        assert!(leftovers(&target).is_empty());
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        write(&target, b"third").unwrap();
        let mode = std::fs::metadata(&target).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o640);
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn a_name_as_long_as_the_file_system_allows_can_be_written() {
        let d = scratch("long");
        let target = d.join(format!("{}.exr", "n".repeat(251)));
        write(&target, b"x").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"x");
        assert!(leftovers(&target).is_empty());
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn aliases_of_one_file_are_the_same_file() {
        let d = scratch("same");
        let a = d.join("a.exr");
        std::fs::write(&a, b"x").unwrap();
        std::os::unix::fs::symlink(&a, d.join("link.exr")).unwrap();
        std::fs::hard_link(&a, d.join("hard.exr")).unwrap();
        std::fs::create_dir(d.join("sub")).unwrap();
        for alias in ["link.exr", "hard.exr", "sub/../a.exr", "./a.exr"] {
            assert!(same_file(&a, &d.join(alias)), "{alias}");
        }
        std::fs::write(d.join("b.exr"), b"x").unwrap();
        assert!(!same_file(&a, &d.join("b.exr")));
        assert!(!same_file(&a, &d.join("missing.exr")));
        std::fs::remove_dir_all(d).unwrap();
    }
}
