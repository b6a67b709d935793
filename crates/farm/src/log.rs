//! A task's log: the JSON lines `specconv convert --json` prints, one per file, framed by the
//! batch script's start and end events. Lines that do not parse (a task killed mid-line) are
//! ignored: their file shows as pending.

use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// What a task's log says.
#[derive(Debug, Clone, Default)]
pub struct TaskLog {
    /// The last record of each input.
    pub records: HashMap<PathBuf, Record>,
    /// Unix time of the start event; `None` before the task starts.
    pub start: Option<f64>,
    /// Unix time of the end event; `None` while the task is queued or running, or when it was
    /// killed before logging it.
    pub end: Option<f64>,
    /// The conversion's exit code, from the end event.
    pub exit: Option<i32>,
}

/// One file's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Converted (or up to date), or failed with its error.
    pub outcome: Outcome,
    /// Pixels converted, as the record says (0 when it gives none).
    pub pixels: u64,
    /// Seconds the conversion took, as the record says (0 when it gives none).
    pub seconds: f64,
}

/// What became of one file, by the record's `status`.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Converted (clipped or not), written through as data, or skipped because its output was
    /// up to date.
    Done,
    /// A data texture skipped (`--data skip`): nothing is written, and nothing is owed.
    Data,
    /// Failed: the record's error message (its JSON text when it is not a string, "failed (no
    /// error given)" when it has none).
    Failed(String),
}

#[derive(Deserialize)]
struct Line {
    event: Option<String>,
    unix: Option<f64>,
    exit: Option<i32>,
    input: Option<PathBuf>,
    status: Option<String>,
    error: Option<serde_json::Value>,
    pixels: Option<u64>,
    seconds: Option<f64>,
}

impl TaskLog {
    /// Reads a log; a missing file is an empty log (the task has not started). One that is not
    /// a regular file, or is larger than [`crate::manifest::MAX_FILE_BYTES`], is refused.
    pub fn read(path: &Path) -> Result<TaskLog, crate::error::Error> {
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(TaskLog::default());
        }
        crate::manifest::read_bounded(path).map(|t| TaskLog::parse(&t))
    }

    /// Reads a log's text. Lines that are not JSON, events other than start and end, and records
    /// of a status this version does not know are skipped; a file's last record counts.
    pub fn parse(text: &str) -> TaskLog {
        let mut log = TaskLog::default();
        for line in text.lines() {
            let Ok(l) = serde_json::from_str::<Line>(line) else {
                continue;
            };
            match (l.event.as_deref(), l.input) {
                (Some("start"), _) => log.start = l.unix,
                (Some("end"), _) => {
                    log.end = l.unix;
                    log.exit = l.exit;
                }
                (None, Some(input)) => {
                    let outcome = match l.status.as_deref() {
                        Some("failed") => Outcome::Failed(match l.error {
                            Some(serde_json::Value::String(s)) => s,
                            Some(other) => other.to_string(),
                            None => "failed (no error given)".into(),
                        }),
                        // A data texture written through is done, not failed; one skipped is
                        // done with no output to look for.
                        Some("ok" | "clipped" | "converted" | "skipped" | "copied") => {
                            Outcome::Done
                        }
                        Some("data") => Outcome::Data,
                        // A status this version does not know: not counted as done.
                        _ => continue,
                    };
                    log.records.insert(
                        input,
                        Record {
                            outcome,
                            pixels: l.pixels.unwrap_or(0),
                            seconds: l.seconds.unwrap_or(0.0),
                        },
                    );
                }
                _ => {}
            }
        }
        log
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_events_and_a_torn_last_line() {
        let log = TaskLog::parse(concat!(
            "{\"event\":\"start\",\"task\":1,\"unix\":100.5}\n",
            "{\"input\":\"/a.png\",\"output\":\"/o/a.exr\",\"status\":\"ok\",\"seconds\":1.5,\"pixels\":64}\n",
            "{\"input\":\"/b.png\",\"status\":\"failed\",\"seconds\":0.1,\"pixels\":0,\"error\":\"cannot open\"}\n",
            "{\"input\":\"/c.png\",\"status\":\"skipped\",\"seconds\":0,\"pixels\":0}\n",
            "{\"input\":\"/n.png\",\"status\":\"data\",\"seconds\":0,\"pixels\":null}\n",
            "{\"input\":\"/k.png\",\"status\":\"clipped\",\"seconds\":1,\"pixels\":4}\n",
            "{\"event\":\"end\",\"task\":1,\"unix\":103.0,\"exit\":1}\n",
            "{\"input\":\"/d.png\",\"sta",
        ));
        assert_eq!(
            (log.start, log.end, log.exit),
            (Some(100.5), Some(103.0), Some(1))
        );
        assert_eq!(log.records.len(), 5);
        assert_eq!(log.records[Path::new("/a.png")].pixels, 64);
        assert_eq!(
            log.records[Path::new("/b.png")].outcome,
            Outcome::Failed("cannot open".into())
        );
        assert_eq!(log.records[Path::new("/c.png")].outcome, Outcome::Done);
        assert_eq!(log.records[Path::new("/n.png")].outcome, Outcome::Data);
        // A conversion with pixels above 1 is converted, not a status to ignore.
        assert_eq!(log.records[Path::new("/k.png")].outcome, Outcome::Done);
    }
}
