//! One live job per output directory. Each output directory holds a marker, [`MARKER`], naming
//! the job directory of the latest submission into it. `submit` and `retry` lock the marker
//! (an exclusive file lock, so two at once cannot both pass), refuse when it names another job
//! whose tasks Slurm still has queued or running ([`Error::Busy`]), and record their own job
//! directory in it before calling sbatch; the lock is held until the round's job id is
//! recorded. A finished, cancelled or never-submitted job's marker does not block, and a
//! marker naming a job directory that is gone or damaged is simply replaced.

use crate::error::Error;

use crate::{slurm, Manifest};
use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The marker's name in an output directory.
pub const MARKER: &str = ".specconv-farm";

/// How long to wait for another submit's lock before giving up ([`Error::Locked`]).
pub const LOCK_WAIT: Duration = Duration::from_secs(120);

/// The markers of a job's output directories, locked until dropped.
#[derive(Debug)]
pub struct Claim {
    markers: Vec<(PathBuf, File)>,
}

/// Locks the marker of every directory in `dirs` (in sorted order, so two claims cannot wait on
/// each other), then refuses when one names a job directory other than `job_dir` whose tasks
/// are still live in Slurm.
pub fn claim(job_dir: &Path, dirs: &[PathBuf]) -> Result<Claim, Error> {
    let mut dirs = dirs.to_vec();
    dirs.sort();
    dirs.dedup();
    let mut markers = Vec::new();
    for dir in dirs {
        let path = dir.join(MARKER);
        let mut file = lock(&path)?;
        if let Some(other) = named(&mut file, &path)? {
            if other != job_dir {
                if let Some(job_id) = live_job(&other)? {
                    return Err(Error::Busy {
                        dir,
                        job_dir: other,
                        job_id,
                    });
                }
            }
        }
        markers.push((path, file));
    }
    Ok(Claim { markers })
}

impl Claim {
    /// Records `job_dir` in every marker (while still locked).
    pub fn record(&mut self, job_dir: &Path) -> Result<(), Error> {
        for (path, file) in &mut self.markers {
            let cannot = |e| Error::Io(format!("cannot write {}", path.display()), e);
            file.set_len(0).map_err(cannot)?;
            file.rewind().map_err(cannot)?;
            writeln!(file, "{}", job_dir.display()).map_err(cannot)?;
        }
        Ok(())
    }
}

/// Opens (creating) and locks a marker, waiting up to [`LOCK_WAIT`] for another holder.
fn lock(path: &Path) -> Result<File, Error> {
    // A FIFO or link planted under the marker's name is refused, never blocked on or followed.
    let file = specconv_atomic_file::create_own(path)
        .map_err(|e| Error::Io(format!("cannot open {}", path.display()), e.into_io()))?;
    let start = Instant::now();
    loop {
        match file.try_lock() {
            Ok(()) => return Ok(file),
            Err(std::fs::TryLockError::WouldBlock) if start.elapsed() < LOCK_WAIT => {
                std::thread::sleep(Duration::from_millis(100));
            }
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(Error::Locked {
                    lock: path.to_path_buf(),
                    seconds: LOCK_WAIT.as_secs(),
                })
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(Error::Io(format!("cannot lock {}", path.display()), e))
            }
        }
    }
}

/// The job directory a marker names (its first line), if any; a marker is a path, so reading
/// stops at 64 KiB.
fn named(file: &mut File, path: &Path) -> Result<Option<PathBuf>, Error> {
    let mut text = String::new();
    Read::by_ref(file)
        .take(64 << 10)
        .read_to_string(&mut text)
        .map_err(|e| Error::Io(format!("cannot read {}", path.display()), e))?;
    Ok(text
        .lines()
        .next()
        .filter(|l| !l.trim().is_empty())
        .map(PathBuf::from))
}

/// The id of a round of the job at `job_dir` with a task still queued or running, if any. A
/// job directory that is gone or does not load holds no live job.
fn live_job(job_dir: &Path) -> Result<Option<String>, Error> {
    let Ok(m) = Manifest::load(job_dir) else {
        return Ok(None);
    };
    for id in m.rounds.iter().rev().filter_map(|r| r.job_id.as_deref()) {
        if slurm::tasks(id)?.is_some_and(|t| t.iter().any(slurm::TaskState::active)) {
            return Ok(Some(id.to_string()));
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_marker_is_held_by_one_claim_at_a_time_and_records_its_job() {
        let d = std::env::temp_dir().join(format!("farm-claim-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let jobs = d.join("jobs");
        // A marker naming no loadable job blocks nothing.
        std::fs::write(d.join(MARKER), "/nowhere/job\n").unwrap();
        let mut c = claim(&jobs, &[d.clone(), d.clone()]).unwrap();
        assert_eq!(c.markers.len(), 1);
        c.record(&jobs).unwrap();
        // While held, another open description of the marker cannot lock it.
        let other = File::open(d.join(MARKER)).unwrap();
        assert!(matches!(
            other.try_lock(),
            Err(std::fs::TryLockError::WouldBlock)
        ));
        drop(c);
        assert!(other.try_lock().is_ok());
        drop(other);
        assert_eq!(
            std::fs::read_to_string(d.join(MARKER)).unwrap(),
            format!("{}\n", jobs.display())
        );
        std::fs::remove_dir_all(&d).unwrap();
    }
}
