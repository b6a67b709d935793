//! What a batch says on standard error while it runs and when it ends. On a terminal, one live
//! line: file i of n, the file's share done, its rate and the batch's ETA. Into a file (a log
//! a farm or a wrapper keeps), a plain line every few seconds instead, so the log grows slowly
//! and reads top to bottom. At the end, a summary: converted, skipped, failed, with each
//! failure again.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// `--progress`: when to show progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum When {
    /// A live line on a terminal; a plain line every few seconds when standard error is a
    /// file; nothing into a pipe, whose reader parses what it gets.
    Auto,
    /// As auto, and plain lines into a pipe too.
    Always,
    /// None.
    Never,
}

specconv_flags::value_by_type!(When);

/// Seconds between plain progress lines, unless $SPECCONV_PROGRESS_SECONDS says otherwise.
const PLAIN_EVERY: f64 = 5.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Live,
    Plain,
    Off,
}

/// Progress over a batch. Each input weighs its size on disk, so the ETA of a batch of
/// unequal textures follows the bytes still to read, not the file count.
pub struct Progress {
    mode: Mode,
    every: Duration,
    weights: Vec<u64>,
    total: u64,
    done: u64,
    start: Instant,
    last: Option<Instant>,
    file: usize,
    name: String,
    file_start: Instant,
}

impl Progress {
    pub fn new(when: When, quiet: bool, inputs: &[PathBuf]) -> Progress {
        let stderr = std::io::stderr();
        let mode = if quiet || when == When::Never {
            Mode::Off
        } else if stderr.is_terminal() {
            Mode::Live
        } else if when == When::Always || stderr_is_a_file() {
            Mode::Plain
        } else {
            Mode::Off
        };
        let every = std::env::var("SPECCONV_PROGRESS_SECONDS")
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(PLAIN_EVERY);
        // Only stat the inputs when something will be shown.
        let weights: Vec<u64> = if mode == Mode::Off {
            vec![1; inputs.len()]
        } else {
            inputs.iter().map(|p| weight(p)).collect()
        };
        Progress {
            mode,
            every: Duration::from_secs_f64(every),
            total: weights.iter().sum(),
            weights,
            done: 0,
            start: Instant::now(),
            last: None,
            file: 0,
            name: String::new(),
            file_start: Instant::now(),
        }
    }

    /// Input `i` (from 0) starts.
    pub fn start(&mut self, i: usize, input: &Path) {
        self.file = i;
        self.name = input.display().to_string();
        self.file_start = Instant::now();
        if self.mode == Mode::Plain {
            self.plain(0.0);
        }
    }

    /// The current input has `done` of `total` pixels uplifted.
    pub fn update(&mut self, done: u64, total: u64) {
        let fraction = if total == 0 {
            1.0
        } else {
            done as f64 / total as f64
        };
        match self.mode {
            Mode::Off => {}
            Mode::Plain => self.plain(fraction),
            Mode::Live => {
                let now = Instant::now();
                if self
                    .last
                    .is_some_and(|l| now - l < Duration::from_millis(100))
                    && done < total
                {
                    return;
                }
                self.last = Some(now);
                let rate = done as f64 / self.file_start.elapsed().as_secs_f64().max(1e-9);
                let mut err = std::io::stderr().lock();
                let _ = write!(
                    err,
                    "\r\x1b[2Kfile {} of {}: {}: {:3.0} %  {:.1} Mpixel/s{}",
                    self.file + 1,
                    self.weights.len(),
                    self.name,
                    100.0 * fraction,
                    rate / 1e6,
                    self.eta(fraction)
                        .map_or(String::new(), |e| format!("  ETA {}", duration(e)))
                );
                let _ = err.flush();
            }
        }
    }

    /// The current input is done (converted or failed).
    pub fn finish(&mut self) {
        self.done += self.weights[self.file];
        if self.mode == Mode::Live {
            err!("\r\x1b[2K");
        }
    }

    /// The current input was skipped: it leaves the batch's work.
    pub fn skip(&mut self) {
        self.total -= self.weights[self.file];
    }

    /// Seconds left in the batch, from the time spent on the share done.
    fn eta(&self, fraction: f64) -> Option<f64> {
        self.eta_after(fraction, self.start.elapsed().as_secs_f64())
    }

    /// Seconds left when `elapsed` seconds went into the inputs done and `fraction` of the
    /// current one.
    fn eta_after(&self, fraction: f64, elapsed: f64) -> Option<f64> {
        let share = (self.done as f64 + fraction * self.weights[self.file] as f64)
            / (self.total.max(1)) as f64;
        (share > 0.0 && elapsed > 0.0).then(|| elapsed * (1.0 - share).max(0.0) / share)
    }

    fn plain(&mut self, fraction: f64) {
        let now = Instant::now();
        if self.last.is_some_and(|l| now - l < self.every) {
            return;
        }
        self.last = Some(now);
        errln!(
            "specconv: progress: file {} of {} ({}), {:.0} % of it{}",
            self.file + 1,
            self.weights.len(),
            self.name,
            100.0 * fraction,
            self.eta(fraction)
                .map_or(String::new(), |e| format!(", batch ETA {}", duration(e)))
        );
    }
}

/// An input's weight in the batch: its size in bytes (1 when it cannot be read; the
/// conversion will say why).
fn weight(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(1, |m| m.len().max(1))
}

/// Standard error is a regular file (`2>log`), not a terminal or a pipe.
fn stderr_is_a_file() -> bool {
    use std::os::fd::AsFd;
    std::io::stderr()
        .as_fd()
        .try_clone_to_owned()
        .map(std::fs::File::from)
        .and_then(|f| f.metadata())
        .is_ok_and(|m| m.is_file())
}

/// `45 s`, `3 min 20 s`, `2 h 05 min`.
pub(crate) fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..=59 => format!("{s} s"),
        60..=3599 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// How a batch went: what its closing line says.
#[derive(Default)]
pub struct Closing {
    pub converted: usize,
    pub skipped: usize,
    /// What became of each data texture.
    pub data: Vec<DataTextureLine>,
    /// Each failed input with its error.
    pub failed: Vec<(PathBuf, String)>,
    /// Inputs converted with pixels clipped.
    pub clipped: usize,
    /// Of each kind of warning, the inputs that had it.
    pub warnings: Vec<usize>,
    /// What was done to an input: `converted` unless set (`expanded`).
    pub done: Option<&'static str>,
}

impl Closing {
    /// `specconv: 10 converted, 1 skipped, 2 failed in 3 min 05 s`, then each failure again.
    pub fn text(&self, seconds: f64) -> String {
        use specconv_conversion::DataOutcome;
        let count = |o: DataOutcome| self.data.iter().filter(|d| d.outcome == Some(o)).count();
        let mut data = String::new();
        for (n, what) in [
            (count(DataOutcome::Skipped), "skipped"),
            (count(DataOutcome::Copied), "written through"),
        ] {
            if n > 0 {
                let s = if n == 1 { "" } else { "s" };
                data += &format!(", {n} data texture{s} {what}");
            }
        }
        let clipped = match self.clipped {
            0 => String::new(),
            n => format!(" ({n} clipped)"),
        };
        let mut text = format!(
            "specconv: {} {}{clipped}, {} skipped{data}, {} failed{} in {}",
            self.converted,
            self.done.unwrap_or("converted"),
            self.skipped,
            self.failed.len(),
            match (self.warnings.len(), self.warnings.iter().sum::<usize>()) {
                (0, _) => String::new(),
                (1, n) => format!(", 1 kind of warning ({n} inputs)"),
                (k, n) => format!(", {k} kinds of warning ({n} in all)"),
            },
            duration(seconds)
        );
        for (input, error) in &self.failed {
            text += &format!("\n  failed: {}: {error}", input.display());
        }
        for d in self
            .data
            .iter()
            .filter(|d| d.outcome == Some(DataOutcome::Skipped))
        {
            text += &format!("\n  skipped as data: {}: {}", d.input.display(), d.why);
        }
        text
    }
}

/// A data texture of the batch: what became of it, and, skipped, why and how to have it.
pub struct DataTextureLine {
    /// The input.
    pub input: PathBuf,
    /// What was done with it.
    pub outcome: Option<specconv_conversion::DataOutcome>,
    /// Its colour space and the rule that made it data, then the remedy.
    pub why: String,
}

impl DataTextureLine {
    /// The summary of `input`'s data texture `report`.
    pub fn of(input: &Path, report: &specconv_conversion::Report) -> DataTextureLine {
        DataTextureLine {
            input: input.to_path_buf(),
            outcome: report.data,
            why: format!(
                "colour space {}, {} ({})",
                report.colorspace,
                crate::records::colorspace_reason(&report.colorspace_rule),
                crate::records::data_remedy(&report.colorspace_rule)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_people_say_them() {
        assert_eq!(duration(0.4), "0 s");
        assert_eq!(duration(59.4), "59 s");
        assert_eq!(duration(200.0), "3 min 20 s");
        assert_eq!(duration(7500.0), "2 h 05 min");
    }

    #[test]
    fn the_summary_lists_the_failures_again() {
        let s = Closing {
            converted: 10,
            skipped: 1,
            data: Vec::new(),
            failed: vec![
                ("a.png".into(), "no such file".into()),
                ("b.exr".into(), "truncated".into()),
            ],
            clipped: 0,
            warnings: Vec::new(),
            done: None,
        };
        assert_eq!(
            s.text(185.0),
            "specconv: 10 converted, 1 skipped, 2 failed in 3 min 05 s\n  \
             failed: a.png: no such file\n  failed: b.exr: truncated"
        );
    }

    #[test]
    fn the_eta_follows_the_bytes_left() {
        let mut p = Progress::new(When::Never, false, &[]);
        p.weights = vec![100, 300];
        p.total = 400;
        // A quarter of the bytes in 10 s: 30 s left.
        assert_eq!(p.eta_after(1.0, 10.0), Some(30.0));
        assert_eq!(p.eta_after(0.0, 10.0), None);
        // Half of the bytes in 10 s: 10 s left.
        p.done = 100;
        p.file = 1;
        assert_eq!(p.eta_after(1.0 / 3.0, 10.0), Some(10.0));
        // A skipped input leaves the batch: the first file was all of it.
        p.done = 0;
        p.file = 0;
        p.total = 100;
        assert_eq!(p.eta_after(1.0, 10.0), Some(0.0));
    }
}
