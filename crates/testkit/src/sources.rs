//! The workspace's production sources as the house tests read them (by line and indentation,
//! the layout `cargo fmt` gives): which files are production code, and which of their lines
//! count. The length rule (tests/function_length.rs) and the crate-root rule
//! (tests/crate_roots.rs) count alike through these.

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The production sources, as paths relative to the workspace root, sorted.
pub fn sources() -> Vec<String> {
    let root = root();
    let mut dirs = vec![root.join("python/src"), root.join("src")];
    for parent in ["crates", "ffi"] {
        for entry in std::fs::read_dir(root.join(parent)).unwrap() {
            dirs.push(entry.unwrap().path().join("src"));
        }
    }
    let mut files = Vec::new();
    for dir in dirs.iter().filter(|d| d.is_dir()) {
        collect(dir, &mut files);
    }
    let test_only: Vec<PathBuf> = files.iter().flat_map(|f| test_modules(f)).collect();
    let mut out: Vec<String> = files
        .iter()
        .filter(|f| !test_only.contains(f))
        .map(|f| {
            f.strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/")
        })
        .collect();
    out.sort();
    out
}

/// The files of the modules `file` declares only for tests (`#[cfg(test)]` then `mod NAME;`).
pub fn test_modules(file: &Path) -> Vec<PathBuf> {
    let text = std::fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let stem = file.file_stem().unwrap().to_string_lossy();
    let dir = match stem.as_ref() {
        "lib" | "main" | "mod" => file.parent().unwrap().to_path_buf(),
        _ => file.with_extension(""),
    };
    lines
        .windows(2)
        .filter(|w| w[0].trim() == "#[cfg(test)]")
        .filter_map(|w| {
            let name = w[1].trim().strip_prefix("mod ")?.strip_suffix(';')?;
            [
                dir.join(format!("{name}.rs")),
                dir.join(name).join("mod.rs"),
            ]
            .into_iter()
            .find(|p| p.is_file())
        })
        .collect()
}

/// Every `.rs` file under `dir`, added to `files`.
fn collect(dir: &Path, files: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            collect(&path, files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
}

/// The line (index) of the `}` at `indent` that closes the item starting at `start`.
pub fn closing(lines: &[&str], start: usize, indent: &str) -> usize {
    let close = format!("{indent}}}");
    (start + 1..lines.len())
        .find(|&i| lines[i] == close)
        .unwrap_or(lines.len() - 1)
}

/// The lines of `text` outside its `#[cfg(test)]` items, as the length rule's functions skip them.
pub fn production(text: &str) -> Vec<&str> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() == "#[cfg(test)]" {
            i = skip_test_item(&lines, i);
            continue;
        }
        out.push(lines[i]);
        i += 1;
    }
    out
}

/// The lines of production code in `text`: not blank, not a comment, not in a `#[cfg(test)]`
/// item. What the crate-size and crate-root limits count.
pub fn production_lines(text: &str) -> usize {
    production(text).iter().filter(|l| is_code(l)).count()
}

/// Whether a line is code: not blank, not a comment.
pub fn is_code(line: &str) -> bool {
    let line = line.trim();
    !line.is_empty() && !line.starts_with("//")
}

/// The line after the item that the `#[cfg(test)]` at `i` introduces.
pub fn skip_test_item(lines: &[&str], i: usize) -> usize {
    let line = lines[i];
    let indent = &line[..line.len() - line.trim_start().len()];
    let one_line = lines
        .get(i + 1)
        .is_some_and(|l| l.trim_end().ends_with(';'));
    if one_line {
        i + 2
    } else {
        closing(lines, i + 1, indent) + 1
    }
}
