//! `farm task`: one array task's work, the job's options read from its manifest.

use crate::args::Task;
use crate::job::{absolute, farm_error, SET_BY_THE_FARM};
use anyhow::{anyhow, Context, Result};
use specconv_conversion::plan::Pair;
use specconv_conversion::{Key, Options};
use specconv_convert_cmd::convert;
use specconv_convert_cmd::errors::usage;
use specconv_farm::Manifest;
use std::path::Path;

/// The options a task converts with: the manifest's, with the farm's own.
pub(crate) fn task_options(m: &Manifest, job_dir: &Path) -> Result<Options> {
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
pub(crate) fn task(t: &Task) -> Result<i32> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::{Args, Farm};
    use crate::job::recorded_options;
    use specconv_farm::manifest::Outputs;
    use specconv_farm::Request;
    use std::collections::BTreeMap;

    /// What submit records is what a task converts with: every option given, by the
    /// library's names, and nothing the farm sets itself.
    #[test]
    fn a_task_converts_with_the_options_given_to_submit_and_nothing_else() {
        use clap::{Args as _, FromArgMatches};
        let matches = Args::augment_args(clap::Command::new("farm"))
            .try_get_matches_from([
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
        let Farm::Submit(s) = Args::from_arg_matches(&matches).unwrap().command else {
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
