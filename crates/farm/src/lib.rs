//! specconv on a farm: a texture library split across the tasks of one Slurm job array.
//!
//! `specconv farm submit` plans the shards ([`mod@plan`]: balanced by pixel count, deterministic),
//! writes a job directory ([`manifest`]: inputs, outputs, settings, each round's plan, the
//! batch script, the task logs) and submits one array with `sbatch`. Each task runs
//! `specconv convert --json -u` on its list, so its log holds one JSON line per file and a
//! file is done exactly when its output was renamed into place. `status`, `collect` and
//! `retry` read the logs and Slurm's view of each task ([`slurm`], [`status`]); a file whose
//! task died before reaching it is pending, and a retry submits only what failed or is pending.
//!
//! Nothing here reads images or links C++: the CLI measures inputs and passes pixel counts.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod log;
pub mod manifest;
pub mod plan;
pub mod slurm;
pub mod status;

pub use manifest::{Manifest, Request, Round};
pub use plan::{plan, Shard};
pub use status::{FileState, Status, Summary};

use std::path::{Path, PathBuf};
use std::time::Duration;

/// What can go wrong planning, submitting or reading a farm job; each message says what to do.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A `--shard` that is malformed or names no shard, or `auto/N` outside a Slurm array task.
    #[error("{0}")]
    Shard(String),
    /// A `manifest.json` that does not parse, or of another layout ([`manifest::FORMAT`]).
    #[error("{0}")]
    Manifest(String),
    /// A Slurm command that could not run, failed (its standard error is in the text) or printed
    /// no job id.
    #[error("{0}")]
    Slurm(String),
    /// A file of the job directory that could not be read or written: what was attempted, and the
    /// I/O error.
    #[error("{0}: {1}")]
    Io(String, #[source] std::io::Error),
}

/// Peak resident memory of a conversion: a fixed part (the program, the model, OCIO) plus a
/// part per pixel of the largest input (OpenImageIO's buffers and the window of strips in
/// flight). Measured with `/usr/bin/time -v` by scripts/farm_memory.sh; see docs/farm.md.
pub const MEMORY_BASE_MIB: u64 = 138;
/// The part per pixel of the largest input, in bytes (see [`MEMORY_BASE_MIB`], in MiB).
pub const MEMORY_BYTES_PER_PIXEL: f64 = 1.4;

/// Memory to request per task: the measured peak for the largest input, with 50 % headroom.
pub fn memory_mib(largest_pixels: u64) -> u64 {
    let peak = MEMORY_BASE_MIB as f64 + MEMORY_BYTES_PER_PIXEL * largest_pixels as f64 / 1048576.0;
    (peak * 1.5).ceil() as u64
}

/// A round ready to submit: its folder, the script, the sbatch options and the plan.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The round's number: its index in [`Manifest::rounds`] once submitted (0 the submission,
    /// then one per retry).
    pub round: usize,
    /// The round's folder, `JOBDIR/round-N` ([`manifest::round_dir`]); written by [`submit`].
    pub dir: PathBuf,
    /// The batch script every task runs ([`manifest::script`]).
    pub script: String,
    /// The sbatch options ([`manifest::sbatch_options`]), without the script.
    pub sbatch: Vec<String>,
    /// Per task, the files it converts (indices into [`Manifest::files`], increasing); none empty.
    pub tasks: Vec<Vec<usize>>,
}

/// Plans a new round of the given files (indices into the manifest) over at most `tasks`
/// tasks (no empty task), balanced by the manifest's pixel counts.
pub fn prepare(job_dir: &Path, m: &Manifest, files: &[usize], tasks: usize) -> Prepared {
    let weights: Vec<u64> = files.iter().map(|&i| m.files[i].pixels).collect();
    let n = tasks.clamp(1, files.len().max(1));
    let shards: Vec<Vec<usize>> = plan(&weights, n)
        .into_iter()
        .map(|s| s.into_iter().map(|k| files[k]).collect())
        .collect();
    let round = m.rounds.len();
    let dir = manifest::round_dir(job_dir, round);
    Prepared {
        round,
        script: manifest::script(m, &dir),
        sbatch: manifest::sbatch_options(m, &dir, shards.len()),
        dir,
        tasks: shards,
    }
}

/// Writes the round's folder (script, input lists), submits it and records it in the manifest
/// (saved). Nothing is recorded when sbatch refuses the job.
pub fn submit(job_dir: &Path, m: &mut Manifest, p: Prepared) -> Result<String, Error> {
    let io = |what: &Path| {
        let what = what.display().to_string();
        move |e| Error::Io(format!("cannot write {what}"), e)
    };
    std::fs::create_dir_all(&p.dir).map_err(io(&p.dir))?;
    let script = p.dir.join("job.sbatch");
    std::fs::write(&script, &p.script).map_err(io(&script))?;
    for (t, files) in p.tasks.iter().enumerate() {
        let list = manifest::task_inputs(&p.dir, t);
        let text: String = files
            .iter()
            .map(|&i| format!("{}\n", m.files[i].input.display()))
            .collect();
        std::fs::write(&list, text).map_err(io(&list))?;
    }
    let job_id = match slurm::submit(&p.sbatch, &script) {
        Ok(id) => id,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&p.dir);
            return Err(e);
        }
    };
    m.rounds.push(Round {
        job_id: job_id.clone(),
        tasks: p.tasks,
    });
    m.save(job_dir)?;
    Ok(job_id)
}

/// Returns when no task of the job is queued or running. Polls `scontrol` (faster than
/// `sbatch --wait`), every half second at first, then every 5 s.
pub fn wait(job_id: &str) -> Result<(), Error> {
    let mut pause = Duration::from_millis(500);
    loop {
        match slurm::tasks(job_id)? {
            Some(t) if t.iter().any(slurm::TaskState::active) => {}
            _ => return Ok(()),
        }
        std::thread::sleep(pause);
        pause = (pause * 5 / 4).min(Duration::from_secs(5));
    }
}
