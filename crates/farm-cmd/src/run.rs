//! Dispatch of `specconv farm SUBCOMMAND`.

use crate::args::{Args, Farm};
use crate::reports::{collect, retry, status};
use crate::submit::submit;
use crate::task::task;
use anyhow::Result;

/// Runs a farm command; `ocio` is the global --ocio, passed on to the tasks.
pub fn run(args: Args, ocio: Option<String>) -> Result<i32> {
    match args.command {
        Farm::Submit(s) => submit(*s, ocio),
        Farm::Status(r) => status(&r),
        Farm::Collect(r) => collect(&r),
        Farm::Retry(r) => retry(&r, ocio),
        Farm::Task(t) => task(&t),
    }
}
