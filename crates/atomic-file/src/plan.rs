//! A job's files checked before its first write: no output any input, no two outputs one file, no existing output replaced unless allowed, every output's
//! directory there. Files are compared as files: an existing file by device and inode, an
//! output that does not exist yet by its directory's device and inode and its name, so links,
//! `..`, bind mounts and other aliases of a directory are seen through.
//!
//! Every check is linear in the number of files: identities go into hash maps, and each
//! directory is looked at once ([`Places`]). Each output is looked at once (its kind and the
//! file there, [`Target`]); inputs are looked at only when some output exists, as only an
//! existing output can be an input by being the same file. A job of 100,000 inputs into a
//! fresh folder is checked in one `lstat` per output.

use crate::kind::Kind;
use std::collections::HashMap;
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

impl Replace {
    /// `Allowed` when overwriting was asked for, else `Never`: the one reading of every
    /// front-end's overwrite setting (`--force`, `overwrite=True`).
    pub fn when(overwrite: bool) -> Replace {
        if overwrite {
            Replace::Allowed
        } else {
            Replace::Never
        }
    }
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
    /// An output whose name does not end in an extension of what is written (or is `-`).
    #[error(
        "{}: {what}; give an output file ending in {}",
        if output.as_os_str() == "-" {
            "'-' is not a file (nothing is written to standard output)".to_string()
        } else {
            format!("the output {} has the wrong extension", output.display())
        },
        extensions.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" or ")
    )]
    WrongExtension {
        /// The output.
        output: PathBuf,
        /// The extensions allowed (without the dot).
        extensions: &'static [&'static str],
        /// What is written, e.g. "a model file is JSON".
        what: &'static str,
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

/// Whether `path` ends in one of `extensions` (without the dot; ASCII case ignored): the one
/// test of an output's name by what is written in it.
pub fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// Refuses an output whose name does not end in one of `extensions` ([`has_extension`]) or is
/// `-`; `what` says what is written ("a model file is JSON"). A texture is never replaced by a
/// file of another kind because its name was given by mistake.
pub fn check_extension(
    output: &Path,
    extensions: &'static [&'static str],
    what: &'static str,
) -> Result<(), PlanError> {
    if output.as_os_str() != "-" && has_extension(output, extensions) {
        return Ok(());
    }
    Err(PlanError::WrongExtension {
        output: output.to_path_buf(),
        extensions,
        what,
    })
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
        Places::default().of(path)
    }
}

/// Places of many paths, each directory looked at once: paths of one folder cost one `stat`
/// of it in all, not one each.
#[derive(Debug, Default)]
pub struct Places {
    directories: HashMap<PathBuf, Option<(u64, u64)>>,
}

impl Places {
    /// The place of `path` ([`Place::of`]).
    pub fn of(&mut self, path: &Path) -> Option<Place> {
        use std::os::unix::fs::MetadataExt;
        let name = path.file_name()?.to_os_string();
        let dir = crate::names::directory_of(path);
        let directory = match self.directories.get(dir) {
            Some(known) => *known,
            None => {
                let id = std::fs::metadata(dir).ok().map(|d| (d.dev(), d.ino()));
                self.directories.insert(dir.to_path_buf(), id);
                id
            }
        }?;
        Some(Place { directory, name })
    }
}

/// A file as the file system knows it (device and inode, through links); `None` when nothing
/// is there.
fn file_id(path: &Path) -> Option<(u64, u64)> {
    Kind::with_id(path).1
}

/// An output as a plan sees it: its place, the file already there (device and inode,
/// through links), if any, and whether anything is at its name (a link that leads nowhere
/// included). Made by [`output_places`], from one `lstat` of the output (and a `stat` through
/// a link).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Target {
    place: Place,
    existing: Option<(u64, u64)>,
    taken: bool,
}

impl Target {
    /// Whether something is at the output's name, as `lstat` saw it when the plan was made:
    /// what an output that may not be replaced is refused for.
    pub fn is_taken(&self) -> bool {
        self.taken
    }
}

/// Checks a job that reads `inputs` and writes `outputs`; the first problem found, in the
/// order output names, directories and kinds, identities, existing outputs. Inputs that are
/// missing or not files are each input's own failure ([`crate::readable_file`]), found when
/// it is read.
pub fn check(inputs: &[&Path], outputs: &[&Path], replace: Replace) -> Result<(), PlanError> {
    let mut known = Places::default();
    let places = output_places(outputs, &mut known)?;
    if let Some((o, i)) = output_is_input(inputs, &places, &mut known) {
        return Err(PlanError::OutputIsInput {
            output: outputs[o].to_path_buf(),
            input: inputs[i].to_path_buf(),
        });
    }
    if let Some((first, second)) = shared_output(&places) {
        return Err(PlanError::SharedOutput {
            first: outputs[first].to_path_buf(),
            second: outputs[second].to_path_buf(),
        });
    }
    if replace == Replace::Never {
        let existing: Vec<&&Path> = outputs
            .iter()
            .zip(&places)
            .filter_map(|(o, t)| t.taken.then_some(o))
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

/// Every output as a [`Target`], once its name, directory and kind allow writing it; the first
/// output that does not is the error.
pub fn output_places(outputs: &[&Path], known: &mut Places) -> Result<Vec<Target>, PlanError> {
    outputs.iter().map(|o| output_place(o, known)).collect()
}

/// The first output (by position) that is one of the inputs, as files: its position and that
/// of the first input it is. `targets` are the outputs' ([`output_places`]). An output is an
/// input when it is at the input's place (the same directory entry, whether or not it exists
/// yet) or is the same existing file (a hard or symbolic link to it). Inputs are `stat`ed
/// only when some output exists: a missing output is no file an input could be.
pub fn output_is_input(
    inputs: &[&Path],
    targets: &[Target],
    known: &mut Places,
) -> Option<(usize, usize)> {
    let mut by_place: HashMap<Place, usize> = HashMap::with_capacity(inputs.len());
    for (k, input) in inputs.iter().enumerate() {
        if let Some(p) = known.of(input) {
            by_place.entry(p).or_insert(k);
        }
    }
    let mut by_file: HashMap<(u64, u64), usize> = HashMap::new();
    if targets.iter().any(|t| t.existing.is_some()) {
        by_file.reserve(inputs.len());
        for (k, input) in inputs.iter().enumerate() {
            if let Some(f) = file_id(input) {
                by_file.entry(f).or_insert(k);
            }
        }
    }
    targets.iter().enumerate().find_map(|(o, target)| {
        let at = by_place.get(&target.place).copied();
        let same = target.existing.and_then(|f| by_file.get(&f).copied());
        at.into_iter().chain(same).min().map(|i| (o, i))
    })
}

/// The first two outputs (by the second's position) that are one file, by their places
/// ([`output_places`]).
pub fn shared_output(targets: &[Target]) -> Option<(usize, usize)> {
    let mut seen: HashMap<&Place, usize> = HashMap::with_capacity(targets.len());
    targets
        .iter()
        .enumerate()
        .find_map(|(k, target)| seen.insert(&target.place, k).map(|first| (first, k)))
}

/// The first folder between `dir` (itself not counted: where a user's folder lives is theirs
/// to choose) and `output`'s own folder that is a symbolic link, as a path: a link there would
/// take an output, and the folders made for it, out of the tree below `dir`. Folders not made
/// yet are no links; `output` must lie lexically below `dir` (else it is its own first link:
/// nothing below `dir` can be checked).
pub fn link_below(dir: &Path, output: &Path) -> Option<PathBuf> {
    let Ok(rest) = output.strip_prefix(dir) else {
        return Some(output.to_path_buf());
    };
    let mut folder = dir.to_path_buf();
    let parents = rest.parent().into_iter().flat_map(Path::components);
    for part in parents {
        folder.push(part);
        match std::fs::symlink_metadata(&folder) {
            Ok(m) if m.file_type().is_symlink() => return Some(folder),
            Ok(_) => {}
            Err(_) => return None,
        }
    }
    None
}

/// An output's [`Target`], once its name, directory and kind allow writing it: one `lstat` of
/// the output (its kind, its file and whether its name is taken; a `stat` more through a
/// link), and one `stat` of its directory the first time that is seen.
fn output_place(output: &Path, known: &mut Places) -> Result<Target, PlanError> {
    use std::os::unix::ffi::OsStrExt;
    let length = output.file_name().map_or(0, |n| n.as_bytes().len());
    if length > 255 {
        return Err(PlanError::NameTooLong {
            output: output.to_path_buf(),
            length,
        });
    }
    let (kind, existing, taken) = Kind::at_name(output);
    match kind {
        Kind::File | Kind::Missing => {}
        kind => {
            return Err(PlanError::OutputNotAFile {
                output: output.to_path_buf(),
                kind,
            })
        }
    }
    let place = known.of(output).ok_or_else(|| PlanError::NoDirectory {
        dir: crate::names::directory_of(output).to_path_buf(),
    })?;
    Ok(Target {
        place,
        existing,
        taken,
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
    fn a_link_below_an_output_folder_is_found_and_the_folder_itself_is_not_counted() {
        let d = crate::tests::scratch("plan-links");
        let out = d.join("out");
        std::fs::create_dir_all(out.join("tex/deep")).unwrap();
        std::fs::create_dir_all(d.join("elsewhere")).unwrap();
        std::os::unix::fs::symlink(d.join("elsewhere"), out.join("tex/away")).unwrap();
        std::os::unix::fs::symlink(&out, d.join("out-link")).unwrap();
        assert_eq!(link_below(&out, &out.join("tex/deep/a.exr")), None);
        assert_eq!(link_below(&out, &out.join("tex/new/more/a.exr")), None);
        assert_eq!(
            link_below(&out, &out.join("tex/away/a.exr")),
            Some(out.join("tex/away"))
        );
        assert_eq!(
            link_below(&out, &out.join("tex/away/not-yet/a.exr")),
            Some(out.join("tex/away"))
        );
        // The output folder given through a link is the user's choice; an output that is
        // itself a link is the plan's to judge ([`check`]), not a folder's.
        let linked = d.join("out-link");
        assert_eq!(link_below(&linked, &linked.join("tex/deep/a.exr")), None);
        std::os::unix::fs::symlink(d.join("x"), out.join("tex/deep/l.exr")).unwrap();
        assert_eq!(link_below(&out, &out.join("tex/deep/l.exr")), None);
        assert_eq!(
            link_below(&out, &d.join("other/a.exr")),
            Some(d.join("other/a.exr"))
        );
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
        // A link that leads nowhere takes its name: refused as existing, replaced when allowed.
        let dangling = d.join("dangling.exr");
        std::os::unix::fs::symlink(d.join("nowhere.exr"), &dangling).unwrap();
        let e = check(&[&x], &[&dangling], Replace::Never).unwrap_err();
        assert!(matches!(e, PlanError::Exists { more: 0, .. }), "{e}");
        assert!(check(&[&x], &[&dangling], Replace::Allowed).is_ok());
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
        for (name, ok) in [
            ("m.json", true),
            ("M.JSON", true),
            ("m.png", false),
            ("-", false),
        ] {
            let r = check_extension(&d.join(name), &["json"], "a model file is JSON");
            assert_eq!(r.is_ok(), ok, "{name}");
        }
        let e = check_extension(Path::new("t.png"), &["exr"], "spectral OpenEXR").unwrap_err();
        assert_eq!(
            e.to_string(),
            "the output t.png has the wrong extension: spectral OpenEXR; give an output file ending in .exr"
        );
        let long = d.join("n".repeat(256));
        assert!(matches!(
            check(&[&x], &[&long], Replace::Never),
            Err(PlanError::NameTooLong { length: 256, .. })
        ));
        std::fs::remove_dir_all(d).unwrap();
    }
}
