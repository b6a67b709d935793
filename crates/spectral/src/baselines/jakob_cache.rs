//! Where the Jakob 2019 tables come from: solved once per setting and kept in a directory the
//! caller names (the CLI: the user's cache directory), keyed by everything the table depends on
//! ([`Fitter::key`]). Solving a 64³ table takes about a minute on all cores; reading it,
//! milliseconds. The caller also says how the columns are solved ([`Solve`]: the CLI runs them
//! on its threads; this crate starts none). The one place in this crate that touches files: the
//! table is a pure function of its key, so keeping it changes no result.

use super::jakob::{self, solve_in_turn, Fitter, Fnv, Table};
use crate::error::Error;
use specconv_colour::Colorimetry;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What happened on the way to a table that the user may want to know.
#[derive(Debug)]
pub enum Note {
    /// A cached file was damaged or built for another key; it is rebuilt.
    Stale(PathBuf),
    /// The table was solved, in this many seconds.
    Built {
        /// The table's resolution, cells per axis.
        res: usize,
        /// The grid of the colorimetry it was solved for.
        grid: specconv_colour::Grid,
        /// Wall time of the solve.
        seconds: f64,
    },
    /// The table could not be kept; it is used anyway.
    NotKept(PathBuf, std::io::Error),
}

impl Note {
    /// Whether the user should act on it (a warning) rather than just know it.
    pub fn is_warning(&self) -> bool {
        matches!(self, Note::NotKept(..))
    }
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Note::Stale(file) => write!(f, "{} is damaged or stale; rebuilding it", file.display()),
            Note::Built { res, grid, seconds } => write!(
                f,
                "built the jakob2019 table ({res}³ × 3 cells, {grid}) in {seconds:.1} s"
            ),
            Note::NotKept(file, e) => write!(
                f,
                "cannot cache the jakob2019 table in {}: {e}",
                file.display()
            ),
        }
    }
}

/// Solves the `3·res` columns of a table ([`Fitter::solve_column`], in the order of
/// [`Table::from_columns`]), one after another or in parallel.
pub type Solve = fn(&Fitter, usize) -> Vec<Vec<[f32; 3]>>;

/// The tables of one directory (or of none: solved every time).
pub struct TableCache {
    dir: Option<PathBuf>,
    solve: Solve,
    tell: fn(&Note),
}

impl TableCache {
    /// Tables kept in `dir` (created when needed), solved by `solve`; `tell` hears every
    /// [`Note`].
    pub fn in_dir(dir: Option<PathBuf>, solve: Solve, tell: fn(&Note)) -> TableCache {
        TableCache { dir, solve, tell }
    }

    /// Tables solved every time, on this thread, silently (tests, one-off studies).
    pub fn none() -> TableCache {
        TableCache::in_dir(None, solve_in_turn, |_| {})
    }

    /// The file of the table for `key`.
    pub fn file(&self, key: &str) -> Option<PathBuf> {
        let mut h = Fnv::new();
        h.write(key.as_bytes());
        let name = format!("jakob2019-{:016x}.bin", h.finish());
        self.dir.as_ref().map(|d| d.join(name))
    }

    /// The table for `a` at resolution `res`: read when an intact file for the same key is
    /// there, else solved and written. A directory that cannot be written is not
    /// an error: the table is used anyway, with a [`Note::NotKept`].
    pub fn table(&self, a: &Colorimetry, res: usize) -> Result<Table, Error> {
        jakob::check_resolution(res)?;
        let fitter = Fitter::new(a)?;
        let key = fitter.key(a, res);
        let file = self.file(&key);
        if let Some(file) = &file {
            if let Ok(bytes) = std::fs::read(file) {
                if let Some(t) = Table::from_bytes(&bytes, &key, res) {
                    return Ok(t);
                }
                (self.tell)(&Note::Stale(file.clone()));
            }
        }
        let start = Instant::now();
        let table = Table::from_columns(res, key, (self.solve)(&fitter, res));
        (self.tell)(&Note::Built {
            res,
            grid: a.grid,
            seconds: start.elapsed().as_secs_f64(),
        });
        if let Some(file) = &file {
            if let Err(e) = keep(file, &table.to_bytes()) {
                (self.tell)(&Note::NotKept(file.clone(), e));
            }
        }
        Ok(table)
    }
}

/// Writes `bytes` to a temporary file beside `file` and renames it into place, so that a
/// reader never sees half a table.
fn keep(file: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if let Some(dir) = file.parent() {
        std::fs::create_dir_all(dir)?;
    }
    specconv_atomic_file::write(file, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_colour::{Grid, Illuminant, Observer};

    #[test]
    fn a_kept_table_is_read_back_and_a_damaged_one_rebuilt() {
        let dir = std::env::temp_dir().join(format!("specconv-jakob-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let a = Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap();
        let cache = TableCache::in_dir(Some(dir.clone()), solve_in_turn, |_| {});
        let built = cache.table(&a, 4).unwrap();
        assert_eq!(
            built.coefficients,
            Table::build(&a, 4).unwrap().coefficients
        );
        let file = cache.file(&built.key).unwrap();
        let mut bytes = std::fs::read(&file).unwrap();
        assert_eq!(cache.table(&a, 4).unwrap().coefficients, built.coefficients);
        // One flipped byte fails the checksum: rebuilt and rewritten, same table.
        bytes[100] ^= 1;
        std::fs::write(&file, &bytes).unwrap();
        assert_eq!(cache.table(&a, 4).unwrap().coefficients, built.coefficients);
        assert_ne!(std::fs::read(&file).unwrap(), bytes);
        assert!(cache.table(&a, 3).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
