//! UDIM tiles: an input pattern (`wood.<UDIM>.png`, `<udim>`, `%(UDIM)d`, as OpenImageIO's
//! TextureSystem and the texture painters spell it) names the tiles that exist on disk, and
//! every tile's name carries its number (1001 + u + 10·v). One definition for the command
//! line's plan, output templates ([`crate::outputs`]) and the farm's check of a job.
//!
//! A tile's number is read back from its name as the **last** run of exactly four digits
//! (1001–9999) in the name without its extension; a pattern whose tiles would read otherwise
//! (`<UDIM>_scan_2019.png`) is refused when it is expanded, so that the plan and every later
//! check of it agree.

use std::ffi::OsString;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};

/// The spellings of the tile number in a pattern.
pub const TOKENS: [&str; 3] = ["<UDIM>", "<udim>", "%(UDIM)d"];

/// The first and last UDIM numbers (u in 0–9, v in 0–898).
pub const FIRST: u32 = 1001;
/// See [`FIRST`].
pub const LAST: u32 = 9999;

/// Why a UDIM pattern names no tiles.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UdimError {
    /// No file matches the pattern.
    #[error(
        "no UDIM tile matches {} (looked in {} for names with a tile number {FIRST}–{LAST} in place of the token)",
        pattern.display(), dir.display()
    )]
    NoTiles {
        /// The pattern.
        pattern: PathBuf,
        /// The directory searched.
        dir: PathBuf,
    },
    /// The token is in a directory name, not in the file name.
    #[error("{}: the UDIM token must be in the file name, not in a directory", pattern.display())]
    InDirectory {
        /// The pattern.
        pattern: PathBuf,
    },
    /// The token appears twice in the file name.
    #[error("{}: the UDIM token appears more than once", pattern.display())]
    Twice {
        /// The pattern.
        pattern: PathBuf,
    },
    /// The pattern's directory cannot be listed.
    #[error("cannot list {} for the UDIM tiles of {}", dir.display(), pattern.display())]
    List {
        /// The pattern.
        pattern: PathBuf,
        /// Its directory.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A tile whose number would not be read back from its name.
    #[error(
        "{}: its tile number {tile} is not the last four-digit number of its name, so outputs \
         could not be named by it; rename the tiles with the number last (NAME.{tile}.EXT)",
        path.display()
    )]
    Ambiguous {
        /// The tile.
        path: PathBuf,
        /// Its number in the pattern.
        tile: u32,
    },
}

/// A tile of a pattern.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tile {
    /// The file.
    pub path: PathBuf,
    /// Its UDIM number.
    pub number: u32,
}

/// The token of `name` and where it is: (start, length).
fn token_in(name: &[u8]) -> Option<(usize, usize)> {
    TOKENS
        .iter()
        .filter_map(|t| find(name, t.as_bytes()).map(|at| (at, t.len())))
        .min()
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Whether `path` is a UDIM pattern (a token anywhere in it).
pub fn is_pattern(path: &Path) -> bool {
    token_in(path.as_os_str().as_bytes()).is_some()
}

/// The tiles of `pattern` that exist, by number; `Ok(None)` when `pattern` has no token (a
/// plain path, used as it is). No tile is an error: a pattern stands for files that exist.
pub fn expand(pattern: &Path) -> Result<Option<Vec<Tile>>, UdimError> {
    if !is_pattern(pattern) {
        return Ok(None);
    }
    let name = pattern
        .file_name()
        .map(|n| n.as_bytes())
        .unwrap_or_default();
    let Some((at, len)) = token_in(name) else {
        return Err(UdimError::InDirectory {
            pattern: pattern.to_path_buf(),
        });
    };
    let (prefix, suffix) = (&name[..at], &name[at + len..]);
    if token_in(suffix).is_some() {
        return Err(UdimError::Twice {
            pattern: pattern.to_path_buf(),
        });
    }
    let parent = pattern.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = parent.unwrap_or(Path::new("."));
    let list = |source| UdimError::List {
        pattern: pattern.to_path_buf(),
        dir: dir.to_path_buf(),
        source,
    };
    let mut tiles = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(list)? {
        let entry = entry.map_err(list)?;
        let file = entry.file_name();
        let bytes = file.as_bytes();
        let Some(middle) = bytes
            .strip_prefix(prefix)
            .and_then(|rest| rest.strip_suffix(suffix))
        else {
            continue;
        };
        let Some(number) = number_of(middle) else {
            continue;
        };
        let path = match parent {
            Some(p) => p.join(&file),
            None => PathBuf::from(&file),
        };
        if tile_number(&path) != Some(number) {
            return Err(UdimError::Ambiguous { path, tile: number });
        }
        tiles.push(Tile { path, number });
    }
    if tiles.is_empty() {
        return Err(UdimError::NoTiles {
            pattern: pattern.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    tiles.sort_by_key(|t| t.number);
    Ok(Some(tiles))
}

/// Four ASCII digits that make a UDIM number.
fn number_of(digits: &[u8]) -> Option<u32> {
    if digits.len() != 4 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let n = std::str::from_utf8(digits).ok()?.parse().ok()?;
    (FIRST..=LAST).contains(&n).then_some(n)
}

/// Where the tile number is in a name without its extension: the last run of exactly four
/// digits that is a UDIM number.
fn tile_span(stem: &[u8]) -> Option<(usize, u32)> {
    let mut end = stem.len();
    while end > 0 {
        if !stem[end - 1].is_ascii_digit() {
            end -= 1;
            continue;
        }
        let mut start = end;
        while start > 0 && stem[start - 1].is_ascii_digit() {
            start -= 1;
        }
        if let Some(n) = number_of(&stem[start..end]) {
            return Some((start, n));
        }
        end = start;
    }
    None
}

/// The UDIM number in `input`'s name ([module rules](self)), if it has one.
pub fn tile_number(input: &Path) -> Option<u32> {
    tile_span(&stem(input)).map(|(_, n)| n)
}

/// `input`'s name without its extension and without its tile number (and the `.` or `_` before
/// it): `wood` for `wood.1001.png`; the whole stem when it has no tile number.
pub fn stem_without_tile(input: &Path) -> Vec<u8> {
    let stem = stem(input);
    match tile_span(&stem) {
        Some((start, _)) => {
            let cut = if start > 0 && matches!(stem[start - 1], b'.' | b'_') {
                start - 1
            } else {
                start
            };
            [&stem[..cut], &stem[start + 4..]].concat()
        }
        None => stem,
    }
}

/// The Mudbox form of a UDIM number, as OpenImageIO's `<UVTILE>` spells it: `u1_v1` for 1001
/// (u and v counted from 1).
pub fn uv_tile(number: u32) -> String {
    let i = number - FIRST;
    format!("u{}_v{}", i % 10 + 1, i / 10 + 1)
}

/// `pattern` with its token replaced by `number` (an output named like its tiles).
pub fn substitute(pattern: &Path, number: u32) -> PathBuf {
    let bytes = pattern.as_os_str().as_bytes();
    match token_in(bytes) {
        Some((at, len)) => {
            let out = [
                &bytes[..at],
                number.to_string().as_bytes(),
                &bytes[at + len..],
            ]
            .concat();
            PathBuf::from(OsString::from_vec(out))
        }
        None => pattern.to_path_buf(),
    }
}

/// The input's name without its extension; `output` for a path without a name.
pub(crate) fn stem(input: &Path) -> Vec<u8> {
    input
        .file_stem()
        .map_or_else(|| b"output".to_vec(), |s| s.as_bytes().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_numbers_are_read_from_names() {
        assert_eq!(tile_number(Path::new("t/wood.1001.png")), Some(1001));
        assert_eq!(tile_number(Path::new("wood_1012.exr")), Some(1012));
        assert_eq!(tile_number(Path::new("scan_2019.1003.tif")), Some(1003));
        assert_eq!(tile_number(Path::new("wood.1000.png")), None);
        assert_eq!(tile_number(Path::new("wood.10010.png")), None);
        assert_eq!(tile_number(Path::new("wood.png")), None);
        assert_eq!(stem_without_tile(Path::new("wood.1001.png")), b"wood");
        assert_eq!(
            stem_without_tile(Path::new("wood_1001_col.png")),
            b"wood_col"
        );
        assert_eq!(stem_without_tile(Path::new("wood.png")), b"wood");
        assert_eq!(uv_tile(1001), "u1_v1");
        assert_eq!(uv_tile(1010), "u10_v1");
        assert_eq!(uv_tile(1023), "u3_v3");
        assert_eq!(
            substitute(Path::new("o/w_spectral.<UDIM>.exr"), 1002),
            Path::new("o/w_spectral.1002.exr")
        );
        assert_eq!(
            substitute(Path::new("w.%(UDIM)d.exr"), 1002),
            Path::new("w.1002.exr")
        );
    }

    #[test]
    fn a_pattern_expands_to_the_tiles_that_exist_in_order() {
        let dir = std::env::temp_dir().join(format!("udim-expand-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for n in [
            "wood.1011.png",
            "wood.1001.png",
            "wood.1002.png",
            "wood.999.png",
        ] {
            std::fs::write(dir.join(n), b"").unwrap();
        }
        std::fs::write(dir.join("wood.1003.exr"), b"").unwrap();
        std::fs::write(dir.join("wood.abcd.png"), b"").unwrap();
        for token in TOKENS {
            let tiles = expand(&dir.join(format!("wood.{token}.png")))
                .unwrap()
                .unwrap();
            let numbers: Vec<u32> = tiles.iter().map(|t| t.number).collect();
            assert_eq!(numbers, [1001, 1002, 1011], "{token}");
            assert_eq!(tiles[0].path, dir.join("wood.1001.png"));
        }
        assert!(expand(&dir.join("wood.png")).unwrap().is_none());
        let none = expand(&dir.join("oak.<UDIM>.png")).unwrap_err().to_string();
        assert!(none.contains("no UDIM tile matches"), "{none}");
        let e = expand(&dir.join("<UDIM>/wood.png"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("in the file name"), "{e}");
        std::fs::write(dir.join("1001_scan_2019.png"), b"").unwrap();
        let e = expand(&dir.join("<UDIM>_scan_2019.png"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not the last four-digit number"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
