//! What the farm's subcommands share about a job: the options it records and the ones the farm
//! sets itself, its pinned OCIO config, its errors as the command line says them.

use anyhow::{anyhow, Context, Result};
use specconv_conversion::{Key, Options};
use specconv_convert_cmd::errors::usage;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options the farm sets itself: the config is the manifest's, threads are the task's CPUs,
/// and outputs are replaced only when out of date.
pub(crate) const SET_BY_THE_FARM: [Key; 3] = [Key::Ocio, Key::Threads, Key::Overwrite];

/// The options of a job, as the manifest records them: those that differ from the library's
/// defaults, by the library's names and text, but for what the farm sets itself.
pub(crate) fn recorded_options(options: &Options) -> BTreeMap<String, String> {
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
pub(crate) fn pinned(config: &specconv_conversion::ColourConfig) -> Result<String> {
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
pub(crate) fn farm_error(e: specconv_farm::Error) -> anyhow::Error {
    if e.refused() {
        usage(e)
    } else {
        e.into()
    }
}

pub(crate) fn absolute(p: &Path) -> Result<PathBuf> {
    std::path::absolute(p).with_context(|| format!("cannot resolve {}", p.display()))
}

/// `1 file`, `2 files`.
pub(crate) fn count(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}
