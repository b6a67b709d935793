//! The one way specconv writes a file: into a temporary file beside the target, renamed over
//! it only when complete. A failed, cancelled or killed writer leaves no partial target (a
//! killed one leaves its temporary, which [`leftovers`] finds), and readers of the target see
//! the old file or the new one, never half of either.
//!
//! ```
//! use std::io::Write;
//! let dir = std::env::temp_dir().join(format!("atomic-file-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! let target = dir.join("out.txt");
//! let pending = specconv_atomic_file::Pending::beside(&target)?;
//! writeln!(pending.file(), "whole or nothing")?;
//! assert!(!target.exists());
//! pending.commit()?;
//! assert_eq!(std::fs::read_to_string(&target)?, "whole or nothing\n");
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), std::io::Error>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A file being written for `target`: commit it to rename it into place; drop it to remove it.
#[derive(Debug)]
pub struct Pending {
    target: PathBuf,
    temporary: Option<PathBuf>,
    file: File,
}

impl Pending {
    /// Creates a new temporary file beside `target` (same directory, so the rename stays on
    /// one file system). Its name is new: never a file another writer holds.
    pub fn beside(target: &Path) -> io::Result<Pending> {
        loop {
            let temporary = temporary_path(target);
            match File::options()
                .write(true)
                .create_new(true)
                .open(&temporary)
            {
                Ok(file) => {
                    return Ok(Pending {
                        target: target.to_path_buf(),
                        temporary: Some(temporary),
                        file,
                    })
                }
                // Another writer's name: take the next.
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// The temporary file to write into (`&File` is `Write`).
    pub fn file(&self) -> &File {
        &self.file
    }

    /// Renames the temporary file over the target.
    pub fn commit(mut self) -> io::Result<()> {
        let temporary = self
            .temporary
            .take()
            .expect("a pending file has its temporary");
        let renamed = std::fs::rename(&temporary, &self.target);
        if renamed.is_err() {
            let _ = std::fs::remove_file(&temporary);
        }
        renamed
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if let Some(t) = self.temporary.take() {
            let _ = std::fs::remove_file(t);
        }
    }
}

/// Writes `bytes` to `target` through a [`Pending`] file.
pub fn write(target: &Path, bytes: &[u8]) -> io::Result<()> {
    use std::io::Write;
    let pending = Pending::beside(target)?;
    pending.file().write_all(bytes)?;
    pending.commit()
}

/// `.NAME.specconv-PID-N.tmp` beside `target`: the process id and a count within the process.
fn temporary_path(target: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    directory_of(target).join(format!("{}{}-{n}.tmp", prefix(target), std::process::id()))
}

/// The start every temporary name of `target` shares.
fn prefix(target: &Path) -> String {
    let name = target.file_name().map_or_else(
        || target.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    format!(".{name}.specconv-")
}

fn directory_of(target: &Path) -> &Path {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Temporary files of `target` left by writers killed before they could remove them (SIGKILL,
/// a node lost), whatever their process.
pub fn leftovers(target: &Path) -> Vec<PathBuf> {
    let prefix = prefix(target);
    std::fs::read_dir(directory_of(target))
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&prefix) && n.ends_with(".tmp")
        })
        .map(|e| e.path())
        .collect()
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

    fn scratch(name: &str) -> PathBuf {
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
    fn two_writers_of_one_target_never_share_a_temporary() {
        let d = scratch("two");
        let target = d.join("t.exr");
        let a = Pending::beside(&target).unwrap();
        let b = Pending::beside(&target).unwrap();
        assert_ne!(a.temporary, b.temporary);
        // A name taken by someone else (another process with the same id in another
        // container) is skipped, not opened.
        let taken = temporary_path(&target);
        std::fs::write(&taken, b"theirs").unwrap();
        let name = taken.file_name().unwrap().to_string_lossy().into_owned();
        let (head, n) = name.trim_end_matches(".tmp").rsplit_once('-').unwrap();
        let next: u64 = n.parse::<u64>().unwrap() + 1;
        std::fs::write(d.join(format!("{head}-{next}.tmp")), b"theirs too").unwrap();
        let c = Pending::beside(&target).unwrap();
        c.commit().unwrap();
        assert_eq!(std::fs::read(&taken).unwrap(), b"theirs");
        assert_eq!(std::fs::read(&target).unwrap(), b"");
        drop((a, b));
        assert_eq!(leftovers(&target).len(), 2, "the others' files stay");
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

    #[test]
    fn a_target_in_the_current_directory_gets_its_temporary_there() {
        let p = temporary_path(Path::new("plain.exr"));
        assert_eq!(p.parent(), Some(Path::new(".")));
        assert!(p
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with(".plain.exr.specconv-"));
    }
}
