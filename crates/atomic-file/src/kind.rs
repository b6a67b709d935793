//! Files as inputs: what kind a path is, and reads that stop at a size. A special file
//! (`/dev/zero`, a FIFO, a terminal, a directory) is refused by kind before anything reads it:
//! readers probing it would block, or read for ever.

use std::fmt;
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

    /// The kind of an existing file of type `t`, as `stat` gave it (links followed).
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
        } else {
            Kind::Socket
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

/// Reads a regular file of at most `limit` bytes; `what` names its use in the error.
pub fn read_bounded(path: &Path, limit: u64, what: &'static str) -> Result<Vec<u8>, ReadError> {
    readable_file(path)?;
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes = Vec::new();
    // One byte more than the limit tells a file at the limit from a larger one, even one
    // that grows while it is read.
    std::fs::File::open(path)
        .map_err(io)?
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        let size = std::fs::metadata(path).map_or(bytes.len() as u64, |m| m.len());
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
