//! `specconv farm submit|status|collect|retry`: a texture library on a Slurm job array. The
//! plans, the job directory and the reading of logs and Slurm live in the farm crate; here the
//! inputs are measured, the convert options passed on, and the results reported.

use crate::cmd::asset::asset_error;
use crate::cmd::convert;
use crate::errors::{print_error, usage};
use crate::{checks, exit};
use anyhow::{anyhow, bail, Context, Result};
use specconv_asset::{Job, Prepared, Reader};
use specconv_conversion::plan::{weights, Pair};
use specconv_conversion::{Key, Options};
use specconv_farm::manifest::{AssetJob, Outputs};
use specconv_farm::{slurm, FileState, Manifest, Request, Status};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub const EXAMPLES: &str = "\
Examples:
  specconv farm submit textures/*.tx -o /shared/spectral --tasks 16 --cpus-per-task 4
  find textures -name '*.tx' | specconv farm submit - -o /shared/spectral --tasks 64 --wait
  specconv farm submit textures/*.tx -o spectral --tasks 4 --dry-run
  specconv farm submit shot.usda -o /shared/spectral --tasks 8 --wait
  specconv farm status /shared/spectral/specconv-farm-1764601234
  specconv farm collect --json /shared/spectral/specconv-farm-1764601234
  specconv farm retry --wait /shared/spectral/specconv-farm-1764601234
";

/// Convert a texture library on a Slurm cluster: one job array, a shard of the inputs per task.
///
/// `submit` writes a job directory (manifest, batch script, task logs) on the shared file
/// system and submits one array; `status` shows each task and file; `collect` summarises;
/// `retry` resubmits only what failed or was not reached. The last three change nothing when
/// run twice. Each task runs `specconv convert --json -u` on its shard, so a task killed
/// mid-file leaves no partial output and its files stay pending until a retry.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Farm,
}

#[derive(Debug, clap::Subcommand)]
enum Farm {
    #[command(after_long_help = EXAMPLES)]
    Submit(Box<Submit>),
    /// Show each task's Slurm state and exit code, and the files failed or pending.
    #[command(after_long_help = EXAMPLES)]
    Status(Report),
    /// Summarise a job: counts, each failure with its error, time and pixels per second.
    #[command(after_long_help = EXAMPLES)]
    Collect(Report),
    /// Resubmit only the files that failed or that ended tasks did not reach.
    #[command(after_long_help = EXAMPLES)]
    Retry(Retry),
    /// One array task's work, as the job's script runs it: the task's files with the job's
    /// options, read from its manifest.
    #[command(hide = true)]
    Task(Task),
}

/// Submit a job array converting INPUT… (or `-`: paths on standard input) into -o DIR.
///
/// Takes every option of `convert`; -j comes from --cpus-per-task, and tasks always skip
/// outputs that are up to date (-u). The inputs are split into --tasks shards of nearly equal
/// pixel count, the same plan as `convert --shard`. A USD stage (.usd, .usda, .usdc, .usdz,
/// given alone) is submitted as `specconv asset` converts it: each texture decided here by its
/// material and converted by the tasks in that colour space, outputs below DIR; `farm collect`
/// writes the layer DIR/STEM_spectral.usda (docs/farm.md).
#[derive(Debug, clap::Args)]
struct Submit {
    #[command(flatten)]
    convert: convert::Args,
    /// Number of array tasks (shards).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    tasks: u32,
    /// At most K tasks at once (`--array=0-(N-1)%K`).
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..))]
    max_running: Option<u32>,
    /// Job directory, on a file system the nodes share (default: a new specconv-farm-TIME
    /// folder in the -o directory).
    #[arg(long, value_name = "JOBDIR")]
    job_dir: Option<PathBuf>,
    /// Slurm partition.
    #[arg(long, value_name = "P")]
    partition: Option<String>,
    /// Time limit per task, as sbatch reads it (`30`, `2:00:00`, `1-0`).
    #[arg(long, value_name = "T")]
    time: Option<String>,
    /// CPUs per task; each task converts with that many threads.
    #[arg(long, value_name = "C", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    cpus_per_task: u32,
    /// Memory per task (`4G`, `800M`; default: the measured peak for the largest input, plus
    /// half).
    #[arg(long, value_name = "M")]
    mem: Option<String>,
    /// Return when the array ends; exit 0 only if every file converted.
    #[arg(long)]
    wait: bool,
    /// Print the plan, the sbatch command and the script; write and submit nothing.
    #[arg(long)]
    dry_run: bool,
}

#[derive(Debug, clap::Args)]
struct Report {
    /// The job directory `submit` printed.
    #[arg(value_name = "JOBDIR")]
    job_dir: PathBuf,
    /// One JSON object on standard output.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Args)]
struct Retry {
    /// The job directory `submit` printed.
    #[arg(value_name = "JOBDIR")]
    job_dir: PathBuf,
    /// Number of array tasks (default: as many as the last submission, at most one per file).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    tasks: Option<u32>,
    /// Return when the array ends; exit 0 only if every file converted.
    #[arg(long)]
    wait: bool,
}

/// `farm task JOBDIR --round R --task T`, the command line `specconv_farm::manifest::task_command`
/// makes for the job's script.
#[derive(Debug, clap::Args)]
struct Task {
    /// The job directory.
    #[arg(value_name = "JOBDIR")]
    job_dir: PathBuf,
    /// The round (0: the submission, then one per retry).
    #[arg(long, value_name = "R")]
    round: usize,
    /// The array task ($SLURM_ARRAY_TASK_ID).
    #[arg(long, value_name = "T")]
    task: usize,
}

/// Options the farm sets itself: the config is the manifest's, threads are the task's CPUs,
/// and outputs are replaced only when out of date.
const SET_BY_THE_FARM: [Key; 3] = [Key::Ocio, Key::Threads, Key::Overwrite];

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

/// The options of a job, as the manifest records them: those that differ from the library's
/// defaults, by the library's names and text, but for what the farm sets itself.
fn recorded_options(options: &Options) -> BTreeMap<String, String> {
    let defaults = Options::default();
    Key::ALL
        .into_iter()
        .filter(|k| !SET_BY_THE_FARM.contains(k))
        .filter_map(|k| {
            let text = options.text(k)?;
            (Some(&text) != defaults.text(k).as_ref()).then(|| (k.about().name.to_string(), text))
        })
        .collect()
}

/// The options a task converts with: the manifest's, with the farm's own.
fn task_options(m: &Manifest, job_dir: &Path) -> Result<Options> {
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
fn task(t: &Task) -> Result<i32> {
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

/// What a submission converts: where outputs go, the files, the stage they come from, and how
/// many of its textures cannot be converted (each said as an error already).
struct Planned {
    outputs: Outputs,
    files: Vec<specconv_farm::manifest::File>,
    asset: Option<AssetJob>,
    unplanned: usize,
}

fn submit(s: Submit, ocio: Option<String>) -> Result<i32> {
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
fn submit_job(s: &Submit, mut manifest: Manifest, job_dir: &Path) -> Result<i32> {
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
fn plan_files(s: &Submit) -> Result<Planned> {
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
fn stage_input(args: &convert::Args) -> Result<Option<&Path>> {
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
fn plan_stage(s: &Submit, stage: &Path, given: &Options, ocio: &str) -> Result<Planned> {
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

/// A stage's job: the layer over the stage ([`specconv_asset::farm_layer`]); false when none
/// was written (a stage changed since submit, a manifest edited), said as an error.
fn write_layer(m: &Manifest, job_dir: &Path, status: &Status) -> Result<bool> {
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
            errln!("specconv: {}", layer.summary());
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

/// The OCIO config a command checked, as every task must name it: a file by its absolute path
/// (`--ocio FILE` or `$OCIO`), a built-in config by the name that picked it.
fn pinned(config: &specconv_conversion::ColourConfig) -> Result<String> {
    use specconv_conversion::ConfigOrigin;
    let path = match config.origin() {
        ConfigOrigin::Builtin(name) => return Ok(name),
        ConfigOrigin::File(p) | ConfigOrigin::Env(p) => absolute(&p)?,
    };
    path.to_str().map(str::to_string).ok_or_else(|| {
        usage(anyhow!(
            "the OCIO config {} has a name that is not UTF-8, which a task's command line cannot carry; rename it",
            path.display()
        ))
    })
}

/// A farm error for the CLI: a refused job directory or request is a usage error (exit 2).
fn farm_error(e: specconv_farm::Error) -> anyhow::Error {
    if e.refused() {
        usage(e)
    } else {
        e.into()
    }
}

fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).with_context(|| format!("cannot resolve {}", p.display()))
}

/// The manifest's files: absolute paths (tasks may start elsewhere) and pixel counts.
fn listed_files(pairs: &[Pair]) -> Result<Vec<specconv_farm::manifest::File>> {
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
fn job_dir_for(s: &Submit) -> Result<PathBuf> {
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
fn print_plan(manifest: &Manifest, prepared: &specconv_farm::Prepared) -> Result<()> {
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

fn announce(
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

fn wait_and_collect(job_dir: &Path, job_id: &str, json: bool) -> Result<i32> {
    specconv_farm::wait(job_id)?;
    collect(&Report {
        job_dir: job_dir.to_path_buf(),
        json,
    })
}

/// `800M`, `4G`, `4000` (MiB, as sbatch reads it) → MiB.
fn parse_mem(s: &str) -> Option<u64> {
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

fn load(job_dir: &Path) -> Result<(Manifest, Status)> {
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
fn all_done(status: &Status) -> i32 {
    if status.files.iter().all(|f| f.state == FileState::Done) {
        exit::OK
    } else {
        exit::FAILED
    }
}

fn status(r: &Report) -> Result<i32> {
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
    let s = status.summary();
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

fn collect(r: &Report) -> Result<i32> {
    let (m, status) = load(&r.job_dir)?;
    let s = status.summary();
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
fn collected(m: &Manifest, job_dir: &Path, status: &Status) -> Result<i32> {
    let running = status.summary().running;
    let layer = running || write_layer(m, &std::path::absolute(job_dir)?, status)?;
    Ok(if layer {
        all_done(status)
    } else {
        exit::FAILED
    })
}

fn retry(r: &Retry, ocio: Option<String>) -> Result<i32> {
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

/// `1 file`, `2 files`.
fn count(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn memory_sizes_read_as_sbatch_reads_them() {
        assert_eq!(parse_mem("800M"), Some(800));
        assert_eq!(parse_mem("4G"), Some(4096));
        assert_eq!(parse_mem("1500"), Some(1500));
        assert_eq!(parse_mem("2048k"), Some(2));
        assert_eq!(parse_mem("lots"), None);
        assert_eq!(parse_mem("0"), None);
    }

    /// What submit records is what a task converts with: every option given, by the
    /// library's names, and nothing the farm sets itself.
    #[test]
    fn a_task_converts_with_the_options_given_to_submit_and_nothing_else() {
        let cli = crate::command_line::Cli::try_parse_from([
            "specconv",
            "farm",
            "submit",
            "a.png",
            "-o",
            "out",
            "--tasks",
            "2",
            "--method",
            "smits1999",
            "--tile",
            "32",
            "32",
            "--unbounded",
            "-j",
            "3",
            "--force",
            "--json",
            "--opaque-detect=false",
            "--constant-color-detect",
            "--fixnan",
            "box3",
        ])
        .unwrap();
        let Some(crate::command_line::Command::Farm(Args {
            command: Farm::Submit(s),
        })) = cli.command
        else {
            panic!("farm submit")
        };
        let given = s.convert.options();
        let recorded = recorded_options(&given);
        let names: Vec<&str> = recorded.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            ["bounded", "method", "non_finite", "opaque_detect", "tile"]
        );
        let m = specconv_farm::Manifest {
            options: recorded,
            ..example_manifest()
        };
        let task = task_options(&m, Path::new("/job")).unwrap();
        for key in Key::ALL {
            match key {
                Key::Ocio => assert_eq!(task.ocio.as_deref(), Some("aces")),
                Key::Threads => assert_eq!(task.threads, Some(1)),
                Key::Overwrite => assert!(!task.overwrite, "a task never replaces"),
                _ => assert_eq!(task.text(key), given.text(key), "{key:?}"),
            }
        }
        // A tampered manifest's unknown option is refused, naming it.
        let mut bad = m.clone();
        bad.options.insert("threads".into(), "9".into());
        let e = task_options(&bad, Path::new("/job"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"threads\""), "{e}");
    }

    fn example_manifest() -> specconv_farm::Manifest {
        specconv_farm::Manifest {
            format: specconv_farm::manifest::FORMAT,
            specconv: "/bin/specconv".into(),
            workdir: "/work".into(),
            ocio: "aces".into(),
            outputs: Outputs::Directory("/out".into()),
            options: BTreeMap::new(),
            files: Vec::new(),
            request: Request {
                partition: None,
                time: None,
                cpus_per_task: 1,
                mem_mib: 100,
                limit: None,
            },
            rounds: Vec::new(),
            asset: None,
        }
    }
}
