//! Inputs and their outputs, from the command line's paths.

use super::Args;
use crate::{checks, files};
use anyhow::{bail, Context, Result};
use specconv_atomic_file::{outputs, udim};
use std::path::PathBuf;

/// Inputs and their outputs, from the positional paths, `-o DIR` or `--output-template`, once
/// the library's rules allow the plan; `update` as the runs that will convert it (`-u`). UDIM
/// patterns (`wood.<UDIM>.png`) stand for the tiles that exist, in tile order.
pub(crate) fn plan(args: &Args, update: bool) -> Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    // A template that cannot name outputs is refused before any input is looked at.
    let template = args
        .output_template
        .as_deref()
        .map(outputs::Template::parse)
        .transpose()?;
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
    let mut listed = Vec::new();
    for p in paths {
        if p.as_os_str() == "-" {
            listed.extend(read_list(std::io::stdin().lock())?);
        } else {
            listed.push(p);
        }
    }
    let mut inputs = Vec::new();
    // The tile numbers of a single conversion's pattern, for an output named by one.
    let mut tiles = Vec::new();
    for p in listed {
        match udim::expand(&p)? {
            Some(found) => {
                tiles.extend(found.iter().map(|t| t.number));
                inputs.extend(found.into_iter().map(|t| t.path));
            }
            None => inputs.push(p),
        }
    }
    let outputs: Vec<PathBuf> = match (&explicit_output, &args.output, &template) {
        (Some(o), _, _) => single_outputs(o, &args.paths[0], &tiles)?,
        (None, Some(dir), _) => {
            checks::directory(dir)?;
            inputs
                .iter()
                .map(|i| outputs::in_directory(dir, i))
                .collect()
        }
        (None, None, Some(t)) => inputs
            .iter()
            .map(|i| t.apply(i))
            .collect::<Result<_, _>>()?,
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
    specconv_conversion::check_plan(&pairs, args.force, update)
        .map_err(|e| anyhow::anyhow!(crate::explain(&e)))?;
    Ok((inputs, outputs))
}

/// The output of `INPUT OUTPUT`: `output` itself, or for a UDIM pattern one per tile, named by
/// the same token in `output` (`wood.<UDIM>.png wood_spectral.<UDIM>.exr`).
fn single_outputs(
    output: &std::path::Path,
    input: &std::path::Path,
    tiles: &[u32],
) -> Result<Vec<PathBuf>> {
    match (udim::is_pattern(input), udim::is_pattern(output)) {
        (false, false) => Ok(vec![output.to_path_buf()]),
        (true, true) => Ok(tiles.iter().map(|&n| udim::substitute(output, n)).collect()),
        (true, false) => bail!(
            "{} is a UDIM pattern ({} tile{}): name the output with the token too (such as {}), \
             or use --output-template with {{udim}}",
            input.display(),
            tiles.len(),
            if tiles.len() == 1 { "" } else { "s" },
            output.with_extension("").display().to_string() + ".<UDIM>.exr"
        ),
        (false, true) => bail!(
            "the output {} has a UDIM token but the input {} is no UDIM pattern",
            output.display(),
            input.display()
        ),
    }
}

/// The most a list of inputs on standard input may hold (a million paths of 64 bytes).
const LIST_LIMIT: u64 = 64 << 20;
/// The longest path a line may hold (Linux's PATH_MAX).
const PATH_MAX: usize = 4096;

/// Input paths, one per line, as bytes (a name need not be UTF-8); blank lines skipped. A
/// list that never ends (`/dev/zero`, `yes`) is refused at the limit instead of filling memory.
fn read_list(from: impl std::io::Read) -> Result<Vec<PathBuf>> {
    use std::io::Read;
    use std::os::unix::ffi::OsStrExt;
    let mut bytes = Vec::new();
    from.take(LIST_LIMIT + 1)
        .read_to_end(&mut bytes)
        .context("cannot read input paths from standard input")?;
    if bytes.len() as u64 > LIST_LIMIT {
        bail!(
            "the list of inputs on standard input is over {} MiB; split it into several runs",
            LIST_LIMIT >> 20
        );
    }
    let mut paths = Vec::new();
    for line in bytes.split(|&b| b == b'\n') {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        if line.len() > PATH_MAX || line.contains(&0) {
            bail!(
                "standard input holds a line of {} bytes{} that is no path; give one input path per line",
                line.len(),
                if line.contains(&0) { " with a NUL byte" } else { "" }
            );
        }
        paths.push(PathBuf::from(std::ffi::OsStr::from_bytes(line)));
    }
    Ok(paths)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn a_list_is_read_as_bytes_and_an_endless_one_refused() {
        let list = read_list(&b"a.png\n\n  \nb\xff.png\r\n"[..]).unwrap();
        assert_eq!(list.len(), 2);
        assert_eq!(list[1].as_os_str().len(), 6, "the non-UTF-8 byte kept");
        let zeros = std::io::repeat(0).take(LIST_LIMIT + 10);
        let e = read_list(zeros).unwrap_err().to_string();
        assert!(e.contains("over 64 MiB"), "{e}");
        let e = read_list(&vec![0u8; 100][..]).unwrap_err().to_string();
        assert!(e.contains("NUL"), "{e}");
    }
}
