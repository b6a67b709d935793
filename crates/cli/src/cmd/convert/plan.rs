//! Inputs and their outputs, from the command line's paths.

use super::Args;
use crate::{checks, files};
use anyhow::{bail, Context, Result};
use std::io::BufRead;
use std::path::{Path, PathBuf};

/// Inputs and their outputs, from the positional paths, `-o DIR` or `--output-template`.
pub(crate) fn plan(args: &Args) -> Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    let mut paths = args.paths.clone();
    let single = args.output.is_none() && args.output_template.is_none();
    let explicit_output = if single {
        if paths.len() != 2 {
            bail!(
                "give INPUT OUTPUT, or several inputs with -o DIR or --output-template (got {} path{})",
                paths.len(),
                if paths.len() == 1 { "" } else { "s" }
            );
        }
        paths.pop()
    } else {
        None
    };
    let mut inputs = Vec::new();
    for p in paths {
        if p.as_os_str() == "-" {
            for line in std::io::stdin().lock().lines() {
                let line = line.context("cannot read input paths from standard input")?;
                if !line.trim().is_empty() {
                    inputs.push(PathBuf::from(line.trim_end()));
                }
            }
        } else {
            inputs.push(p);
        }
    }
    let outputs: Vec<PathBuf> = match (&explicit_output, &args.output, &args.output_template) {
        (Some(o), _, _) => vec![o.clone()],
        (None, Some(dir), _) => {
            checks::directory(dir)?;
            inputs
                .iter()
                .map(|i| dir.join(format!("{}_spectral.exr", stem(i))))
                .collect()
        }
        (None, None, Some(t)) => inputs
            .iter()
            .map(|i| {
                let dir = i
                    .parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .unwrap_or(Path::new("."));
                PathBuf::from(
                    t.replace("{dir}", &dir.display().to_string())
                        .replace("{stem}", &stem(i))
                        .replace(
                            "{name}",
                            &i.file_name()
                                .map(|n| n.to_string_lossy().into_owned())
                                .unwrap_or_default(),
                        ),
                )
            })
            .collect(),
        (None, None, None) => unreachable!("single conversions have an explicit output"),
    };
    for o in &outputs {
        files::check_output(o, &["exr"], "specconv writes spectral OpenEXR")?;
    }
    // The library's rules, on the whole plan before any shard is taken: every run of a
    // farm job refuses the same plan.
    let pairs: Vec<(PathBuf, PathBuf)> = inputs
        .iter()
        .cloned()
        .zip(outputs.iter().cloned())
        .collect();
    specconv_conversion::check_plan(&pairs, args.force, args.update)
        .map_err(|e| anyhow::anyhow!(crate::explain(&e)))?;
    Ok((inputs, outputs))
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "output".into(), |s| s.to_string_lossy().into_owned())
}
