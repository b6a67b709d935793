//! Every file made from the project's definitions, in one list ([`made`]): what `--help` and
//! the library define is written into the docs, the man pages, the Python stub and the C
//! header, so that none of them is written by hand twice. A part of a hand-written file sits
//! between two marker lines (`BEGIN GENERATED: NAME` … `END GENERATED: NAME`, inside a comment
//! of the file's language); a made file or folder is written whole.

use std::path::{Path, PathBuf};

/// What one generator makes.
pub enum Made {
    /// The lines between a file's two marker lines.
    Part {
        /// The file, relative to the checkout.
        file: &'static str,
        /// The name its marker lines carry.
        name: &'static str,
        /// The lines between them.
        text: String,
    },
    /// A whole file.
    Whole {
        /// The file, relative to the checkout.
        file: &'static str,
        /// Its contents.
        bytes: Vec<u8>,
    },
    /// Every file of a folder with one extension: a file of it that is not made is stale.
    Folder {
        /// The folder, relative to the checkout.
        dir: &'static str,
        /// The extension its made files have (others are left alone).
        extension: &'static str,
        /// (file name, contents).
        files: Vec<(String, Vec<u8>)>,
    },
}

/// Everything made, from the command line's and the library's definitions.
pub fn made() -> Vec<Made> {
    use specconv_cli::generated;
    vec![
        Made::Part {
            file: "docs/guide.md",
            name: "convert's options",
            text: generated::guide_table(),
        },
        Made::Part {
            file: "README.md",
            name: "the options most used",
            text: generated::readme_table(),
        },
        Made::Whole {
            file: "docs/commands.md",
            bytes: generated::commands_page().into_bytes(),
        },
        Made::Part {
            file: "python/specconv/_specconv.pyi",
            name: "convert's keywords",
            text: generated::python_stub(),
        },
        Made::Part {
            file: "include/specconv_spectrum.h",
            name: "the library's constants",
            text: specconv_spectral::c_header::generated(),
        },
        Made::Folder {
            dir: "man",
            extension: "1",
            files: specconv_cli::man_pages(),
        },
    ]
}

/// The checkout this tool was built from.
pub fn checkout() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A file that is not what is made: its path and what it should hold (`None`: remove it).
#[derive(Debug, PartialEq)]
pub struct Change {
    /// The file.
    pub path: PathBuf,
    /// What it should hold; `None` when nothing makes it.
    pub contents: Option<Vec<u8>>,
}

/// The changes that would make the checkout at `root` what [`made`] makes, none when it is
/// current. An error when a file with a part lacks its marker lines.
pub fn changes(root: &Path) -> Result<Vec<Change>, String> {
    changes_of(root, made())
}

fn changes_of(root: &Path, made: Vec<Made>) -> Result<Vec<Change>, String> {
    let mut out = Vec::new();
    let mut differs = |path: PathBuf, bytes: Vec<u8>| {
        if std::fs::read(&path).ok().as_ref() != Some(&bytes) {
            out.push(Change {
                path,
                contents: Some(bytes),
            });
        }
    };
    let mut gone = Vec::new();
    for m in made {
        match m {
            Made::Part { file, name, text } => {
                let path = root.join(file);
                let old = std::fs::read_to_string(&path)
                    .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
                let new =
                    replaced(&old, name, &text).map_err(|e| format!("{}: {e}", path.display()))?;
                differs(path, new.into_bytes());
            }
            Made::Whole { file, bytes } => differs(root.join(file), bytes),
            Made::Folder {
                dir,
                extension,
                files,
            } => {
                let dir = root.join(dir);
                for (name, bytes) in &files {
                    differs(dir.join(name), bytes.clone());
                }
                gone.extend(unmade(&dir, extension, &files)?);
            }
        }
    }
    out.extend(gone);
    Ok(out)
}

/// The files of `dir` with `extension` that nothing makes.
fn unmade(dir: &Path, extension: &str, files: &[(String, Vec<u8>)]) -> Result<Vec<Change>, String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot list {}: {e}", dir.display())),
    };
    let mut out = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| e.to_string())?.path();
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let made = files.iter().any(|(n, _)| *n == name);
        if path.extension().is_some_and(|e| e == extension) && !made {
            out.push(Change {
                path,
                contents: None,
            });
        }
    }
    out.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(out)
}

/// Writes (or removes) each changed file.
pub fn apply(root: &Path, changes: &[Change]) -> Result<(), String> {
    for c in changes {
        let result = match &c.contents {
            Some(bytes) => std::fs::create_dir_all(c.path.parent().unwrap_or(root))
                .and_then(|()| std::fs::write(&c.path, bytes)),
            None => std::fs::remove_file(&c.path),
        };
        result.map_err(|e| format!("cannot write {}: {e}", c.path.display()))?;
    }
    Ok(())
}

/// `text` with the lines between its marker lines for `name` replaced by `part`.
fn replaced(text: &str, name: &str, part: &str) -> Result<String, String> {
    let begin_marker = format!("BEGIN GENERATED: {name}");
    let end_marker = format!("END GENERATED: {name}");
    let missing = |m: &str| format!("no line with `{m}` (the marker lines of a generated part)");
    let begin = text
        .find(&begin_marker)
        .ok_or_else(|| missing(&begin_marker))?;
    if text[begin + 1..].contains(&begin_marker) {
        return Err(format!("`{begin_marker}` is on more than one line"));
    }
    let begin = begin
        + text[begin..]
            .find('\n')
            .map(|n| n + 1)
            .ok_or_else(|| missing(&end_marker))?;
    let end = begin
        + text[begin..]
            .find(&end_marker)
            .ok_or_else(|| missing(&end_marker))?;
    // The end marker's line starts with its comment opener: keep the whole line.
    let end = text[..end].rfind('\n').map_or(end, |n| n + 1).max(begin);
    Ok(format!("{}{part}{}", &text[..begin], &text[end..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checkout's generated files are what the definitions make: CI's `generate --check`,
    /// also run by `cargo test`.
    #[test]
    fn every_generated_file_is_current() {
        let stale = changes(&checkout()).unwrap();
        let paths: Vec<_> = stale.iter().map(|c| c.path.display().to_string()).collect();
        assert!(
            stale.is_empty(),
            "stale, run `cargo run -p specconv-dev -- generate`: {paths:?}"
        );
    }

    #[test]
    fn a_part_is_replaced_between_its_markers() {
        let text = "a\n<!-- BEGIN GENERATED: t -->\nold\nrows\n<!-- END GENERATED: t -->\nb\n";
        assert_eq!(
            replaced(text, "t", "new\n").unwrap(),
            "a\n<!-- BEGIN GENERATED: t -->\nnew\n<!-- END GENERATED: t -->\nb\n"
        );
        assert!(replaced(text, "u", "new\n")
            .unwrap_err()
            .contains("BEGIN GENERATED: u"));
        let twice = format!("{text}{text}");
        assert!(replaced(&twice, "t", "x\n")
            .unwrap_err()
            .contains("more than one"));
        let no_end = "a\n# BEGIN GENERATED: t\nold\n";
        assert!(replaced(no_end, "t", "x\n")
            .unwrap_err()
            .contains("END GENERATED: t"));
    }

    /// In a scratch checkout: a stale part, a stale page and a page nothing makes are each
    /// found, `apply` makes the tree current, and a second look finds nothing.
    #[test]
    fn stale_files_are_found_and_written() {
        let root = std::env::temp_dir().join(format!("specconv-dev-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("man")).unwrap();
        std::fs::write(
            root.join("doc.md"),
            "x\n<!-- BEGIN GENERATED: t -->\nold\n<!-- END GENERATED: t -->\n",
        )
        .unwrap();
        std::fs::write(root.join("man/a.1"), "old page").unwrap();
        std::fs::write(root.join("man/gone.1"), "a command that is gone").unwrap();
        std::fs::write(root.join("man/notes.txt"), "not a page").unwrap();
        let made = || {
            vec![
                Made::Part {
                    file: "doc.md",
                    name: "t",
                    text: "new\n".into(),
                },
                Made::Folder {
                    dir: "man",
                    extension: "1",
                    files: vec![("a.1".into(), b"page".to_vec())],
                },
            ]
        };
        let found = changes_of(&root, made()).unwrap();
        let names: Vec<_> = found
            .iter()
            .map(|c| {
                (
                    c.path.strip_prefix(&root).unwrap().display().to_string(),
                    c.contents.is_some(),
                )
            })
            .collect();
        assert_eq!(
            names,
            [
                ("doc.md".into(), true),
                ("man/a.1".into(), true),
                ("man/gone.1".into(), false)
            ]
        );
        apply(&root, &found).unwrap();
        assert_eq!(changes_of(&root, made()).unwrap(), []);
        assert!(root.join("man/notes.txt").exists() && !root.join("man/gone.1").exists());
        std::fs::remove_dir_all(&root).unwrap();
    }
}
