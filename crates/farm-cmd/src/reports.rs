//! `farm status`, `collect` and `retry`: a job read back from its directory and Slurm, reported,
//! a stage's layer written, and what failed resubmitted.

use crate::args::{Report, Retry};
use crate::job::{count, farm_error, pinned};
use crate::task::task_options;
use anyhow::Result;
use specconv_asset::Reader;
use specconv_conversion::plan::weights;
use specconv_convert_cmd::errors::{asset_error, print_error, usage};
use specconv_convert_cmd::{checks, exit};
use specconv_farm::manifest::Outputs;
use specconv_farm::{slurm, FileState, Manifest, Status};
use std::path::Path;

/// A stage's job: the layer over the stage ([`specconv_asset::farm_layer`]); false when none
/// was written (a stage changed since submit, a manifest edited), said as an error.
pub(crate) fn write_layer(m: &Manifest, job_dir: &Path, status: &Status) -> Result<bool> {
    let (Some(job), Outputs::Tree(dir)) = (&m.asset, &m.outputs) else {
        return Ok(true);
    };
    let options = task_options(m, job_dir).map_err(usage)?;
    let reader = Reader::from_env().map_err(asset_error)?;
    let files: Vec<specconv_asset::FarmFile> = status
        .files
        .iter()
        .map(|f| {
            let file = &m.files[f.index];
            let done = f.state == FileState::Done;
            (
                file.input.clone(),
                file.output.clone(),
                file.colorspace.clone(),
                done,
            )
        })
        .collect();
    match specconv_asset::farm_layer(&reader, (&job.stage, dir), &options, &files) {
        Ok(layer) => {
            errln!("specconv: {}", layer.line());
            Ok(true)
        }
        Err(why) => {
            print_error(&format!(
                "the layer {} is not written: {why}; submit the stage again (-u keeps what is \
                 up to date)",
                job.layer.display()
            ));
            Ok(false)
        }
    }
}

pub(crate) fn load(job_dir: &Path) -> Result<(Manifest, Status)> {
    let manifest = Manifest::load(job_dir).map_err(farm_error)?;
    let mut warned = false;
    let status = Status::read(job_dir, &manifest, &mut |id| {
        slurm::tasks(id).inspect_err(|e| {
            if !warned {
                errln!("specconv: warning: {e}; tasks Slurm did not report may still run");
                warned = true;
            }
        })
    })
    .map_err(farm_error)?;
    Ok((manifest, status))
}

/// Exit status of a report: OK when every file is done, else FAILED.
pub(crate) fn all_done(status: &Status) -> i32 {
    if status.files.iter().all(|f| f.state == FileState::Done) {
        exit::OK
    } else {
        exit::FAILED
    }
}

pub(crate) fn status(r: &Report) -> Result<i32> {
    let (m, status) = load(&r.job_dir)?;
    if r.json {
        outln!("{}", serde_json::to_string(&status)?)?;
        return Ok(all_done(&status));
    }
    for (round, sub) in m.rounds.iter().enumerate() {
        outln!(
            "round {round} ({}), {}:",
            if round == 0 { "submit" } else { "retry" },
            sub.job_id.as_ref().map_or_else(
                || "not submitted (interrupted before Slurm took it)".to_string(),
                |id| format!("job {id}")
            )
        )?;
        for t in status.tasks.iter().filter(|t| t.round == round) {
            outln!(
                "  task {:<3} {:<13} exit {:<6} {}",
                t.task,
                t.state,
                t.exit.as_deref().unwrap_or("-"),
                count(t.files, "file")
            )?;
        }
    }
    let s = status.collected();
    outln!(
        "files: {} done, {} failed, {} pending",
        s.done,
        s.failed,
        s.pending
    )?;
    for f in &status.files {
        match &f.state {
            FileState::Done => {}
            FileState::Failed { error } => outln!("  failed   {}: {error}", f.input.display())?,
            FileState::Pending { why, .. } => outln!("  pending  {}: {why}", f.input.display())?,
        }
    }
    Ok(all_done(&status))
}

pub(crate) fn collect(r: &Report) -> Result<i32> {
    let (m, status) = load(&r.job_dir)?;
    let s = status.collected();
    if r.json {
        outln!("{}", serde_json::to_string(&s)?)?;
        return collected(&m, &r.job_dir, &status);
    }
    outln!(
        "{} files: {} done, {} failed, {} pending{}",
        s.files,
        s.done,
        s.failed,
        s.pending,
        if s.running {
            " (tasks still queued or running)"
        } else {
            ""
        }
    )?;
    if s.seconds > 0.0 {
        outln!(
            "{:.1} Mpixel in {:.1} s over the array: {:.2} Mpixel/s",
            s.pixels as f64 / 1e6,
            s.seconds,
            s.pixels_per_second / 1e6
        )?;
    }
    for f in &s.failures {
        outln!("failed: {}: {}", f.input.display(), f.error)?;
    }
    for p in &s.pending_files {
        outln!("pending: {}: {}", p.input.display(), p.why)?;
    }
    if s.failed + s.pending > 0 && !s.running {
        outln!(
            "to convert them again: specconv farm retry {}",
            r.job_dir.display()
        )?;
    }
    collected(&m, &r.job_dir, &status)
}

/// The end of `collect`: a stage's layer written (once no task is live), and the exit status.
pub(crate) fn collected(m: &Manifest, job_dir: &Path, status: &Status) -> Result<i32> {
    let running = status.collected().running;
    let layer = running || write_layer(m, &std::path::absolute(job_dir)?, status)?;
    Ok(if layer {
        all_done(status)
    } else {
        exit::FAILED
    })
}

pub(crate) fn retry(r: &Retry, ocio: Option<String>) -> Result<i32> {
    let job_dir = std::path::absolute(&r.job_dir)?;
    // Locked before the job's state is read: a second retry of this job waits, then finds this
    // one's round live instead of submitting the same files again.
    let dirs = Manifest::load(&job_dir).map_err(farm_error)?.output_dirs();
    let mut claim = specconv_farm::claim::claim(&job_dir, &dirs).map_err(farm_error)?;
    let (mut m, status) = load(&job_dir)?;
    let again = status.to_retry();
    let waiting = status
        .files
        .iter()
        .filter(|f| matches!(f.state, FileState::Pending { waiting: true, .. }))
        .count();
    if again.is_empty() {
        if waiting > 0 {
            outln!("nothing to retry yet: {waiting} files wait for tasks still queued or running")?;
        } else {
            outln!("nothing to retry: all {} files are done", m.files.len())?;
        }
        return Ok(exit::OK);
    }
    // --ocio given to retry replaces the config the job was submitted with, checked as submit
    // checks it.
    if ocio.is_some() {
        m.ocio = pinned(&checks::config(ocio.as_deref())?)?;
    }
    specconv_farm::remove_leftovers(&m, &status, &again);
    // The inputs may have been fixed or replaced since: plan on what they are now.
    let inputs: Vec<&Path> = again.iter().map(|&i| m.files[i].input.as_path()).collect();
    for (&i, pixels) in again.iter().zip(weights(&inputs)) {
        m.files[i].pixels = pixels;
    }
    let last = m.rounds.last().map_or(1, |r| r.tasks.len());
    let tasks = r.tasks.map_or(last, |n| n as usize);
    let prepared = specconv_farm::prepare(&job_dir, &m, &again, tasks).map_err(farm_error)?;
    let n = prepared.tasks.len();
    claim.record(&job_dir)?;
    let job_id = specconv_farm::submit(&job_dir, &mut m, prepared).map_err(farm_error)?;
    drop(claim);
    outln!(
        "submitted job {job_id}: {} in {} (round {})",
        count(again.len(), "file"),
        count(n, "task"),
        m.rounds.len() - 1
    )?;
    outln!("job directory: {}", job_dir.display())?;
    if r.wait {
        return wait_and_collect(&job_dir, &job_id, false);
    }
    Ok(exit::OK)
}

/// `--wait`: waits for the job to end, then collects it as `farm collect` does.
pub(crate) fn wait_and_collect(job_dir: &Path, job_id: &str, json: bool) -> Result<i32> {
    specconv_farm::wait(job_id)?;
    collect(&Report {
        job_dir: job_dir.to_path_buf(),
        json,
    })
}
