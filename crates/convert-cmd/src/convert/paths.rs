//! Inputs and their outputs, from the command line's paths: the arguments, and the list on
//! standard input, handed to the library's plan ([`specconv_conversion::plan`]), which owns
//! every rule (output names, UDIM patterns, identities, shards, existing outputs).

use super::Args;
use anyhow::{bail, Context, Result};
use specconv_conversion::plan::{self, Outputs, Pair, Plan};
use std::path::PathBuf;

/// The whole plan of the command line's inputs and outputs: the positional paths (`-` reads
/// a list on standard input), into the explicit output, `-o DIR` or `--output-template`.
fn whole(args: &Args) -> Result<Plan> {
    of_paths(
        &args.paths,
        args.output.as_deref(),
        args.output_template.as_deref(),
    )
}

/// The plan of a batch command's positional `paths` (inputs, then the output of one input;
/// `-` reads a list on standard input) into the explicit output, the directory `output` or
/// the `template`: `convert`'s, and `expand`'s.
pub fn of_paths(
    paths: &[PathBuf],
    output: Option<&std::path::Path>,
    template: Option<&str>,
) -> Result<Plan> {
    // A template that cannot name outputs is refused before any input is looked at.
    let template = template
        .map(Outputs::template)
        .transpose()
        .map_err(planned)?;
    let mut paths = paths.to_vec();
    let single = output.is_none() && template.is_none();
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
            inputs.extend(read_list(std::io::stdin().lock())?);
        } else {
            inputs.push(p);
        }
    }
    let outputs = match (explicit_output, output, template) {
        (Some(o), _, _) => Outputs::Files(vec![o]),
        (None, Some(dir), _) => Outputs::Directory(dir.to_path_buf()),
        (None, None, Some(t)) => t,
        (None, None, None) => unreachable!("single conversions have an explicit output"),
    };
    // `-o DIR` makes DIR, as `asset -o` does (the library's rule).
    Plan::new_making_directory(inputs, &outputs).map_err(planned)
}

/// The pairs this run converts: the whole plan, or `--shard`'s part of it, once no output of
/// theirs exists that may not be replaced (`--force`, `-u`). Outputs of other shards are never
/// looked at, so shards run side by side in any order.
pub(crate) fn this_run(args: &Args) -> Result<Vec<Pair>> {
    let mut plan = whole(args)?;
    if let Some(shard) = args.shard {
        let index = crate::shard::index(shard)?;
        plan = plan.shard(index, shard.count).map_err(planned)?;
    }
    plan.check_existing(args.conversion.options.overwrite, args.batch.update)
        .map_err(planned)?;
    Ok(plan.into_pairs())
}

/// The whole plan for `farm submit`, whose tasks all convert with `-u`: every output checked.
pub fn for_farm(args: &Args) -> Result<Plan> {
    let plan = whole(args)?;
    plan.check_existing(args.conversion.options.overwrite, true)
        .map_err(planned)?;
    Ok(plan)
}

/// A plan's error as a library error, so that the command line's hint (`--force`) follows it.
pub fn planned(e: plan::Error) -> anyhow::Error {
    anyhow::anyhow!(crate::errors::explain(&specconv_conversion::Error::from(e)))
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
