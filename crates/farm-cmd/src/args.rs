//! The farm command's arguments: `submit` takes every option of `convert`; `status`, `collect`
//! and `retry` a job directory; `task` is what the job's script runs.

use specconv_flags::defs;
use std::path::PathBuf;

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
    pub(crate) command: Farm,
}

#[derive(Debug, clap::Subcommand)]
pub(crate) enum Farm {
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

specconv_flags::args! {
    /// Submit a job array converting INPUT… (or `-`: paths on standard input) into -o DIR.
    ///
    /// Takes every option of `convert`; -j comes from --cpus-per-task, and tasks always skip
    /// outputs that are up to date (-u). The inputs are split into --tasks shards of nearly equal
    /// pixel count, the same plan as `convert --shard`. A USD stage (.usd, .usda, .usdc, .usdz,
    /// given alone) is submitted as `specconv asset` converts it: each texture decided here by its
    /// material and converted by the tasks in that colour space, outputs below DIR; `farm collect`
    /// writes the layer DIR/STEM_spectral.usda (docs/farm.md).
    #[derive(Debug)]
    pub(crate) struct Submit {
        pub(crate) convert: specconv_convert_cmd::convert::Args = flatten,
        pub(crate) tasks: u32 = (defs::FARM_SUBMIT_TASKS),
        pub(crate) max_running: Option<u32> = (defs::FARM_SUBMIT_MAX_RUNNING),
        pub(crate) job_dir: Option<PathBuf> = (defs::FARM_SUBMIT_JOB_DIR),
        pub(crate) partition: Option<String> = (defs::FARM_SUBMIT_PARTITION),
        pub(crate) time: Option<String> = (defs::FARM_SUBMIT_TIME),
        pub(crate) cpus_per_task: u32 = (defs::FARM_SUBMIT_CPUS_PER_TASK),
        pub(crate) mem: Option<String> = (defs::FARM_SUBMIT_MEM),
        pub(crate) wait: bool = (defs::FARM_WAIT),
        pub(crate) dry_run: bool = (defs::FARM_SUBMIT_DRY_RUN),
    }
}

specconv_flags::args! {
    #[derive(Debug)]
    pub(crate) struct Report {
        pub(crate) job_dir: PathBuf = (defs::FARM_JOB_DIR),
        pub(crate) json: bool = (defs::FARM_JSON),
    }
}

specconv_flags::args! {
    #[derive(Debug)]
    pub(crate) struct Retry {
        pub(crate) job_dir: PathBuf = (defs::FARM_JOB_DIR),
        pub(crate) tasks: Option<u32> = (defs::FARM_RETRY_TASKS),
        pub(crate) wait: bool = (defs::FARM_WAIT),
    }
}

specconv_flags::args! {
    /// `farm task JOBDIR --round R --task T`, the command line
    /// `specconv_farm::manifest::task_command` makes for the job's script.
    #[derive(Debug)]
    pub(crate) struct Task {
        pub(crate) job_dir: PathBuf = (defs::FARM_TASK_JOB_DIR),
        pub(crate) round: usize = (defs::FARM_TASK_ROUND),
        pub(crate) task: usize = (defs::FARM_TASK_TASK),
    }
}
