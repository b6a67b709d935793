//! What `asset` wrote under its output folder, so that it never replaces a file it did not
//! write (issue 57): `DIR/.specconv-asset.json` names each file an asset run planned there,
//! relative to DIR, with its size and modification time once written.
//!
//! Before anything is written the whole plan is checked ([`check`]): no output may be a file
//! the stage reads (the stage, a layer it composes, a MaterialX document or XInclude, a
//! texture), whatever `-u` or `--force` say; and an output that exists must be one this or
//! an earlier asset run wrote and nobody changed since (its record's size and time). The plan
//! is then claimed ([`claim`]) and, once written, stamped ([`stamp`]). A claimed file that a
//! killed run left unstamped is still the asset's: it was checked free before the claim.

use crate::error::Error;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

// Kept in paths, below error, whose messages name it.
pub use crate::file_names::RECORD;

/// The largest record read (a million files' entries fit well within it).
const MAX_RECORD: u64 = 256 << 20;

/// A written file's size and modification time (ns since the epoch).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
struct Stamp {
    len: u64,
    modified_ns: u128,
}

#[derive(Debug, Default, Serialize, Deserialize)]
struct Record {
    /// Path relative to DIR → its stamp (`None`: claimed, not yet written).
    files: BTreeMap<String, Option<Stamp>>,
}

fn stamp_of(path: &Path) -> Option<Stamp> {
    let m = std::fs::symlink_metadata(path).ok()?;
    let modified_ns = m
        .modified()
        .ok()?
        .duration_since(UNIX_EPOCH)
        .ok()?
        .as_nanos();
    Some(Stamp {
        len: m.len(),
        modified_ns,
    })
}

/// `path`'s key in the record: relative to `dir` (outputs always lie under it).
fn key(dir: &Path, path: &Path) -> String {
    path.strip_prefix(dir)
        .unwrap_or(path)
        .to_string_lossy()
        .into_owned()
}

fn load(dir: &Path) -> Result<Record, Error> {
    let path = dir.join(RECORD);
    let bad = |why: String| Error::Record {
        path: path.clone(),
        why,
    };
    match std::fs::symlink_metadata(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Record::default()),
        Err(e) => return Err(bad(e.to_string())),
        Ok(m) if !m.is_file() => return Err(bad("not a regular file".into())),
        Ok(m) if m.len() > MAX_RECORD => return Err(bad(format!("{} bytes", m.len()))),
        Ok(_) => {}
    }
    let bytes = std::fs::read(&path).map_err(|e| bad(e.to_string()))?;
    serde_json::from_slice(&bytes).map_err(|e| bad(e.to_string()))
}

fn save(dir: &Path, record: &Record) -> Result<(), Error> {
    let path = dir.join(RECORD);
    let text = serde_json::to_vec_pretty(record).map_err(|e| Error::Record {
        path: path.clone(),
        why: e.to_string(),
    })?;
    specconv_atomic_file::write(&path, &text).map_err(|e| Error::Io(path, e))
}

/// The file `path` names, as compared: its canonical path where it exists.
fn identity(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Refuses the plan when an output in `writes` is a file in `reads`, or exists and was not
/// written by an asset run into `dir` (or changed since). Reads nothing but metadata.
pub fn check(dir: &Path, writes: &[PathBuf], reads: &[PathBuf]) -> Result<(), Error> {
    let read: HashSet<PathBuf> = reads.iter().map(|p| identity(p)).collect();
    for w in writes {
        if read.contains(&identity(w)) {
            return Err(Error::WritesItsInput { output: w.clone() });
        }
    }
    let record = load(dir)?;
    for w in writes {
        let Some(now) = stamp_of(w) else { continue };
        match record.files.get(&key(dir, w)) {
            None => return Err(Error::NotWrittenByAsset { path: w.clone() }),
            Some(Some(then)) if *then != now => {
                return Err(Error::ChangedSinceWritten { path: w.clone() })
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// The files under `folder` (inside `dir`) that the record names and nobody changed since:
/// what a usdz's copy-outs may replace.
pub fn own_under(dir: &Path, folder: &Path) -> Result<Vec<PathBuf>, Error> {
    let record = load(dir)?;
    Ok(record
        .files
        .iter()
        .map(|(k, stamp)| (dir.join(k), stamp))
        .filter(|(p, stamp)| p.starts_with(folder) && stamp.is_none_or(|s| stamp_of(p) == Some(s)))
        .map(|(p, _)| p)
        .collect())
}

/// Records `writes` as planned by an asset run into `dir` (stamps already there are kept).
pub fn claim(dir: &Path, writes: &[PathBuf]) -> Result<(), Error> {
    let mut record = load(dir)?;
    for w in writes {
        record.files.entry(key(dir, w)).or_insert(None);
    }
    save(dir, &record)
}

/// Stamps those of `writes` that exist with their size and time, as this run wrote them.
pub fn stamp(dir: &Path, writes: &[PathBuf]) -> Result<(), Error> {
    let mut record = load(dir)?;
    for w in writes {
        if let Some(s) = stamp_of(w) {
            record.files.insert(key(dir, w), Some(s));
        }
    }
    save(dir, &record)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("asset-record-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn only_what_it_wrote_and_nobody_changed_may_be_replaced() {
        let dir = scratch("own");
        let (mine, theirs) = (dir.join("a_spectral.exr"), dir.join("b_spectral.exr"));
        let writes = [mine.clone(), theirs.clone()];
        let only_mine = std::slice::from_ref(&mine);
        // Nothing there: free, and claimed.
        check(&dir, &writes, &[]).unwrap();
        claim(&dir, only_mine).unwrap();
        std::fs::write(&mine, b"written").unwrap();
        stamp(&dir, only_mine).unwrap();
        check(&dir, only_mine, &[]).unwrap();
        // A file it did not write.
        std::fs::write(&theirs, b"a user's").unwrap();
        assert!(matches!(
            check(&dir, &writes, &[]),
            Err(Error::NotWrittenByAsset { path }) if path == theirs
        ));
        // Its own file, changed by someone since.
        std::thread::sleep(std::time::Duration::from_millis(20));
        std::fs::write(&mine, b"edited by hand").unwrap();
        assert!(matches!(
            check(&dir, only_mine, &[]),
            Err(Error::ChangedSinceWritten { .. })
        ));
        // An output that is an input, by another name.
        let input = dir.join("in.mtlx");
        std::fs::write(&input, b"<materialx/>").unwrap();
        let other = dir.join(".").join("in.mtlx");
        assert!(matches!(
            check(&dir, &[other], &[input]),
            Err(Error::WritesItsInput { .. })
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
