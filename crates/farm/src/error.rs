//! What can go wrong planning, submitting or reading a farm job: this crate's error.

use std::path::PathBuf;

/// What can go wrong planning, submitting or reading a farm job; each message says what to do.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A `--shard` that is malformed or names no shard, or `auto/N` outside a Slurm array task.
    #[error("{0}")]
    Shard(String),
    /// A `manifest.json` that does not parse, or of another layout
    /// ([`manifest::FORMAT`](crate::manifest::FORMAT)).
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
    /// A manifest or task log larger than
    /// [`manifest::MAX_FILE_BYTES`](crate::manifest::MAX_FILE_BYTES): not what specconv wrote.
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
    /// A task the manifest does not list (a script run with another job's numbers).
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
    /// output directory ([`claim`](crate::claim)).
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
        /// The lock file ([`claim::MARKER`](crate::claim::MARKER) in the output directory).
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
