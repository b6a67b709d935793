//! `farm task`: one array task's work, the job's options read from its manifest.

use super::{absolute, farm_error, Task, SET_BY_THE_FARM};
use crate::cmd::convert;
use crate::errors::usage;
use anyhow::{anyhow, Context, Result};
use specconv_conversion::plan::Pair;
use specconv_conversion::{Key, Options};
use specconv_farm::Manifest;
use std::path::Path;

/// The options a task converts with: the manifest's, with the farm's own.
pub(super) fn task_options(m: &Manifest, job_dir: &Path) -> Result<Options> {
    let mut options = Options::default();
    for (name, text) in &m.options {
        let key = Key::from_name(name)
            .filter(|k| !SET_BY_THE_FARM.contains(k))
            .ok_or_else(|| {
                anyhow!(
                    "{} names an option {name:?} that this specconv does not take: submit the job again with this version",
                    Manifest::path(job_dir).display()
                )
            })?;
        options
            .set(key, Some(text))
            .with_context(|| format!("in {}", Manifest::path(job_dir).display()))?;
    }
    options.ocio = Some(m.ocio.clone());
    let cpus = std::env::var("SLURM_CPUS_PER_TASK")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(m.request.cpus_per_task);
    options.threads = Some(cpus);
    Ok(options)
}

/// One array task: its files, converted with the job's options, skipping outputs up to date,
/// a JSON record per file on standard output.
pub(super) fn task(t: &Task) -> Result<i32> {
    let job_dir = absolute(&t.job_dir)?;
    let m = Manifest::load(&job_dir).map_err(farm_error)?;
    let pairs: Vec<Pair> = (m.task_files(t.round, t.task).map_err(farm_error)?)
        .into_iter()
        .map(|f| Pair {
            data: f.data.clone(),
            ..Pair::new(&f.input, &f.output)
        })
        .collect();
    let spaces: Vec<Option<&str>> = (m.task_files(t.round, t.task).map_err(farm_error)?)
        .into_iter()
        .map(|f| f.colorspace.as_deref())
        .collect();
    let options = task_options(&m, &job_dir).map_err(usage)?;
    convert::run_task(options, &pairs, &spaces)
}
