//! The job directory: `manifest.json` (inputs, outputs, settings, the plan of every round) and
//! one folder per round (`round-0` for the submission, then one per retry) holding the sbatch
//! script, each task's input list, its log of JSON lines and its standard error.

use crate::Error;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the manifest's layout.
pub const FORMAT: u32 = 1;

/// `manifest.json`, the job directory's record of a job: what to convert, how, and every round
/// submitted. The fields are its JSON, written by serde (docs/farm.md describes the directory).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Manifest {
    /// The layout version the file was written in; [`Manifest::load`] refuses any but [`FORMAT`].
    pub format: u32,
    /// The specconv binary every task runs (on the shared file system).
    pub specconv: PathBuf,
    /// The directory tasks run in (where relative paths in `convert_options` mean something).
    pub workdir: PathBuf,
    /// The convert options every task gets, besides the ones the farm sets (`--json -u -j`).
    pub convert_options: Vec<String>,
    /// Every input of the job; rounds refer to them by index.
    pub files: Vec<File>,
    /// What each task asks of Slurm, the same in every round.
    pub request: Request,
    /// The rounds submitted, in order: the submission first, then each retry.
    pub rounds: Vec<Round>,
}

/// One input and where its output goes.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct File {
    /// The input texture, as the task's `convert` reads it (relative to `workdir` if relative).
    pub input: PathBuf,
    /// Where its spectral EXR goes; the file is done only when this exists.
    pub output: PathBuf,
    /// Pixels over all levels when planned (0 when the input could not be read then).
    pub pixels: u64,
}

/// What each array task asks of Slurm.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Request {
    /// `--partition`; `None` leaves Slurm's default.
    pub partition: Option<String>,
    /// `--time`, as sbatch reads it (`30`, `2:00:00`, `1-0`); `None` leaves the partition's limit.
    pub time: Option<String>,
    /// `--cpus-per-task`, also the threads each conversion uses (`-j`).
    pub cpus_per_task: usize,
    /// Memory per task in MiB.
    pub mem_mib: u64,
    /// At most this many tasks at once (`--array=…%K`).
    pub limit: Option<usize>,
}

/// One submission: an array whose task `t` converts the files `tasks[t]` (indices into
/// [`Manifest::files`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Round {
    /// The array job's id, as sbatch printed it.
    pub job_id: String,
    /// Per array task, the indices of its files.
    pub tasks: Vec<Vec<usize>>,
}

impl Manifest {
    /// `JOBDIR/manifest.json`.
    pub fn path(job_dir: &Path) -> PathBuf {
        job_dir.join("manifest.json")
    }

    /// Reads the manifest of a job directory: [`Error::Io`] when it cannot be read (not a job
    /// directory), [`Error::Manifest`] when it does not parse or has another [`FORMAT`].
    pub fn load(job_dir: &Path) -> Result<Manifest, Error> {
        let path = Manifest::path(job_dir);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            Error::Io(
                format!(
                    "cannot read {} (is this a job directory of `specconv farm submit`?)",
                    path.display()
                ),
                e,
            )
        })?;
        let m: Manifest = serde_json::from_str(&text)
            .map_err(|e| Error::Manifest(format!("{}: {e}", path.display())))?;
        if m.format != FORMAT {
            return Err(Error::Manifest(format!(
                "{} has layout {} where this specconv reads {FORMAT}; use the specconv that submitted it",
                path.display(),
                m.format
            )));
        }
        Ok(m)
    }

    /// Writes the manifest atomically (temporary file, then rename).
    pub fn save(&self, job_dir: &Path) -> Result<(), Error> {
        let path = Manifest::path(job_dir);
        let text = serde_json::to_string_pretty(self).expect("a manifest serialises");
        specconv_atomic_file::write(&path, (text + "\n").as_bytes())
            .map_err(|e| Error::Io(format!("cannot write {}", path.display()), e))
    }
}

/// The folder of round `r`.
pub fn round_dir(job_dir: &Path, round: usize) -> PathBuf {
    job_dir.join(format!("round-{round}"))
}

/// Task `t`'s list of inputs, its log (JSON lines, standard output) and its standard error.
pub fn task_inputs(round_dir: &Path, task: usize) -> PathBuf {
    round_dir.join(format!("task-{task}.inputs"))
}

/// `task-T.jsonl`: the task's log, its standard output.
pub fn task_log(round_dir: &Path, task: usize) -> PathBuf {
    round_dir.join(format!("task-{task}.jsonl"))
}

/// `task-T.err`: the task's standard error.
pub fn task_stderr(round_dir: &Path, task: usize) -> PathBuf {
    round_dir.join(format!("task-{task}.err"))
}

/// The sbatch options of a round: one array of `tasks` tasks, its logs in `round_dir`.
pub fn sbatch_options(m: &Manifest, round_dir: &Path, tasks: usize) -> Vec<String> {
    let r = &m.request;
    let mut o = vec![
        "--parsable".to_string(),
        "--job-name=specconv".to_string(),
        format!(
            "--array=0-{}{}",
            tasks - 1,
            r.limit.map_or(String::new(), |k| format!("%{k}"))
        ),
        format!("--cpus-per-task={}", r.cpus_per_task),
        format!("--mem={}M", r.mem_mib),
        format!("--chdir={}", m.workdir.display()),
        format!("--output={}", round_dir.join("task-%a.jsonl").display()),
        format!("--error={}", round_dir.join("task-%a.err").display()),
    ];
    if let Some(p) = &r.partition {
        o.push(format!("--partition={p}"));
    }
    if let Some(t) = &r.time {
        o.push(format!("--time={t}"));
    }
    o
}

/// The batch script every task runs: convert its list with `-u`, one JSON line per file on
/// standard output (the task's log), framed by start and end events that carry the time and
/// the exit code.
pub fn script(m: &Manifest, round_dir: &Path) -> String {
    let mut convert = vec![
        quote(&m.specconv.display().to_string()),
        "convert".into(),
        "--json".into(),
        "-u".into(),
        format!(
            "-j \"${{SLURM_CPUS_PER_TASK:-{}}}\"",
            m.request.cpus_per_task
        ),
    ];
    convert.extend(m.convert_options.iter().map(|o| quote(o)));
    convert.push("-".into());
    format!(
        r#"#!/bin/bash
# specconv farm: one task of a job array converts the inputs listed in its task-N.inputs.
# Written by `specconv farm`; its manifest is {manifest}.
t=$SLURM_ARRAY_TASK_ID
echo "{{\"event\":\"start\",\"task\":$t,\"unix\":$(date +%s.%N)}}"
# In the background, so that a SIGTERM (scancel, time limit) reaching this shell is passed on
# and waited for: the conversion stops between windows and removes its temporary file.
{convert} < {dir}/task-$t.inputs &
pid=$!
trap 'kill -TERM $pid 2>/dev/null' TERM INT
wait $pid
code=$?
while kill -0 $pid 2>/dev/null; do wait $pid; code=$?; done
echo "{{\"event\":\"end\",\"task\":$t,\"unix\":$(date +%s.%N),\"exit\":$code}}"
exit $code
"#,
        manifest = round_dir
            .parent()
            .unwrap_or(round_dir)
            .join("manifest.json")
            .display(),
        convert = convert.join(" "),
        dir = quote(&round_dir.display().to_string()),
    )
}

/// Quotes a word for bash (single quotes unless it is plainly safe).
pub fn quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_quoted_for_bash() {
        assert_eq!(quote("-o"), "-o");
        assert_eq!(quote("/a b/c"), "'/a b/c'");
        assert_eq!(quote("it's"), r"'it'\''s'");
        assert_eq!(quote(""), "''");
    }
}
