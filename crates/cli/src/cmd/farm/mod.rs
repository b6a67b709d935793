//! `specconv farm submit|status|collect|retry`: a texture library on a Slurm job array. The
//! plans, the job directory and the reading of logs and Slurm live in the farm crate; here the
//! inputs are measured, the convert options passed on, and the results reported.

use crate::cmd::convert;
use crate::errors::usage;
use anyhow::{anyhow, Context, Result};
use specconv_conversion::{Key, Options};
use specconv_flags::defs;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod reports;
mod submit;
mod task;

use reports::{collect, retry, status};
use submit::submit;
use task::task;

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
    struct Submit {
        convert: convert::Args = flatten,
        tasks: u32 = (defs::FARM_SUBMIT_TASKS),
        max_running: Option<u32> = (defs::FARM_SUBMIT_MAX_RUNNING),
        job_dir: Option<PathBuf> = (defs::FARM_SUBMIT_JOB_DIR),
        partition: Option<String> = (defs::FARM_SUBMIT_PARTITION),
        time: Option<String> = (defs::FARM_SUBMIT_TIME),
        cpus_per_task: u32 = (defs::FARM_SUBMIT_CPUS_PER_TASK),
        mem: Option<String> = (defs::FARM_SUBMIT_MEM),
        wait: bool = (defs::FARM_WAIT),
        dry_run: bool = (defs::FARM_SUBMIT_DRY_RUN),
    }
}

specconv_flags::args! {
    #[derive(Debug)]
    struct Report {
        job_dir: PathBuf = (defs::FARM_JOB_DIR),
        json: bool = (defs::FARM_JSON),
    }
}

specconv_flags::args! {
    #[derive(Debug)]
    struct Retry {
        job_dir: PathBuf = (defs::FARM_JOB_DIR),
        tasks: Option<u32> = (defs::FARM_RETRY_TASKS),
        wait: bool = (defs::FARM_WAIT),
    }
}

specconv_flags::args! {
    /// `farm task JOBDIR --round R --task T`, the command line
    /// `specconv_farm::manifest::task_command` makes for the job's script.
    #[derive(Debug)]
    struct Task {
        job_dir: PathBuf = (defs::FARM_TASK_JOB_DIR),
        round: usize = (defs::FARM_TASK_ROUND),
        task: usize = (defs::FARM_TASK_TASK),
    }
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

/// `1 file`, `2 files`.
fn count(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

#[cfg(test)]
mod tests {
    use super::submit::parse_mem;
    use super::task::task_options;
    use super::*;
    use clap::Parser;
    use specconv_farm::manifest::Outputs;
    use specconv_farm::Request;

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
