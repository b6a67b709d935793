//! `farm submit`: the inputs (files, or a USD stage decided by the asset library) planned and
//! measured, the job directory written and the array submitted (or the plan printed).

use crate::args::Submit;
use crate::job::{absolute, count, farm_error, pinned, recorded_options};
use crate::reports::wait_and_collect;
use anyhow::{anyhow, bail, Context, Result};
use specconv_asset::{Job, Prepared, Reader};
use specconv_conversion::plan::{weights, Pair};
use specconv_conversion::Options;
use specconv_convert_cmd::convert;
use specconv_convert_cmd::errors::{asset_error, print_error, usage};
use specconv_convert_cmd::{checks, exit};
use specconv_farm::manifest::{AssetJob, Outputs};
use specconv_farm::{Manifest, Request};
use std::path::{Path, PathBuf};

/// What a submission converts: where outputs go, the files, the stage they come from, and how
/// many of its textures cannot be converted (each said as an error already).
pub(crate) struct Planned {
    outputs: Outputs,
    files: Vec<specconv_farm::manifest::File>,
    asset: Option<AssetJob>,
    unplanned: usize,
}

pub(crate) fn submit(s: Submit, ocio: Option<String>) -> Result<i32> {
    if s.convert.sharded() {
        return Err(usage(anyhow!(
            "farm submit plans the shards itself: drop --shard"
        )));
    }
    let mut given = s.convert.options();
    // The model in force here is the tasks' (as the OCIO config is): a node's own
    // $SPECCONV_MODEL, or none, changes nothing. It must load before anything is submitted.
    use specconv_conversion::models;
    models::load(given.model.as_deref()).map_err(usage)?;
    given.model = Some(models::pinned(given.model.as_deref()));
    // Settings that cannot work for any input fail here, not once in every task.
    let config = checks::config(ocio.as_deref())?;
    checks::input_colorspace(&config, s.convert.colorspace())?;
    let ocio = pinned(&config)?;
    let planned = match stage_input(&s.convert)? {
        Some(stage) => plan_stage(&s, stage, &given, &ocio)?,
        None => plan_files(&s)?,
    };
    let largest = planned.files.iter().map(|f| f.pixels).max().unwrap_or(0);
    let mem_mib = match &s.mem {
        Some(m) => parse_mem(m)
            .ok_or_else(|| usage(anyhow!("--mem {m:?} is not a size such as 800M or 4G")))?,
        None => specconv_farm::memory_mib(largest),
    };
    let job_dir = job_dir_for(&s)?;
    if Manifest::path(&job_dir).exists() {
        return Err(usage(anyhow!(
            "{} already holds a job; use `specconv farm retry {}` or another --job-dir",
            job_dir.display(),
            job_dir.display()
        )));
    }
    let manifest = Manifest {
        format: specconv_farm::manifest::FORMAT,
        specconv: std::env::current_exe().context("cannot locate the specconv binary")?,
        workdir: std::env::current_dir().context("cannot read the current directory")?,
        ocio,
        outputs: planned.outputs,
        options: recorded_options(&given),
        files: planned.files,
        request: Request {
            partition: s.partition.clone(),
            time: s.time.clone(),
            cpus_per_task: s.cpus_per_task as usize,
            mem_mib,
            limit: s.max_running.map(|k| k as usize),
        },
        rounds: Vec::new(),
        asset: planned.asset,
    };
    let code = submit_job(&s, manifest, &job_dir)?;
    // A texture of the stage that cannot be converted was said; the job goes on without it.
    Ok(if planned.unplanned > 0 && code == exit::OK {
        exit::FAILED
    } else {
        code
    })
}

/// Checks the manifest, then prints the plan (`--dry-run`) or claims the output directories,
/// writes the job directory and submits round 0.
pub(crate) fn submit_job(s: &Submit, mut manifest: Manifest, job_dir: &Path) -> Result<i32> {
    // What tasks and later commands will check, checked before anything is written.
    manifest.check(job_dir).map_err(farm_error)?;
    let all: Vec<usize> = (0..manifest.files.len()).collect();
    let prepared =
        specconv_farm::prepare(job_dir, &manifest, &all, s.tasks as usize).map_err(farm_error)?;
    if s.dry_run {
        print_plan(&manifest, &prepared)?;
        return Ok(exit::OK);
    }
    // Held until the job id is recorded: a second submit into these directories waits, then
    // sees this job live.
    let mut claim =
        specconv_farm::claim::claim(job_dir, &manifest.output_dirs()).map_err(farm_error)?;
    std::fs::create_dir_all(job_dir)
        .with_context(|| format!("cannot create the job directory {}", job_dir.display()))?;
    claim.record(job_dir)?;
    let tasks = prepared.tasks.len();
    let job_id = match specconv_farm::submit(job_dir, &mut manifest, prepared) {
        Ok(id) => id,
        Err(e) => {
            // Nothing was submitted: leave no job directory behind.
            let _ = std::fs::remove_dir_all(job_dir);
            return Err(farm_error(e));
        }
    };
    drop(claim);
    announce(&s.convert, &job_id, job_dir, tasks, manifest.files.len())?;
    if s.wait {
        return wait_and_collect(job_dir, &job_id, s.convert.json_wanted());
    }
    Ok(exit::OK)
}

/// The inputs as files: `-o DIR` or `--output-template`, each planned as `convert` plans them.
pub(crate) fn plan_files(s: &Submit) -> Result<Planned> {
    let outputs = match (s.convert.output_dir(), s.convert.output_template()) {
        (Some(dir), _) => Outputs::Directory(absolute(dir)?),
        (None, Some(t)) => Outputs::Template(t.to_string()),
        (None, None) => {
            return Err(usage(anyhow!(
                "farm submit writes many outputs: give -o DIR or --output-template"
            )))
        }
    };
    // Every task converts with -u.
    let plan = convert::for_farm(&s.convert).map_err(usage)?;
    if plan.is_empty() {
        return Err(usage(anyhow!("no inputs to submit")));
    }
    Ok(Planned {
        outputs,
        files: listed_files(plan.pairs())?,
        asset: None,
        unplanned: 0,
    })
}

/// The one input, when it is a USD stage (by its extension); a stage among other inputs is a
/// usage error.
pub(crate) fn stage_input(args: &convert::Args) -> Result<Option<&Path>> {
    let inputs = args.inputs();
    if let Some(doc) = inputs.iter().find(|p| specconv_asset::is_document(p)) {
        return Err(usage(anyhow!(
            "{} is a MaterialX document, which a farm job does not take yet: convert it with \
             `specconv asset {} -o DIR` (docs/assets.md)",
            doc.display(),
            doc.display()
        )));
    }
    match inputs.iter().find(|p| specconv_asset::is_stage(p)) {
        None => Ok(None),
        Some(stage) if inputs.len() == 1 => Ok(Some(stage)),
        Some(stage) => Err(usage(anyhow!(
            "{} is a USD stage, which is submitted alone (`specconv farm submit STAGE -o DIR`): \
             submit the other inputs in a job of their own",
            stage.display()
        ))),
    }
}

/// A stage's textures, read and decided by the asset library once, here: each file with the
/// colour space its material gave it (docs/assets.md), outputs under DIR as `asset` puts them.
pub(crate) fn plan_stage(s: &Submit, stage: &Path, given: &Options, ocio: &str) -> Result<Planned> {
    let Some(dir) = s.convert.output_dir() else {
        return Err(usage(anyhow!(
            "a stage's outputs are named by its plan (docs/assets.md): give -o DIR, not \
             --output-template"
        )));
    };
    if given.colorspace.is_some() {
        return Err(usage(anyhow!(
            "a stage takes no --colorspace: the material names each texture's colour space \
             (docs/assets.md)"
        )));
    }
    let mut options = given.clone();
    options.ocio = Some(ocio.to_string());
    let reader = Reader::from_env().map_err(asset_error)?;
    let replace = s.convert.updating() || options.overwrite;
    let Prepared { asset, jobs } =
        specconv_asset::prepare(&reader, (stage, dir), &options, (s.dry_run, replace))
            .map_err(asset_error)?;
    let mut unplanned = 0;
    for t in &asset.textures {
        if let Some(why) = &t.error {
            print_error(&format!("{}: {why}", t.texture.file.display()));
            unplanned += 1;
        }
    }
    if jobs.is_empty() {
        return Err(usage(anyhow!(
            "{}: no texture to submit ({} read by its bound materials, {unplanned} not \
             convertible)",
            asset.stage.display(),
            asset.textures.len()
        )));
    }
    if !s.dry_run {
        // The folders below DIR, made once here on the shared file system, not by each task.
        specconv_asset::make_folders(&asset.dir, &jobs).map_err(asset_error)?;
    }
    let pairs: Vec<Pair> = jobs.iter().map(Job::pair).collect();
    let mut files = listed_files(&pairs)?;
    for (f, j) in files.iter_mut().zip(&jobs) {
        f.colorspace = j.colorspace.clone();
    }
    Ok(Planned {
        outputs: Outputs::Tree(asset.dir.clone()),
        files,
        asset: Some(AssetJob {
            stage: asset.stage,
            layer: asset.layer,
        }),
        unplanned,
    })
}

/// The manifest's files: absolute paths (tasks may start elsewhere) and pixel counts.
pub(crate) fn listed_files(pairs: &[Pair]) -> Result<Vec<specconv_farm::manifest::File>> {
    let inputs: Vec<&Path> = pairs.iter().map(|p| p.input.as_path()).collect();
    let mut files = Vec::new();
    for (
        Pair {
            input: i,
            output: o,
            data,
        },
        pixels,
    ) in pairs.iter().zip(weights(&inputs))
    {
        if i.to_string_lossy().contains('\n') {
            bail!(
                "{:?}: input paths with a newline cannot be listed for a task; rename it",
                i
            );
        }
        files.push(specconv_farm::manifest::File {
            input: absolute(i)?,
            output: absolute(o)?,
            data: data.as_deref().map(absolute).transpose()?,
            pixels,
            colorspace: None,
        });
    }
    Ok(files)
}

/// --job-dir, else a new specconv-farm-SECONDS folder in the output directory.
pub(crate) fn job_dir_for(s: &Submit) -> Result<PathBuf> {
    Ok(match (&s.job_dir, s.convert.output_dir()) {
        (Some(d), _) => absolute(d)?,
        (None, Some(dir)) => {
            let secs = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            let mut d = absolute(dir)?.join(format!("specconv-farm-{secs}"));
            let mut k = 1;
            while d.exists() {
                k += 1;
                d = absolute(dir)?.join(format!("specconv-farm-{secs}-{k}"));
            }
            d
        }
        (None, None) => {
            return Err(usage(anyhow!(
                "with --output-template, give --job-dir JOBDIR (on a file system the nodes share)"
            )))
        }
    })
}

/// `--dry-run`: the plan, the sbatch command and the script, as comments and text.
pub(crate) fn print_plan(manifest: &Manifest, prepared: &specconv_farm::Prepared) -> Result<()> {
    outln!(
        "# plan: {} in {}",
        count(manifest.files.len(), "file"),
        count(prepared.tasks.len(), "task")
    )?;
    // What every task converts with: the manifest's, as `farm task` reads them.
    match &manifest.outputs {
        Outputs::Directory(d) => outln!("# outputs: directory {}", d.display())?,
        Outputs::Template(t) => outln!("# outputs: template {t}")?,
        Outputs::Tree(d) => outln!("# outputs: below {}", d.display())?,
    }
    if let Some(a) = &manifest.asset {
        outln!(
            "# stage: {} (collect writes the layer {})",
            a.stage.display(),
            a.layer.display()
        )?;
    }
    let options: Vec<String> = manifest
        .options
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    outln!("# config: {}", manifest.ocio)?;
    outln!(
        "# options: {}",
        if options.is_empty() {
            "the defaults".to_string()
        } else {
            options.join(" ")
        }
    )?;
    for (t, shard) in prepared.tasks.iter().enumerate() {
        let px: u64 = shard.iter().map(|&i| manifest.files[i].pixels).sum();
        // A task's files in one write, not one a line: a plan may list 100,000.
        let mut lines = format!("# task {t}: {}, {px} pixels\n", count(shard.len(), "file"));
        for &i in shard {
            use std::fmt::Write;
            let f = &manifest.files[i];
            let _ = match &f.colorspace {
                Some(c) => writeln!(lines, "#   {} [colour space {c}]", f.input.display()),
                None => writeln!(lines, "#   {}", f.input.display()),
            };
        }
        out!("{lines}")?;
    }
    outln!(
        "# sbatch {} {}",
        prepared.sbatch.join(" "),
        prepared.dir.join("job.sbatch").display()
    )?;
    out!("{}", prepared.script)?;
    Ok(())
}

pub(crate) fn announce(
    convert: &convert::Args,
    job_id: &str,
    job_dir: &Path,
    tasks: usize,
    files: usize,
) -> Result<()> {
    if convert.json_wanted() {
        outln!(
            "{}",
            serde_json::json!({"job_id": job_id, "job_dir": job_dir, "tasks": tasks, "files": files})
        )?;
    } else {
        outln!(
            "submitted job {job_id}: {} in {}",
            count(files, "file"),
            count(tasks, "task")
        )?;
        outln!("job directory: {}", job_dir.display())?;
    }
    Ok(())
}

/// `800M`, `4G`, `4000` (MiB, as sbatch reads it) → MiB.
pub(crate) fn parse_mem(s: &str) -> Option<u64> {
    let s = s.trim();
    let (num, mult) = match s.char_indices().last()? {
        (i, 'K' | 'k') => (&s[..i], 0),
        (i, 'M' | 'm') => (&s[..i], 1),
        (i, 'G' | 'g') => (&s[..i], 1024),
        (i, 'T' | 't') => (&s[..i], 1024 * 1024),
        _ => (s, 1),
    };
    let n: u64 = num.parse().ok()?;
    Some(if mult == 0 {
        n.div_ceil(1024)
    } else {
        n * mult
    })
    .filter(|&v| v > 0)
}

#[cfg(test)]
mod tests {
    use super::parse_mem;

    #[test]
    fn memory_sizes_read_as_sbatch_reads_them() {
        assert_eq!(parse_mem("800M"), Some(800));
        assert_eq!(parse_mem("4G"), Some(4096));
        assert_eq!(parse_mem("1500"), Some(1500));
        assert_eq!(parse_mem("2048k"), Some(2));
        assert_eq!(parse_mem("lots"), None);
        assert_eq!(parse_mem("0"), None);
    }
}
