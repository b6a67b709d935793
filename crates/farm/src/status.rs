//! Where a job stands, from its manifest, its task logs and Slurm: per task its state and exit
//! code, per file done / failed / pending. Reading it changes nothing.

use crate::log::{Outcome, TaskLog};
use crate::manifest::{round_dir, task_log, File, Manifest};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// A file's state in the latest round that planned it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "state", rename_all = "lowercase")]
pub enum FileState {
    /// Converted (or already up to date) and its output exists.
    Done,
    /// The latest round's task logged an error for it.
    Failed {
        /// The error, as the task logged it.
        error: String,
    },
    /// Not converted yet: its task is queued or running (`waiting`), or it ended without
    /// reaching the file (killed, cancelled, out of time), or its output has gone missing.
    Pending {
        /// Why, in words for the status report.
        why: String,
        /// Whether its task is still queued or running; a retry takes only files whose task ended.
        waiting: bool,
    },
}

/// One file's state, from the latest round that planned it.
#[derive(Debug, Clone, Serialize)]
pub struct FileStatus {
    /// The file's index in [`Manifest::files`].
    pub index: usize,
    /// The input, as in the manifest.
    pub input: PathBuf,
    /// Its output, as in the manifest.
    pub output: PathBuf,
    /// The latest round that planned it.
    pub round: usize,
    /// The task of that round it was given to.
    pub task: usize,
    /// Done, failed or pending (flattened into the record's `state` field and its details).
    #[serde(flatten)]
    pub state: FileState,
    /// Pixels converted and seconds spent, from the log record (0 without one).
    pub pixels: u64,
    /// Seconds the conversion took, from the same record (0 without one).
    pub seconds: f64,
}

/// One array task of one round, from Slurm and the task's log.
#[derive(Debug, Clone, Serialize)]
pub struct TaskStatus {
    /// The round, an index into [`Manifest::rounds`].
    pub round: usize,
    /// The round's array job id.
    pub job_id: String,
    /// The array task id within the round.
    pub task: usize,
    /// Slurm's state, or `UNKNOWN` when Slurm no longer knows the job.
    pub state: String,
    /// Slurm's `code:signal`, else the exit code the task's end event logged.
    pub exit: Option<String>,
    /// How many files the task was given.
    pub files: usize,
    /// Unix time of the task's start event; `None` before it starts (or when its log is lost).
    pub start: Option<f64>,
    /// Unix time of the task's end event; `None` while it runs, or when it was killed first.
    pub end: Option<f64>,
}

/// The state of a task whose round was recorded but never reached Slurm.
pub const NOT_SUBMITTED: &str = "NOT_SUBMITTED";
/// The state of a task Slurm could not be asked about (its commands failed): it may run.
pub const UNREACHABLE: &str = "UNREACHABLE";

impl TaskStatus {
    /// Queued or running, as Slurm says, or possibly so (Slurm did not answer): a task that
    /// logged its end may still be completing, and its final state (CANCELLED, TIMEOUT…) is
    /// what a status should show.
    pub fn active(&self) -> bool {
        self.state == UNREACHABLE || crate::slurm::active(&self.state)
    }
}

/// Where a job stands ([`Status::read`]): every task and every planned file.
#[derive(Debug, Clone, Serialize)]
pub struct Status {
    /// Every task of every round, round by round.
    pub tasks: Vec<TaskStatus>,
    /// Every file some round planned, in manifest order.
    pub files: Vec<FileStatus>,
}

/// A file's state from its task's record of it (`outcome`, none when the log has none), its
/// output, and its task's state.
fn file_state(outcome: Option<&Outcome>, file: &File, task: &TaskStatus) -> FileState {
    let (r, t) = (task.round, task.task);
    match outcome {
        // A data texture written through is at its data name.
        Some(Outcome::Done) if file.outputs().any(Path::exists) => FileState::Done,
        Some(Outcome::Data) => FileState::Done,
        Some(Outcome::Done) => FileState::Pending {
            why: "its output has gone missing".into(),
            waiting: false,
        },
        Some(Outcome::Failed(e)) => FileState::Failed { error: e.clone() },
        None if task.state == NOT_SUBMITTED => FileState::Pending {
            why: format!(
                "round {r} was not submitted (interrupted before Slurm took it); \
                 `specconv farm retry` submits it"
            ),
            waiting: false,
        },
        None if task.state == UNREACHABLE => FileState::Pending {
            why: format!("task {t} may still run: Slurm did not answer"),
            waiting: true,
        },
        None if task.active() => FileState::Pending {
            why: format!("task {t} is {}", task.state.to_lowercase()),
            waiting: true,
        },
        None => FileState::Pending {
            why: format!(
                "task {t} ended ({}{}) before converting it",
                task.state,
                task.exit
                    .as_deref()
                    .map_or(String::new(), |e| format!(", exit {e}"))
            ),
            waiting: false,
        },
    }
}

impl Status {
    /// Combines the manifest, the logs under `job_dir` and Slurm's view of each submitted
    /// round's job (`slurm(job_id)`: `None` when Slurm has forgotten it, an error when it could
    /// not be asked, and then its tasks count as possibly running). Fails only on a log that is
    /// refused ([`TaskLog::read`]).
    pub fn read(
        job_dir: &Path,
        m: &Manifest,
        slurm: &mut dyn FnMut(&str) -> crate::slurm::Tasks,
    ) -> Result<Status, crate::error::Error> {
        let (tasks, logs) = Status::tasks(job_dir, m, slurm)?;
        let mut files = Vec::new();
        for (i, f) in m.files.iter().enumerate() {
            // The latest round that planned this file decides.
            let Some((r, t)) = m.rounds.iter().enumerate().rev().find_map(|(r, round)| {
                round
                    .tasks
                    .iter()
                    .position(|t| t.contains(&i))
                    .map(|t| (r, t))
            }) else {
                continue;
            };
            let Some(task) = tasks.iter().find(|s| s.round == r && s.task == t) else {
                continue;
            };
            let record = logs[r][t].records.get(&f.input);
            files.push(FileStatus {
                index: i,
                input: f.input.clone(),
                output: f.output.clone(),
                round: r,
                task: t,
                state: file_state(record.map(|r| &r.outcome), f, task),
                pixels: record.map_or(0, |r| r.pixels),
                seconds: record.map_or(0.0, |r| r.seconds),
            });
        }
        Ok(Status { tasks, files })
    }

    /// Every task of every round as the manifest, its log and Slurm say, and the logs by
    /// round and task.
    fn tasks(
        job_dir: &Path,
        m: &Manifest,
        slurm: &mut dyn FnMut(&str) -> crate::slurm::Tasks,
    ) -> Result<(Vec<TaskStatus>, Vec<Vec<TaskLog>>), crate::error::Error> {
        let mut tasks = Vec::new();
        let mut logs = Vec::new();
        for (r, round) in m.rounds.iter().enumerate() {
            let states = match &round.job_id {
                Some(id) => slurm(id).map_err(|_| UNREACHABLE),
                None => Err(NOT_SUBMITTED),
            };
            let dir = round_dir(job_dir, r);
            let mut round_logs = Vec::new();
            for (t, files) in round.tasks.iter().enumerate() {
                let log = TaskLog::read(&task_log(&dir, t))?;
                let known = match &states {
                    Ok(s) => s.as_ref().and_then(|s| s.iter().find(|s| s.task == t)),
                    Err(_) => None,
                };
                let state = match (&states, known) {
                    (Err(why), _) => why.to_string(),
                    (Ok(_), Some(s)) => s.state.clone(),
                    (Ok(_), None) => "UNKNOWN".to_string(),
                };
                tasks.push(TaskStatus {
                    round: r,
                    job_id: round.job_id.clone().unwrap_or_default(),
                    task: t,
                    state,
                    exit: known
                        .and_then(|s| s.exit.clone())
                        .or_else(|| log.exit.map(|e| e.to_string())),
                    files: files.len(),
                    start: log.start,
                    end: log.end,
                });
                round_logs.push(log);
            }
            logs.push(round_logs);
        }
        Ok((tasks, logs))
    }

    /// Whether file `index`'s task (in the latest round that planned it) is known to have
    /// ended, or never reached Slurm: nothing of this job can be writing its output.
    pub fn ended(&self, index: usize) -> bool {
        // Both lists are in order (files by index, tasks by round and task): a retry of many
        // files stays linear-logarithmic.
        let Ok(f) = self.files.binary_search_by_key(&index, |f| f.index) else {
            return false;
        };
        let f = &self.files[f];
        self.tasks
            .binary_search_by_key(&(f.round, f.task), |t| (t.round, t.task))
            .is_ok_and(|t| !self.tasks[t].active())
    }

    /// Whether any task of any round may still run.
    pub fn running(&self) -> bool {
        self.tasks.iter().any(TaskStatus::active)
    }

    /// Files a retry should convert again: failed, or pending with their task ended.
    pub fn to_retry(&self) -> Vec<usize> {
        self.files
            .iter()
            .filter(|f| match &f.state {
                FileState::Done => false,
                FileState::Failed { .. } => true,
                FileState::Pending { waiting, .. } => !waiting,
            })
            .map(|f| f.index)
            .collect()
    }

    /// Counts, failures, pending files and throughput, for `farm collect`.
    pub fn collected(&self) -> Collected {
        let count = |p: fn(&FileState) -> bool| self.files.iter().filter(|f| p(&f.state)).count();
        // Wall time of each round: first task start to last task end.
        let mut seconds = 0.0;
        for r in 0..=self.tasks.iter().map(|t| t.round).max().unwrap_or(0) {
            let of_round = || self.tasks.iter().filter(move |t| t.round == r);
            let start = of_round().filter_map(|t| t.start).reduce(f64::min);
            let end = of_round().filter_map(|t| t.end).reduce(f64::max);
            if let (Some(s), Some(e)) = (start, end) {
                seconds += (e - s).max(0.0);
            }
        }
        let pixels: u64 = self.files.iter().map(|f| f.pixels).sum();
        Collected {
            files: self.files.len(),
            done: count(|s| matches!(s, FileState::Done)),
            failed: count(|s| matches!(s, FileState::Failed { .. })),
            pending: count(|s| matches!(s, FileState::Pending { .. })),
            running: self.running(),
            seconds,
            pixels,
            pixels_per_second: if seconds > 0.0 {
                pixels as f64 / seconds
            } else {
                0.0
            },
            failures: self
                .files
                .iter()
                .filter_map(|f| match &f.state {
                    FileState::Failed { error } => Some(Failure {
                        input: f.input.clone(),
                        error: error.clone(),
                    }),
                    _ => None,
                })
                .collect(),
            pending_files: self
                .files
                .iter()
                .filter_map(|f| match &f.state {
                    FileState::Pending { why, .. } => Some(Pending {
                        input: f.input.clone(),
                        why: why.clone(),
                    }),
                    _ => None,
                })
                .collect(),
        }
    }
}

/// `farm collect`: counts, each failure with its error, time and throughput over the array.
#[derive(Debug, Clone, Serialize)]
pub struct Collected {
    /// Files some round planned: `done + failed + pending`.
    pub files: usize,
    /// Files converted whose output exists.
    pub done: usize,
    /// Files whose latest round logged an error.
    pub failed: usize,
    /// Files not converted yet: their task is waiting, or ended before reaching them.
    pub pending: usize,
    /// Whether tasks are still queued or running.
    pub running: bool,
    /// Wall time of the array, summed over rounds (first task start to last task end).
    pub seconds: f64,
    /// Pixels converted (all levels), over that time.
    pub pixels: u64,
    /// `pixels / seconds`; 0 when no wall time was logged.
    pub pixels_per_second: f64,
    /// Every failed file with its error.
    pub failures: Vec<Failure>,
    /// Every pending file with the reason.
    pub pending_files: Vec<Pending>,
}

/// A failed file, in the [`Collected`].
#[derive(Debug, Clone, Serialize)]
pub struct Failure {
    /// The input that failed.
    pub input: PathBuf,
    /// The error its task logged.
    pub error: String,
}

/// A pending file, in the [`Collected`].
#[derive(Debug, Clone, Serialize)]
pub struct Pending {
    /// The input not converted yet.
    pub input: PathBuf,
    /// Why it is pending (its task is running, ended early, or its output has gone missing).
    pub why: String,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifest::{Outputs, Round};
    use crate::slurm::TaskState;

    fn manifest(rounds: Vec<Round>) -> Manifest {
        let files = (0..3)
            .map(|k| {
                (
                    format!("/in/{k}.png").into(),
                    format!("/out/{k}_spectral.exr").into(),
                )
            })
            .collect();
        crate::manifest::example(Outputs::Directory("/out".into()), files, rounds)
    }

    #[test]
    fn a_round_never_submitted_is_pending_and_retried_and_one_slurm_did_not_report_is_not() {
        let m = manifest(vec![
            Round {
                job_id: Some("7".into()),
                tasks: vec![vec![0, 1]],
            },
            Round {
                job_id: None,
                tasks: vec![vec![2]],
            },
        ]);
        let nowhere = Path::new("/nonexistent/job");
        let mut unreachable = |_: &str| Err(crate::error::Error::Slurm("no controller".into()));
        let s = Status::read(nowhere, &m, &mut unreachable).unwrap();
        assert_eq!(s.tasks[0].state, UNREACHABLE);
        assert_eq!(s.tasks[1].state, NOT_SUBMITTED);
        assert!(s.running());
        // Files of the round Slurm did not report may be being written: not retried, not
        // cleaned; the round never submitted is.
        assert_eq!(s.to_retry(), [2]);
        assert!(!s.ended(0) && !s.ended(1) && s.ended(2));
        assert!(
            matches!(&s.files[2].state, FileState::Pending { why, waiting: false } if why.contains("not submitted"))
        );
        // Slurm says the task ended: its files are retried and cleaned.
        let mut ended = |_: &str| {
            Ok(Some(vec![TaskState {
                task: 0,
                state: "CANCELLED".into(),
                exit: Some("0:15".into()),
            }]))
        };
        let s = Status::read(nowhere, &m, &mut ended).unwrap();
        assert_eq!(s.to_retry(), [0, 1, 2]);
        assert!(s.ended(0) && !s.running());
    }
}
