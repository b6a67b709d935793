//! Where the Jakob 2019 coefficient tables are kept between runs, and how they are built: every
//! front-end finds the same tables.

use specconv_spectral::baselines::jakob::Fitter;
use specconv_spectral::baselines::jakob_cache::{Note, TableCache};
use std::io::Write;
use std::path::PathBuf;

/// Where cached tables live: $SPECCONV_CACHE_DIR, else $XDG_CACHE_HOME/specconv, else
/// ~/.cache/specconv.
pub fn cache_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("SPECCONV_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("specconv")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("specconv")))
}

/// The tables of `dir` (`None`: [`cache_dir`]), built on every core when missing; `tell`
/// hears what happens to them.
pub fn in_dir(dir: Option<PathBuf>, tell: fn(&Note)) -> TableCache {
    TableCache::in_dir(dir.or_else(cache_dir), solve_in_parallel, tell)
}

/// Says on standard error what happens to a table (building one takes seconds).
pub fn print_note(note: &Note) {
    let kind = match note {
        Note::Built { .. } => "",
        _ if note.is_warning() => "warning: ",
        _ => "note: ",
    };
    // Not eprintln!, which panics when standard error is full: a note can go unsaid.
    let _ = writeln!(std::io::stderr().lock(), "specconv: {kind}{note}");
}

/// The columns of a Jakob 2019 table on every core.
fn solve_in_parallel(fitter: &Fitter, res: usize) -> Vec<Vec<[f32; 3]>> {
    use rayon::prelude::*;
    (0..3 * res)
        .into_par_iter()
        .map(|c| fitter.solve_column(res, c / res, c % res))
        .collect()
}
