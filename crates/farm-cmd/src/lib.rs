//! `specconv farm submit|status|collect|retry`: a texture library on a Slurm job array, each
//! task running the convert command (specconv-convert-cmd) on its shard. The plans, the job
//! directory and the reading of logs and Slurm live in the farm crate (specconv-farm); here the
//! inputs are measured, the convert options passed on, and the results reported. The cli
//! dispatches `farm` here.
#![forbid(unsafe_code)]

#[macro_use]
extern crate specconv_convert_cmd;

mod args;
mod job;
mod reports;
mod run;
mod submit;
mod task;

pub use args::{Args, EXAMPLES};
pub use run::run;
