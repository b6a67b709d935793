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
//! The job directory is checked, not trusted: [`Manifest::load`] refuses a manifest that names
//! anything the job does not own (an output outside its output directory or template, a file no
//! list holds) and files over [`manifest::MAX_FILE_BYTES`]; `%` in paths given to sbatch is
//! escaped; a round is recorded before sbatch runs and its job id after, so an interrupted
//! submit shows as not submitted; [`claim`] keeps one live job per output directory; and the
//! OCIO config `submit` checked is named on every task's command line
//! ([`Manifest::ocio`]).
//!
//! Nothing here reads images or links C++: the CLI measures inputs and passes pixel counts.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod claim;
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
    /// A manifest that names what its job does not own (an output outside the job's output
    /// directory, a file no list holds, a round folder that is a link): edited or damaged.
    #[error("{} names {named}, {why}: the manifest was edited or damaged; submit the job again into a new job directory", manifest.display())]
    Untrusted {
        /// The manifest.
        manifest: PathBuf,
        /// The path (or file index) it names.
        named: String,
        /// The rule it breaks, in words.
        why: String,
    },
    /// A manifest or task log larger than [`manifest::MAX_FILE_BYTES`]: not what specconv wrote.
    #[error("{} is larger than {limit} bytes, the limit for a job directory's file: it was not written by specconv farm", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The limit, in bytes.
        limit: u64,
    },
    /// A file of the job directory (`manifest.json`, a task log) that is missing or not a
    /// regular file of its own: a link, a FIFO, a device, a directory. Never followed or read.
    #[error("{}: {}; is this a job directory of `specconv farm submit`?", path.display(), match kind {
        specconv_atomic_file::Kind::Missing => "no such file".to_string(),
        k => format!("{k}, not a regular file of a job directory"),
    })]
    NotAJobFile {
        /// The file.
        path: PathBuf,
        /// What it is.
        kind: specconv_atomic_file::Kind,
    },
    /// A task the manifest does not plan (a script run with another job's numbers).
    #[error("the job has no task {task} in round {round}")]
    NoSuchTask {
        /// The round asked for.
        round: usize,
        /// The task asked for.
        task: usize,
    },
    /// A job directory whose path sbatch cannot be given as a log file name.
    #[error("the job directory {} holds {why}: sbatch cannot name its logs there; choose another --job-dir", dir.display())]
    JobDir {
        /// The job directory (or its round folder).
        dir: PathBuf,
        /// What sbatch cannot take in it.
        why: String,
    },
    /// Another job directory whose tasks are still queued or running writes into the same
    /// output directory ([`claim`]).
    #[error("job {job_id} (job directory {}) still writes into {}: wait for it (`specconv farm status {}`) or cancel it (`scancel {job_id}`) before submitting into that directory again", job_dir.display(), dir.display(), job_dir.display())]
    Busy {
        /// The output directory.
        dir: PathBuf,
        /// The other job's directory, as the output directory's marker names it.
        job_dir: PathBuf,
        /// Its Slurm job id.
        job_id: String,
    },
    /// Another submit or retry into the same output directory held its lock too long.
    #[error("another specconv farm submit or retry has held {} for {seconds} s; try again when it is done", lock.display())]
    Locked {
        /// The lock file ([`claim::MARKER`] in the output directory).
        lock: PathBuf,
        /// How long this one waited.
        seconds: u64,
    },
}

impl Error {
    /// Whether the job directory or the request itself is at fault (nothing was submitted,
    /// nothing changed): the CLI's usage status. A manifest that does not parse or has another
    /// layout, or is no regular file, is one (docs/farm.md).
    pub fn refused(&self) -> bool {
        matches!(
            self,
            Error::Untrusted { .. }
                | Error::Manifest(_)
                | Error::NotAJobFile { .. }
                | Error::TooLarge { .. }
                | Error::JobDir { .. }
                | Error::Busy { .. }
                | Error::Locked { .. }
        )
    }
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
/// tasks (no empty task), balanced by the manifest's pixel counts. [`Error::JobDir`] when the
/// job directory cannot be named to sbatch.
pub fn prepare(
    job_dir: &Path,
    m: &Manifest,
    files: &[usize],
    tasks: usize,
) -> Result<Prepared, Error> {
    let weights: Vec<u64> = files.iter().map(|&i| m.files[i].pixels).collect();
    let n = tasks.clamp(1, files.len().max(1));
    let shards: Vec<Vec<usize>> = plan(&weights, n)
        .into_iter()
        .map(|s| s.into_iter().map(|k| files[k]).collect())
        .collect();
    let round = m.rounds.len();
    let dir = manifest::round_dir(job_dir, round);
    Ok(Prepared {
        round,
        script: manifest::script(m, job_dir, round),
        sbatch: manifest::sbatch_options(m, &dir, shards.len())?,
        dir,
        tasks: shards,
    })
}

/// Records the round in the manifest as not submitted, writes its folder (script, input
/// lists), submits it and records its job id (each save atomic). A submit killed before sbatch
/// returns leaves the round recorded without a job id: `status` says "not submitted" and
/// `retry` submits its files. When the folder cannot be written or sbatch refuses the job, the
/// round and the folder are removed again.
pub fn submit(job_dir: &Path, m: &mut Manifest, p: Prepared) -> Result<String, Error> {
    m.rounds.push(Round {
        job_id: None,
        tasks: p.tasks.clone(),
    });
    if let Err(e) = m.save(job_dir) {
        m.rounds.pop();
        return Err(e);
    }
    let submitted = write_round(m, &p).and_then(|script| {
        slurm::submit(&p.sbatch, &script).inspect_err(|_| {
            let _ = std::fs::remove_dir_all(&p.dir);
        })
    });
    match submitted {
        Ok(job_id) => {
            if let Some(r) = m.rounds.last_mut() {
                r.job_id = Some(job_id.clone());
            }
            m.save(job_dir)?;
            Ok(job_id)
        }
        Err(e) => {
            m.rounds.pop();
            m.save(job_dir)?;
            Err(e)
        }
    }
}

/// Writes a new round's folder: the script and each task's input list; returns the script's
/// path. The folder must be new (one already there, perhaps a link planted elsewhere, is not
/// written through); a folder left half-written is removed.
fn write_round(m: &Manifest, p: &Prepared) -> Result<PathBuf, Error> {
    let io = |what: &Path| {
        let what = what.display().to_string();
        move |e| Error::Io(format!("cannot write {what}"), e)
    };
    std::fs::create_dir(&p.dir).map_err(io(&p.dir))?;
    let script = p.dir.join("job.sbatch");
    let mut written = std::fs::write(&script, &p.script).map_err(io(&script));
    for (t, files) in p.tasks.iter().enumerate() {
        let list = manifest::task_inputs(&p.dir, t);
        let text: String = files
            .iter()
            .map(|&i| format!("{}\n", m.files[i].input.display()))
            .collect();
        written = written.and_then(|()| std::fs::write(&list, text).map_err(io(&list)));
    }
    match written {
        Ok(()) => Ok(script),
        Err(e) => {
            let _ = std::fs::remove_dir_all(&p.dir);
            Err(e)
        }
    }
}

/// Removes the temporary files that killed tasks left beside the outputs of `files` (indices
/// into the manifest), but only of files whose task is known to have ended (a task still
/// queued or running, or whose state Slurm did not give, may be writing one), and only those
/// no live writer holds ([`specconv_atomic_file::remove_stale`]: a conversion of the same
/// output run by hand or by another job keeps its file). Outputs were confined to the job's
/// output directory when the manifest was loaded, so nothing outside it is touched. Returns
/// how many were removed.
pub fn remove_leftovers(m: &Manifest, status: &Status, files: &[usize]) -> usize {
    files
        .iter()
        .filter(|&&i| status.ended(i))
        .map(|&i| specconv_atomic_file::remove_stale(&m.files[i].output).len())
        .sum()
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
