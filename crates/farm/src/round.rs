//! A round of a job: the memory its tasks ask for, its tasks' files, its folder and its submission,
//! waiting for it and removing what its killed tasks left.

use crate::error::Error;
use crate::manifest::{self, Manifest, Round};
use crate::slurm;
use crate::status::Status;
use crate::tasks::assign;
use std::path::{Path, PathBuf};
use std::time::Duration;

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

/// A round ready to submit: its folder, the script, the sbatch options and the tasks' files.
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
    let shards: Vec<Vec<usize>> = assign(&weights, n)
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
