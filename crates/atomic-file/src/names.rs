//! Temporary names: `.NAME.specconv-RANDOM.tmp` beside the target, where RANDOM is 16 hex
//! digits that differ per process, node and call. A NAME too long for that to fit in the 255
//! bytes a file name may have is cut and followed by a hash of the whole name, so every target
//! still has its own names.

use std::ffi::OsString;
use std::hash::{BuildHasher, Hasher};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The longest file name Linux file systems take (NAME_MAX).
const NAME_MAX: usize = 255;
const MARK: &[u8] = b".specconv-";
const RANDOM_DIGITS: usize = 16;
const END: &[u8] = b".tmp";

/// A new temporary name for `target`.
pub(crate) fn temporary(target: &Path) -> PathBuf {
    let mut name = prefix(target);
    name.extend_from_slice(format!("{:016x}", random()).as_bytes());
    name.extend_from_slice(END);
    directory_of(target).join(OsString::from_vec(name))
}

/// Every file in the target's directory named as one of its temporaries.
pub(crate) fn temporaries_of(target: &Path) -> Vec<PathBuf> {
    let prefix = prefix(target);
    std::fs::read_dir(directory_of(target))
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n = e.file_name();
            let n = n.as_bytes();
            n.len() > prefix.len() + END.len()
                && n.starts_with(&prefix)
                && n.ends_with(END)
                && is_middle(&n[prefix.len()..n.len() - END.len()])
        })
        .map(|e| e.path())
        .collect()
}

/// Whether `middle` (between `.NAME.specconv-` and `.tmp`) is one of ours: this version's
/// random digits or an older one's PID-COUNT, or either followed by `.DIGITS.temp`, the
/// temporary OpenImageIO's `make_texture` makes of a path it is given (`.tmp` replaced by
/// `.%%%%%%%%.temp.tmp`). A longer name that merely starts like the target's is another
/// target's.
fn is_middle(middle: &[u8]) -> bool {
    let ours = |m: &[u8]| !m.is_empty() && m.iter().all(|c| c.is_ascii_hexdigit() || *c == b'-');
    match middle.strip_suffix(OIIO_TEMP) {
        Some(rest) => rest
            .iter()
            .rposition(|&c| c == b'.')
            .is_some_and(|dot| ours(&rest[..dot]) && ours(&rest[dot + 1..])),
        None => ours(middle),
    }
}

/// What OpenImageIO's `make_texture` puts before the extension of its own temporary.
const OIIO_TEMP: &[u8] = b".temp";

/// `.NAME.specconv-`, with NAME cut and hashed when the whole would not fit.
fn prefix(target: &Path) -> Vec<u8> {
    let name = target
        .file_name()
        .map_or_else(|| target.as_os_str().as_bytes(), |n| n.as_bytes());
    let room = NAME_MAX - 1 - MARK.len() - RANDOM_DIGITS - END.len();
    let mut p = vec![b'.'];
    if name.len() <= room {
        p.extend_from_slice(name);
    } else {
        let hash = format!("~{:016x}", fnv1a(name));
        p.extend_from_slice(&name[..room - hash.len()]);
        p.extend_from_slice(hash.as_bytes());
    }
    p.extend_from_slice(MARK);
    p
}

pub(crate) fn directory_of(target: &Path) -> &Path {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// 64 random bits: std's per-process random hash keys, mixed with the time and a count so
/// that two calls in one process differ too.
fn random() -> u64 {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let mut h = std::hash::RandomState::new().build_hasher();
    h.write_u64(COUNT.fetch_add(1, Ordering::Relaxed));
    h.write_u32(std::process::id());
    if let Ok(t) = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH) {
        h.write_u128(t.as_nanos());
    }
    h.finish()
}

/// FNV-1a, 64 bits: the same for a name in every process, unlike std's keyed hash.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_new_each_time_and_fit_any_name_the_file_system_takes() {
        let a = temporary(Path::new("plain.exr"));
        assert_eq!(a.parent(), Some(Path::new(".")));
        assert!(a.to_string_lossy().starts_with("./.plain.exr.specconv-"));
        assert_ne!(a, temporary(Path::new("plain.exr")));
        for len in [200, 224, 225, 255] {
            let target = PathBuf::from("d").join("x".repeat(len));
            let t = temporary(&target);
            assert!(t.file_name().unwrap().len() <= NAME_MAX, "{len}");
            assert!(t
                .file_name()
                .unwrap()
                .as_bytes()
                .starts_with(&prefix(&target)));
        }
        // Two long names sharing their start still have their own temporaries.
        let one = prefix(Path::new(&format!("{}1", "x".repeat(254))));
        let two = prefix(Path::new(&format!("{}2", "x".repeat(254))));
        assert_ne!(one, two);
        assert!(!one.starts_with(&two) && !two.starts_with(&one));
    }
}
