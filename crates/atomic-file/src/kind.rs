//! Files as inputs: what kind a path is, and reads that stop at a size. A special file
//! (`/dev/zero`, a FIFO, a terminal, a directory) is refused by kind before anything reads it:
//! readers probing it would block, or read for ever.
//!
//! A name in a shared folder may change kind between a look and an open (someone replaces a
//! file with a FIFO), and opening a FIFO for reading blocks until a writer comes. So every
//! file opened by name is opened without blocking (`O_NONBLOCK`, which a regular file
//! ignores) and its kind decided on the open file (`fstat`), never on the name alone:
//! [`open_file`] for what a user names (links followed), [`open_own`] for our own files
//! beside a target (temporaries: links not followed either).

use std::fmt;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The kind of a path, as `stat` sees it (through symbolic links).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A regular file: the only kind specconv reads.
    File,
    /// A directory.
    Directory,
    /// A character device (`/dev/zero`, `/dev/null`, a terminal).
    CharacterDevice,
    /// A block device.
    BlockDevice,
    /// A FIFO (named pipe).
    Fifo,
    /// A socket.
    Socket,
    /// A symbolic link, where links are not followed ([`open_own`]).
    Link,
    /// Nothing is there (or a link that leads nowhere).
    Missing,
}

impl Kind {
    /// The kind of `path`.
    pub fn of(path: &Path) -> Kind {
        Kind::with_id(path).0
    }

    /// The kind of `path` and, when something is there, the file it is (device and inode,
    /// through links): one `stat` for both.
    pub fn with_id(path: &Path) -> (Kind, Option<(u64, u64)>) {
        use std::os::unix::fs::MetadataExt;
        match std::fs::metadata(path) {
            Err(_) => (Kind::Missing, None),
            Ok(m) => (Kind::of_type(m.file_type()), Some((m.dev(), m.ino()))),
        }
    }

    /// [`Kind::with_id`], and whether anything is at the name itself (a link that leads
    /// nowhere is [`Kind::Missing`] but takes the name): one `lstat`, and a `stat` more only
    /// through a link.
    pub fn at_name(path: &Path) -> (Kind, Option<(u64, u64)>, bool) {
        use std::os::unix::fs::MetadataExt;
        match std::fs::symlink_metadata(path) {
            Err(_) => (Kind::Missing, None, false),
            Ok(m) if m.file_type().is_symlink() => {
                let (kind, id) = Kind::with_id(path);
                (kind, id, true)
            }
            Ok(m) => (Kind::of_type(m.file_type()), Some((m.dev(), m.ino())), true),
        }
    }

    /// The kind of a file type (`stat`'s or `fstat`'s; links followed unless `lstat`).
    fn of_type(t: std::fs::FileType) -> Kind {
        use std::os::unix::fs::FileTypeExt;
        if t.is_file() {
            Kind::File
        } else if t.is_dir() {
            Kind::Directory
        } else if t.is_char_device() {
            Kind::CharacterDevice
        } else if t.is_block_device() {
            Kind::BlockDevice
        } else if t.is_fifo() {
            Kind::Fifo
        } else if t.is_socket() {
            Kind::Socket
        } else {
            Kind::Link
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            Kind::File => "a file",
            Kind::Directory => "a directory",
            Kind::CharacterDevice => "a character device",
            Kind::BlockDevice => "a block device",
            Kind::Fifo => "a FIFO (named pipe)",
            Kind::Socket => "a socket",
            Kind::Link => "a symbolic link",
            Kind::Missing => "missing",
        })
    }
}

/// Why a path cannot be read as a file.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The path is not a regular file.
    #[error("{}: {}", path.display(), match kind { Kind::Missing => "no such file".to_string(), k => format!("{k}, not a file") })]
    NotAFile {
        /// The path.
        path: PathBuf,
        /// What it is.
        kind: Kind,
    },
    /// The file is larger than what its use can need.
    #[error("{} is {size} bytes, more than the {limit} bytes a {what} can need; is it the right file?", path.display())]
    TooLarge {
        /// The path.
        path: PathBuf,
        /// Its size (at least).
        size: u64,
        /// The limit.
        limit: u64,
        /// What the file was read as ("model", "scene").
        what: &'static str,
    },
    /// Reading failed.
    #[error("cannot read {}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

impl ReadError {
    /// As an I/O error of the same kind (`NotFound` for a missing file, `InvalidInput` for
    /// another kind of file), the message kept.
    pub fn into_io(self) -> std::io::Error {
        let kind = match &self {
            ReadError::NotAFile {
                kind: Kind::Missing,
                ..
            } => std::io::ErrorKind::NotFound,
            ReadError::Io { source, .. } => source.kind(),
            _ => std::io::ErrorKind::InvalidInput,
        };
        std::io::Error::new(kind, self)
    }
}

/// Refuses anything but a regular file (through links), naming what it is.
pub fn readable_file(path: &Path) -> Result<(), ReadError> {
    match Kind::of(path) {
        Kind::File => Ok(()),
        kind => Err(ReadError::NotAFile {
            path: path.to_path_buf(),
            kind,
        }),
    }
}

/// Opens `path` for reading if it is a regular file (through links), without ever blocking:
/// a FIFO, a device, a socket or a directory, even one put in place of a file a moment ago,
/// is refused by kind ([`ReadError::NotAFile`]).
pub fn open_file(path: &Path) -> Result<File, ReadError> {
    open_regular(path, libc::O_NONBLOCK)
}

/// As [`open_file`] for a file of our own beside a target (a temporary, a marker), opened for
/// reading and writing when `write`: a symbolic link is not followed but refused, so a link
/// planted under such a name never leads a lock, a read or a write to another file.
pub fn open_own(path: &Path, write: bool) -> Result<File, ReadError> {
    let mut options = std::fs::File::options();
    options.read(true).write(write);
    open_with(path, options, libc::O_NONBLOCK | libc::O_NOFOLLOW)
}

/// As [`open_own`] for reading and writing, creating the file if no name is there (never
/// truncating it).
pub fn create_own(path: &Path) -> Result<File, ReadError> {
    let mut options = std::fs::File::options();
    options.read(true).write(true).create(true).truncate(false);
    open_with(path, options, libc::O_NONBLOCK | libc::O_NOFOLLOW)
}

fn open_regular(path: &Path, flags: i32) -> Result<File, ReadError> {
    let mut options = std::fs::File::options();
    options.read(true);
    open_with(path, options, flags)
}

fn open_with(
    path: &Path,
    mut options: std::fs::OpenOptions,
    flags: i32,
) -> Result<File, ReadError> {
    use std::os::unix::fs::OpenOptionsExt;
    let not_a_file = |kind| ReadError::NotAFile {
        path: path.to_path_buf(),
        kind,
    };
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = match options.custom_flags(flags).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(not_a_file(Kind::Missing))
        }
        // O_NOFOLLOW on a link: ELOOP. A link is no file of ours.
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) && flags & libc::O_NOFOLLOW != 0 => {
            return Err(not_a_file(Kind::Link))
        }
        // A directory opened for writing: EISDIR; say what it is.
        Err(e) if e.raw_os_error() == Some(libc::EISDIR) => {
            return Err(not_a_file(Kind::Directory))
        }
        // A FIFO without a reader, opened for writing without blocking: ENXIO.
        Err(e) if e.raw_os_error() == Some(libc::ENXIO) => return Err(not_a_file(Kind::of(path))),
        Err(e) => return Err(io(e)),
    };
    match Kind::of_type(file.metadata().map_err(io)?.file_type()) {
        Kind::File => Ok(file),
        kind => Err(not_a_file(kind)),
    }
}

/// Reads a regular file of at most `limit` bytes; `what` names its use in the error.
pub fn read_bounded(path: &Path, limit: u64, what: &'static str) -> Result<Vec<u8>, ReadError> {
    read_bounded_from(open_file(path)?, path, limit, what)
}

/// As [`read_bounded`] for a file of our own ([`open_own`]: a link is refused, not followed).
pub fn read_bounded_own(path: &Path, limit: u64, what: &'static str) -> Result<Vec<u8>, ReadError> {
    read_bounded_from(open_own(path, false)?, path, limit, what)
}

fn read_bounded_from(
    file: File,
    path: &Path,
    limit: u64,
    what: &'static str,
) -> Result<Vec<u8>, ReadError> {
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes = Vec::new();
    let size = file.metadata().map_or(0, |m| m.len());
    // One byte more than the limit tells a file at the limit from a larger one, even one
    // that grows while it is read.
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        let size = size.max(bytes.len() as u64);
        return Err(ReadError::TooLarge {
            path: path.to_path_buf(),
            size,
            limit,
            what,
        });
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_are_named_by_kind_and_never_read() {
        for (path, kind) in [
            ("/dev/zero", Kind::CharacterDevice),
            ("/dev/null", Kind::CharacterDevice),
            ("/", Kind::Directory),
            ("/no/such/file", Kind::Missing),
        ] {
            let e = read_bounded(Path::new(path), 10, "model").unwrap_err();
            assert!(
                matches!(e, ReadError::NotAFile { kind: k, .. } if k == kind),
                "{path}: {e}"
            );
        }
        assert_eq!(
            readable_file(Path::new("/dev/zero"))
                .unwrap_err()
                .to_string(),
            "/dev/zero: a character device, not a file"
        );
    }

    #[test]
    fn a_fifo_or_device_is_refused_without_blocking_even_through_a_link() {
        let d = crate::tests::scratch("kind-open");
        let fifo = d.join("list.txt");
        crate::tests::mkfifo(&fifo);
        let link = d.join("model.json");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        let file = d.join("file.json");
        std::fs::write(&file, b"{}").unwrap();
        let file_link = d.join("file-link.json");
        std::os::unix::fs::symlink(&file, &file_link).unwrap();
        let (f, l, fl) = (fifo.clone(), link.clone(), file_link.clone());
        let (by_name, by_link, own, own_link, bounded) = crate::tests::within_bound(move || {
            (
                open_file(&f).map(drop),
                open_file(&l).map(drop),
                open_own(&f, true).map(drop),
                open_own(&fl, false).map(drop),
                read_bounded(&l, 10, "model").map(drop),
            )
        });
        for e in [by_name, by_link, own, bounded] {
            let e = e.unwrap_err();
            assert!(
                matches!(
                    e,
                    ReadError::NotAFile {
                        kind: Kind::Fifo,
                        ..
                    }
                ),
                "{e}"
            );
            assert!(
                e.to_string().ends_with("a FIFO (named pipe), not a file"),
                "{e}"
            );
        }
        // Our own files are never reached through a link; a user's named file may be.
        let e = own_link.unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::NotAFile {
                    kind: Kind::Link,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(read_bounded(&file_link, 10, "model").unwrap(), b"{}");
        let e = open_file(&d.join("missing")).unwrap_err();
        assert!(e.to_string().ends_with("no such file"), "{e}");
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn a_file_over_the_limit_is_refused_and_one_at_it_read() {
        let d = crate::tests::scratch("bounded");
        let f = d.join("m.json");
        std::fs::write(&f, b"0123456789").unwrap();
        assert_eq!(read_bounded(&f, 10, "model").unwrap(), b"0123456789");
        let e = read_bounded(&f, 9, "model").unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{} is 10 bytes, more than the 9 bytes a model can need; is it the right file?",
                f.display()
            )
        );
        std::fs::remove_dir_all(d).unwrap();
    }
}
