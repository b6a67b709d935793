//! A job's files checked before its first write: no output any input, no two outputs one file, no existing output replaced unless allowed, every output's
//! directory there. Files are compared as files: an existing file by device and inode, an
//! output that does not exist yet by its directory's device and inode and its name, so links,
//! `..`, bind mounts and other aliases of a directory are seen through.

use crate::kind::Kind;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Whether existing outputs may be replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Replace {
    /// An existing output is an error.
    Never,
    /// Existing outputs are replaced (`--force`), or replaced when out of date (`-u`).
    Allowed,
}

/// Why a job may not start; nothing has been read or written.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// An output that is one of the inputs.
    #[error("the output {} is the input {}; choose another output path", output.display(), input.display())]
    OutputIsInput {
        /// The output.
        output: PathBuf,
        /// The input it is.
        input: PathBuf,
    },
    /// Two outputs that are one file.
    #[error("{} and {} are one output file, which two inputs would write; give each its own output", first.display(), second.display())]
    SharedOutput {
        /// The first output.
        first: PathBuf,
        /// The second, the same file.
        second: PathBuf,
    },
    /// Existing outputs that may not be replaced.
    #[error("{} exists{}", output.display(), if *more > 0 { format!(" (and {more} more output{})", if *more == 1 { "" } else { "s" }) } else { String::new() })]
    Exists {
        /// The first existing output.
        output: PathBuf,
        /// How many more exist.
        more: usize,
    },
    /// An output that exists and is not a regular file.
    #[error("the output {} is {kind}; give a file path", output.display())]
    OutputNotAFile {
        /// The output.
        output: PathBuf,
        /// What it is.
        kind: Kind,
    },
    /// An output whose directory does not exist (outputs are never given new directories).
    #[error("the output directory {} does not exist; create it first", dir.display())]
    NoDirectory {
        /// The directory.
        dir: PathBuf,
    },
    /// An output name longer than a file name may be.
    #[error("the output name {} is {length} bytes; file names have at most 255", output.display())]
    NameTooLong {
        /// The output.
        output: PathBuf,
        /// Its name's length in bytes.
        length: usize,
    },
}

/// Where a path's directory entry is: its directory as a file, and its name.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Place {
    directory: (u64, u64),
    name: OsString,
}

impl Place {
    /// The place of `path`; `None` when its directory does not exist.
    pub fn of(path: &Path) -> Option<Place> {
        use std::os::unix::fs::MetadataExt;
        let name = path.file_name()?.to_os_string();
        let d = std::fs::metadata(crate::names::directory_of(path)).ok()?;
        Some(Place {
            directory: (d.dev(), d.ino()),
            name,
        })
    }
}

/// Checks a job that reads `inputs` and writes `outputs`; the first problem found, in the
/// order output names, directories and kinds, identities, existing outputs. Inputs that are
/// missing or not files are each input's own failure ([`crate::readable_file`]), found when
/// it is read.
pub fn check(inputs: &[&Path], outputs: &[&Path], replace: Replace) -> Result<(), PlanError> {
    let mut places = Vec::with_capacity(outputs.len());
    for output in outputs {
        places.push(output_place(output)?);
    }
    let input_places: Vec<Option<Place>> = inputs.iter().map(|i| Place::of(i)).collect();
    for (output, place) in outputs.iter().zip(&places) {
        if let Some(i) = inputs.iter().zip(&input_places).find_map(|(input, p)| {
            (p.as_ref() == Some(place) || crate::same_file(output, input)).then_some(input)
        }) {
            return Err(PlanError::OutputIsInput {
                output: output.to_path_buf(),
                input: i.to_path_buf(),
            });
        }
    }
    let mut seen = std::collections::HashMap::new();
    for (output, place) in outputs.iter().zip(places) {
        if let Some(first) = seen.insert(place, *output) {
            return Err(PlanError::SharedOutput {
                first: first.to_path_buf(),
                second: output.to_path_buf(),
            });
        }
    }
    if replace == Replace::Never {
        let existing: Vec<&&Path> = outputs
            .iter()
            .filter(|o| std::fs::symlink_metadata(o).is_ok())
            .collect();
        if let Some(first) = existing.first() {
            return Err(PlanError::Exists {
                output: first.to_path_buf(),
                more: existing.len() - 1,
            });
        }
    }
    Ok(())
}

/// An output's place, once its name, directory and kind allow writing it.
fn output_place(output: &Path) -> Result<Place, PlanError> {
    use std::os::unix::ffi::OsStrExt;
    let length = output.file_name().map_or(0, |n| n.as_bytes().len());
    if length > 255 {
        return Err(PlanError::NameTooLong {
            output: output.to_path_buf(),
            length,
        });
    }
    match Kind::of(output) {
        Kind::File | Kind::Missing => {}
        kind => {
            return Err(PlanError::OutputNotAFile {
                output: output.to_path_buf(),
                kind,
            })
        }
    }
    Place::of(output).ok_or_else(|| PlanError::NoDirectory {
        dir: crate::names::directory_of(output).to_path_buf(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aliases_of_an_input_or_of_another_output_are_refused() {
        let d = crate::tests::scratch("plan");
        std::fs::create_dir_all(d.join("a")).unwrap();
        std::fs::create_dir_all(d.join("o2")).unwrap();
        std::os::unix::fs::symlink(d.join("a"), d.join("alias")).unwrap();
        let x = d.join("a/x.png");
        std::fs::write(&x, b"png").unwrap();
        let y = d.join("a/y.png");
        std::fs::write(&y, b"png").unwrap();
        let never = Replace::Never;
        // An output that is an input under another name, existing or through a directory link.
        for alias in ["alias/x.png", "a/../a/x.png"] {
            let e = check(&[&x], &[&d.join(alias)], Replace::Allowed).unwrap_err();
            assert!(matches!(e, PlanError::OutputIsInput { .. }), "{alias}: {e}");
        }
        // Two inputs mapped by a template to one file not yet there.
        let (o1, o2) = (d.join("a/../o2/x.exr"), d.join("alias/../o2/x.exr"));
        let e = check(&[&x, &y], &[&o1, &o2], never).unwrap_err();
        assert!(matches!(e, PlanError::SharedOutput { .. }), "{e}");
        // An input named like another input's output, before and after that output exists.
        let later = d.join("a/x_spectral.exr");
        let e = check(
            &[&x, &later],
            &[&later, &d.join("o2/z.exr")],
            Replace::Allowed,
        )
        .unwrap_err();
        assert!(matches!(e, PlanError::OutputIsInput { .. }), "{e}");
        std::fs::write(&later, b"exr").unwrap();
        let e = check(
            &[&x, &later],
            &[&later, &d.join("o2/z.exr")],
            Replace::Allowed,
        )
        .unwrap_err();
        assert!(matches!(e, PlanError::OutputIsInput { .. }), "{e}");
        assert!(check(
            &[&x, &y],
            &[&d.join("o2/x.exr"), &d.join("o2/y.exr")],
            never
        )
        .is_ok());
        std::fs::remove_dir_all(d).unwrap();
    }

    #[test]
    fn existing_outputs_special_files_and_missing_directories_are_named() {
        let d = crate::tests::scratch("plan-exists");
        let x = d.join("x.png");
        std::fs::write(&x, b"png").unwrap();
        for o in ["o1.exr", "o2.exr"] {
            std::fs::write(d.join(o), b"exr").unwrap();
        }
        let outs = [d.join("o1.exr"), d.join("o2.exr")];
        let e = check(&[&x, &x], &[&outs[0], &outs[1]], Replace::Never).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{} exists (and 1 more output)", outs[0].display())
        );
        assert!(check(&[&x, &x], &[&outs[0], &outs[1]], Replace::Allowed).is_ok());
        let e = check(&[&x], &[Path::new("/dev/null")], Replace::Allowed).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the output /dev/null is a character device; give a file path"
        );
        let e = check(&[&x], &[&d], Replace::Allowed).unwrap_err();
        assert!(
            matches!(
                e,
                PlanError::OutputNotAFile {
                    kind: Kind::Directory,
                    ..
                }
            ),
            "{e}"
        );
        let e = check(&[&x], &[&d.join("none/o.exr")], Replace::Never).unwrap_err();
        assert!(matches!(e, PlanError::NoDirectory { .. }), "{e}");
        let long = d.join("n".repeat(256));
        assert!(matches!(
            check(&[&x], &[&long], Replace::Never),
            Err(PlanError::NameTooLong { length: 256, .. })
        ));
        std::fs::remove_dir_all(d).unwrap();
    }
}
