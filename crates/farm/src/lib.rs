//! specconv on a farm: a texture library split across the tasks of one Slurm job array.
//!
//! `specconv farm submit` assigns the inputs to tasks ([`tasks`]: balanced by pixel count,
//! deterministic), writes a job directory ([`manifest`]: inputs, outputs, settings, each round's tasks, the
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
mod error;
pub mod log;
pub mod manifest;
mod round;
pub mod slurm;
pub mod status;
pub mod tasks;

pub use error::Error;
pub use manifest::{Manifest, Request, Round};
pub use round::{
    memory_mib, prepare, remove_leftovers, submit, wait, Prepared, MEMORY_BASE_MIB,
    MEMORY_BYTES_PER_PIXEL,
};
pub use status::{Collected, FileState, Status};
pub use tasks::{assign, Shard};
