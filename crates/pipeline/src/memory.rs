//! What a command holds at once, estimated before its output exists ([`needed`]), and what the
//! machine can give it ([`available`]): one rule for `convert` (every layout) and `expand`,
//! checked before the temporary is created ([`check`]), so a job that cannot fit is refused
//! with the figure instead of taking the machine's memory and aborting.
//!
//! Both write a file a window of strips at a time (a strip: the blocks of one row of tiles). A
//! strip's spectra are `width × tile height × values` floats whatever the image height, so a
//! fine grid (30,001 bands) on a wide image needs gigabytes for one strip; that is the floor of
//! the work, and what the estimate counts.

use specconv_exr::SpectralFile;

/// What the refusal says: the bytes the command would hold, and what this process may use.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Shortfall {
    /// Bytes the command would hold at once ([`needed`]).
    pub needed: u64,
    /// Bytes this process may still use ([`available`]).
    pub available: u64,
    /// Where that figure comes from (`MemAvailable` or the address-space limit).
    pub bound: &'static str,
}

impl std::fmt::Display for Shortfall {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the file needs about {} MiB of memory at once (a strip of its tiles' spectra, as \
             floats, in flight), more than {MARGIN_PERCENT}% of the {} MiB available ({}); \
             make it with fewer bands (a coarser grid) or smaller tiles, or run it where more \
             memory is free",
            self.needed.div_ceil(1 << 20),
            self.available >> 20,
            self.bound
        )
    }
}

/// The share of the available memory a command may plan to hold: the rest is for what the
/// estimate does not count (the decoders, the allocator's slack, other processes).
pub const MARGIN_PERCENT: u64 = 75;

/// Bytes held besides the strips: the program, its libraries, the input decoder, the threads.
const BASE: u64 = 256 << 20;

/// How a command comes by the spectra it writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `convert`: windows of `rows` input rows, each block uplifted on its own.
    Windows {
        /// Rows of the longest window.
        rows: usize,
    },
    /// `expand`: a strip of spectra decoded whole, then each block's copied out of it, as
    /// many blocks at once as there are `threads`.
    DecodedStrips {
        /// Worker threads: the blocks in flight at once.
        threads: usize,
    },
}

/// Bytes `file` holds at once while it is made from `source`'s rows `width` pixels wide.
///
/// `convert`, in windows of spectra as floats: the chunks of the window being made and of the
/// one before (being written), at most a float a value each; with MIP levels, also each
/// block's spectra kept for the filter (both windows), copied into rows, and the smaller
/// levels' strips, gathered and emitted (two level-0 strips in all). Measured peaks are 1.6 to
/// 2.4 times below it.
///
/// `expand`, in level-0 strips S of spectra as floats (`expand_strips`). Measured peaks are
/// 1.07 to 1.36 times below it (docs/performance.md, "Memory").
pub fn needed(file: &SpectralFile, width: usize, source: Source) -> u64 {
    let row = width as u64 * file.values_per_pixel() as u64 * 4;
    let strip = row * file.block_height() as u64;
    let (per_window, window, cascade) = match source {
        Source::Windows { rows } if file.levels() > 1 => (5, row * rows as u64, 2 * strip),
        Source::Windows { rows } => (2, row * rows as u64, 0),
        Source::DecodedStrips { threads } => {
            return BASE + (expand_strips(file, threads) * strip as f64) as u64;
        }
    };
    BASE + per_window * window + cascade
}

/// What `expand` holds at once, in level-0 strips S: the decoded strip (S) and its blocks'
/// chunks, collected before they are written (S/2 as half, S as float); the blocks in flight,
/// each copied out of the strip, encoded and compressed (two blocks' spectra each, as many as
/// `threads`); with MIP levels, the smaller levels the cascade makes from the strip (S), and
/// the rows it carries from one strip to the next (3S/4 more where there are several). The
/// terms are the code's allocations; their weights are what the peaks measured on 64 to 1,024
/// pixels wide, one to eight strips, 1 and 2 threads need to stay below (docs/performance.md).
fn expand_strips(file: &SpectralFile, threads: usize) -> f64 {
    let level0: Vec<_> = file.blocks().into_iter().filter(|b| b.level == 0).collect();
    let per_strip = level0.iter().filter(|b| b.y == 0).count().max(1);
    let strips = level0.len().div_ceil(per_strip);
    let chunks = match file.spec().sample {
        specconv_exr::Sample::Half => 0.5,
        specconv_exr::Sample::Float => 1.0,
    };
    let in_flight = 2.0 * threads.clamp(1, per_strip) as f64 / per_strip as f64;
    let cascade = match (file.levels() > 1, strips > 1) {
        (false, _) => 0.0,
        (true, false) => 1.0,
        (true, true) => 1.75,
    };
    1.0 + chunks + in_flight + cascade
}

/// Refuses a job that would hold `needed` bytes when this process cannot have them with the
/// margin ([`MARGIN_PERCENT`]); where nothing is known of the machine, it runs.
pub fn check(needed: u64) -> Result<(), Shortfall> {
    match available() {
        Some((available, bound)) if needed > available / 100 * MARGIN_PERCENT => Err(Shortfall {
            needed,
            available,
            bound,
        }),
        _ => Ok(()),
    }
}

/// The bytes this process may still use, and which bound gives them: the lesser of the
/// kernel's `MemAvailable` and the address-space limit (`ulimit -v`) less the process's size.
/// `None` where neither can be read (not Linux). Not a memory cgroup's limit: a farm task's
/// is sized by the measured peak (`specconv_farm::memory_mib`), which this deliberately
/// generous estimate passes for most textures, so it would refuse tasks that run.
pub fn available() -> Option<(u64, &'static str)> {
    let mem = meminfo("MemAvailable").map(|b| (b, "MemAvailable of /proc/meminfo"));
    let address = address_space().map(|b| {
        (
            b,
            "the address-space limit (ulimit -v) less the process's size",
        )
    });
    [mem, address].into_iter().flatten().min_by_key(|&(b, _)| b)
}

/// A `/proc/meminfo` figure in bytes.
fn meminfo(key: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.split(':').next() == Some(key))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The address-space limit (`RLIMIT_AS`, `/proc/self/limits`) less the process's virtual size
/// (`VmSize`); `None` when unlimited.
fn address_space() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    // Columns: the name, the soft limit, the hard limit, the unit.
    let soft: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let size = status
        .lines()
        .find(|l| l.starts_with("VmSize:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |kib| kib * 1024);
    Some(soft.saturating_sub(size))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_available_memory_is_read_on_linux() {
        let (bytes, bound) = available().expect("Linux has /proc/meminfo");
        assert!(bytes > 0, "{bound}");
        assert!(bytes <= meminfo("MemTotal").unwrap(), "{bound}");
    }

    #[test]
    fn a_shortfall_says_both_figures_and_where_the_second_comes_from() {
        let s = Shortfall {
            needed: 13 << 30,
            available: 4 << 30,
            bound: "MemAvailable of /proc/meminfo",
        };
        let text = s.to_string();
        assert!(
            text.contains("13312 MiB") && text.contains("4096 MiB"),
            "{text}"
        );
        assert!(text.contains("MemAvailable"), "{text}");
    }
}
