//! The Slurm commands the farm uses: `sbatch` to submit, `scontrol show job` for the state and
//! exit code of every array task (with `sacct` as fallback where accounting keeps jobs that the
//! controller has forgotten). Nothing else runs: no daemon, no scheduler of our own.

use crate::error::Error;
use std::path::Path;
use std::process::Command;

/// One array task as Slurm sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TaskState {
    /// The array task id (`$SLURM_ARRAY_TASK_ID`).
    pub task: usize,
    /// PENDING, RUNNING, COMPLETED, FAILED, CANCELLED, TIMEOUT, OUT_OF_MEMORY, NODE_FAIL…
    pub state: String,
    /// `code:signal`, as Slurm prints it.
    pub exit: Option<String>,
}

impl TaskState {
    /// Whether the task may still run (or is running).
    pub fn active(&self) -> bool {
        active(&self.state)
    }
}

/// States in which a task has not finished.
pub fn active(state: &str) -> bool {
    matches!(
        state,
        "PENDING"
            | "RUNNING"
            | "CONFIGURING"
            | "COMPLETING"
            | "SUSPENDED"
            | "REQUEUED"
            | "REQUEUE_HOLD"
            | "REQUEUE_FED"
            | "RESIZING"
            | "SIGNALING"
            | "STAGE_OUT"
    )
}

fn run(program: &str, args: &[&str]) -> Result<String, Error> {
    let out = Command::new(program).args(args).output().map_err(|e| {
        Error::Slurm(format!(
            "cannot run {program} ({e}); the farm needs Slurm's commands on PATH (apt-get install slurm-client)"
        ))
    })?;
    if !out.status.success() {
        return Err(Error::Slurm(format!(
            "{program} {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Submits a batch script with the given sbatch options (`--parsable` among them); returns the
/// job id.
pub fn submit(options: &[String], script: &Path) -> Result<String, Error> {
    let mut args: Vec<&str> = options.iter().map(String::as_str).collect();
    let script = script.display().to_string();
    args.push(&script);
    let out = run("sbatch", &args)?;
    // `--parsable` prints `id` or `id;cluster`.
    let id = out.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::Slurm(format!(
            "sbatch printed {out:?}, not a job id"
        )));
    }
    Ok(id)
}

/// What Slurm says of an array job's tasks ([`tasks`]): their states, `None` when it no longer
/// knows the job, an error when it could not be asked.
pub type Tasks = Result<Option<Vec<TaskState>>, Error>;

/// The state of every task of an array job, or `None` when Slurm no longer knows the job
/// (the controller has purged it and there is no accounting).
pub fn tasks(job_id: &str) -> Tasks {
    match run("scontrol", &["-o", "show", "job", job_id]) {
        Ok(text) => return Ok(Some(parse_scontrol(&text))),
        Err(Error::Slurm(e)) if e.contains("Invalid job id") => {}
        Err(e) => return Err(e),
    }
    match run(
        "sacct",
        &["-j", job_id, "-n", "-P", "-X", "-o", "JobID,State,ExitCode"],
    ) {
        Ok(text) => {
            let tasks = parse_sacct(&text);
            Ok((!tasks.is_empty()).then_some(tasks))
        }
        // No accounting storage: the job is gone.
        Err(_) => Ok(None),
    }
}

/// Task ids of `ArrayTaskId=`: `3`, `2-5`, `0,4-7%2` (the `%K` limit is not an id).
fn task_ids(s: &str) -> Vec<usize> {
    let s = s.split('%').next().unwrap_or("");
    let mut ids = Vec::new();
    for part in s.split(',') {
        let range = part.split(':').next().unwrap_or("");
        match range.split_once('-') {
            Some((a, b)) => {
                if let (Ok(a), Ok(b)) = (a.parse::<usize>(), b.parse::<usize>()) {
                    ids.extend(a..=b);
                }
            }
            None => ids.extend(range.parse::<usize>().ok()),
        }
    }
    ids
}

/// `scontrol -o show job`: one line per task record; pending tasks share one record.
pub fn parse_scontrol(text: &str) -> Vec<TaskState> {
    let mut out = Vec::new();
    for line in text.lines() {
        let field = |name: &str| {
            line.split_whitespace()
                .find_map(|w| w.strip_prefix(name).and_then(|v| v.strip_prefix('=')))
        };
        let (Some(ids), Some(state)) = (field("ArrayTaskId"), field("JobState")) else {
            continue;
        };
        for task in task_ids(ids) {
            out.push(TaskState {
                task,
                state: state.to_string(),
                exit: field("ExitCode").map(str::to_string),
            });
        }
    }
    out.sort_by_key(|t| t.task);
    out
}

/// `sacct -n -P -X -o JobID,State,ExitCode`: `12_3|COMPLETED|0:0`, `12_[4-7]|PENDING|0:0`.
pub fn parse_sacct(text: &str) -> Vec<TaskState> {
    let mut out = Vec::new();
    for line in text.lines() {
        let mut f = line.split('|');
        let (Some(id), Some(state), exit) = (f.next(), f.next(), f.next()) else {
            continue;
        };
        let Some((_, ids)) = id.split_once('_') else {
            continue;
        };
        // `CANCELLED by 0` → CANCELLED.
        let state = state.split_whitespace().next().unwrap_or("").to_string();
        for task in task_ids(ids.trim_matches(|c| c == '[' || c == ']')) {
            out.push(TaskState {
                task,
                state: state.clone(),
                exit: exit.map(str::to_string),
            });
        }
    }
    out.sort_by_key(|t| t.task);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scontrol_records_give_each_task_its_state_and_exit_code() {
        // Abridged from slurm-wlm 22.05's `scontrol -o show job 7` on the project's cluster.
        let text = "JobId=9 ArrayJobId=7 ArrayTaskId=2-3%2 ArrayTaskThrottle=2 JobName=specconv JobState=PENDING Reason=JobArrayTaskLimit ExitCode=0:0\n\
                    JobId=8 ArrayJobId=7 ArrayTaskId=1 JobName=specconv JobState=RUNNING Reason=None ExitCode=0:0\n\
                    JobId=7 ArrayJobId=7 ArrayTaskId=0 JobName=specconv JobState=FAILED Reason=NonZeroExitCode ExitCode=1:0\n";
        let t = parse_scontrol(text);
        assert_eq!(t.iter().map(|t| t.task).collect::<Vec<_>>(), [0, 1, 2, 3]);
        assert_eq!(
            (t[0].state.as_str(), t[0].exit.as_deref()),
            ("FAILED", Some("1:0"))
        );
        assert!(t[1].active() && t[3].active() && !t[0].active());
    }

    #[test]
    fn sacct_lines_expand_pending_ranges() {
        let t = parse_sacct("12_0|COMPLETED|0:0\n12_1|CANCELLED by 0|0:15\n12_[2-3]|PENDING|0:0\n");
        assert_eq!(t.len(), 4);
        assert_eq!(t[1].state, "CANCELLED");
        assert_eq!(t[3].state, "PENDING");
        assert_eq!(task_ids("0,4-6%2"), [0, 4, 5, 6]);
    }
}
