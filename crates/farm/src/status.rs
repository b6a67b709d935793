//! Where a job stands, from its manifest, its task logs and Slurm: per task its state and exit
//! code, per file done / failed / pending. Reading it changes nothing.

use crate::log::{Outcome, TaskLog};
use crate::manifest::{round_dir, task_log, Manifest};
use crate::slurm::TaskState;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// A file's state in the latest round that planned it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "state", rename_all = "lowercase")]
pub enum FileState {
    Done,
    Failed {
        error: String,
    },
    /// Not converted yet: its task is queued or running (`waiting`), or it ended without
    /// reaching the file (killed, cancelled, out of time), or its output has gone missing.
    Pending {
        why: String,
        waiting: bool,
    },
}

#[derive(Debug, Clone, Serialize)]
pub struct FileStatus {
    pub index: usize,
    pub input: PathBuf,
    pub output: PathBuf,
    pub round: usize,
    pub task: usize,
    #[serde(flatten)]
    pub state: FileState,
    /// Pixels converted and seconds spent, from the log record (0 without one).
    pub pixels: u64,
    pub seconds: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct TaskStatus {
    pub round: usize,
    pub job_id: String,
    pub task: usize,
    /// Slurm's state, or `UNKNOWN` when Slurm no longer knows the job.
    pub state: String,
    /// Slurm's `code:signal`, else the exit code the task's end event logged.
    pub exit: Option<String>,
    pub files: usize,
    pub start: Option<f64>,
    pub end: Option<f64>,
}

impl TaskStatus {
    /// Queued or running, as Slurm says: a task that logged its end may still be completing,
    /// and its final state (CANCELLED, TIMEOUT…) is what a status should show.
    pub fn active(&self) -> bool {
        crate::slurm::active(&self.state)
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct Status {
    pub tasks: Vec<TaskStatus>,
    pub files: Vec<FileStatus>,
}

impl Status {
    /// Combines the manifest, the logs under `job_dir` and Slurm's view of each round's job
    /// (`slurm(job_id)`, `None` when Slurm has forgotten it).
    pub fn read(
        job_dir: &Path,
        m: &Manifest,
        slurm: &mut dyn FnMut(&str) -> Option<Vec<TaskState>>,
    ) -> Status {
        let mut tasks = Vec::new();
        let mut logs = Vec::new();
        for (r, round) in m.rounds.iter().enumerate() {
            let states = slurm(&round.job_id);
            let dir = round_dir(job_dir, r);
            let mut round_logs = Vec::new();
            for (t, files) in round.tasks.iter().enumerate() {
                let log = TaskLog::read(&task_log(&dir, t));
                let known = states.as_ref().and_then(|s| s.iter().find(|s| s.task == t));
                tasks.push(TaskStatus {
                    round: r,
                    job_id: round.job_id.clone(),
                    task: t,
                    state: known.map_or_else(|| "UNKNOWN".to_string(), |s| s.state.clone()),
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
            let task = tasks
                .iter()
                .find(|s| s.round == r && s.task == t)
                .expect("every planned task has a status");
            let record = logs[r][t].records.get(&f.input);
            let state = match record.map(|r| &r.outcome) {
                Some(Outcome::Done) if f.output.exists() => FileState::Done,
                Some(Outcome::Done) => FileState::Pending {
                    why: "its output has gone missing".into(),
                    waiting: false,
                },
                Some(Outcome::Failed(e)) => FileState::Failed { error: e.clone() },
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
            };
            files.push(FileStatus {
                index: i,
                input: f.input.clone(),
                output: f.output.clone(),
                round: r,
                task: t,
                state,
                pixels: record.map_or(0, |r| r.pixels),
                seconds: record.map_or(0.0, |r| r.seconds),
            });
        }
        Status { tasks, files }
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

    pub fn summary(&self) -> Summary {
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
        Summary {
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
pub struct Summary {
    pub files: usize,
    pub done: usize,
    pub failed: usize,
    pub pending: usize,
    /// Whether tasks are still queued or running.
    pub running: bool,
    /// Wall time of the array, summed over rounds (first task start to last task end).
    pub seconds: f64,
    /// Pixels converted (all levels), over that time.
    pub pixels: u64,
    pub pixels_per_second: f64,
    pub failures: Vec<Failure>,
    pub pending_files: Vec<Pending>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Failure {
    pub input: PathBuf,
    pub error: String,
}

#[derive(Debug, Clone, Serialize)]
pub struct Pending {
    pub input: PathBuf,
    pub why: String,
}
