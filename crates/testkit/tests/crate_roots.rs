//! The house rule on crate roots, checked: a crate root says what the crate is and re-exports;
//! the work lives in modules named for it. For every crate root of the workspace
//! (`crates/*/src/lib.rs`, `ffi/*/src/lib.rs`, `python/src/lib.rs`, `src/lib.rs` or `main.rs`):
//!
//! - it has at most [`ROOT_LIMIT`] lines of production code, counted as the length rule counts
//!   a crate's (`specconv_testkit::sources::production_lines`: not blank, not a comment, unit
//!   tests left out);
//! - no module of its crate names an item the root defines (`fn`, `struct`, `enum`, `union`,
//!   `const`, `static`, `type`, `trait`, `macro_rules!`): not through `crate::NAME`, a
//!   `use crate::{…}` group, nor `super::NAME` from a module the root declares. A module
//!   imports from the module that defines what it needs, so that the root stays a list of
//!   modules and re-exports and no module leans on it (a root that holds work hides the
//!   circles between modules that tests/layers.rs looks for). What the root only re-exports
//!   (`pub use`) may be named through it.
//!
//! Run with `--nocapture` to print each root's size. [`ALLOWED`] lists the roots not thinned
//! yet, each with why; an entry that no longer breaks the rule fails the test too, so that the
//! list only shrinks.

use specconv_testkit::sources::{production, production_lines, root, sources};

/// The most lines of production code a crate root may have: its doc, its modules and its
/// re-exports fit in far fewer.
const ROOT_LIMIT: usize = 300;

/// Crate roots that still hold work: (root, why).
const ALLOWED: &[(&str, &str)] = &[];

/// The item kinds whose names a root defines (modules are what a root is for).
const KINDS: &[&str] = &[
    "fn",
    "struct",
    "enum",
    "union",
    "const",
    "static",
    "type",
    "trait",
    "macro_rules!",
];

/// Every crate of the workspace: its root and its other production files (paths from the
/// workspace root), from the sources the length rule reads. A folder `src/` is one crate;
/// its root is `lib.rs`, else `main.rs`.
fn crates() -> Vec<(String, Vec<String>)> {
    let files = sources();
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    let dirs: std::collections::BTreeSet<String> = files
        .iter()
        .filter_map(|f| Some(format!("{}src/", f.split_once("src/")?.0)))
        .collect();
    for dir in dirs {
        let mine: Vec<&String> = files.iter().filter(|f| f.starts_with(&dir)).collect();
        let root = ["lib.rs", "main.rs"]
            .iter()
            .map(|r| format!("{dir}{r}"))
            .find(|r| mine.contains(&r))
            .unwrap_or_else(|| panic!("{dir} has neither lib.rs nor main.rs"));
        let modules = mine.into_iter().filter(|f| **f != root).cloned().collect();
        out.push((root, modules));
    }
    out
}

/// The names of the items a crate root's `text` defines at its top level (lines without
/// indentation, unit tests left out): what its modules must not name through it.
fn defined_items(text: &str) -> Vec<String> {
    production(text)
        .into_iter()
        .filter(|l| !l.starts_with(char::is_whitespace))
        .filter_map(item_name)
        .collect()
}

/// The name of the item a line starts, if it starts one of [`KINDS`].
fn item_name(line: &str) -> Option<String> {
    let mut rest = line.trim_end();
    if let Some(scoped) = rest.strip_prefix("pub(") {
        rest = scoped.split_once(") ")?.1;
    }
    rest = rest.strip_prefix("pub ").unwrap_or(rest);
    // A function's qualifiers: `const fn` is a function, `const X` a constant.
    loop {
        let before = rest;
        for word in ["async ", "unsafe "] {
            rest = rest.strip_prefix(word).unwrap_or(rest);
        }
        if let Some(qualified) = rest.strip_prefix("const ") {
            let function = ["fn ", "async ", "unsafe ", "extern "];
            if function.iter().any(|w| qualified.starts_with(w)) {
                rest = qualified;
            }
        }
        if let Some(abi) = rest.strip_prefix("extern \"") {
            rest = abi.split_once("\" ").map_or(rest, |(_, after)| after);
        }
        if rest == before {
            break;
        }
    }
    let after = KINDS
        .iter()
        .find_map(|k| rest.strip_prefix(k)?.strip_prefix(' '))?;
    let after = after.strip_prefix("mut ").unwrap_or(after);
    let name: String = after
        .trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then_some(name)
}

/// The first segment of every path `code` names after `prefix` (`crate::`, or `super::` from a
/// module the root declares), groups opened: `use crate::{a::B, c}` names `a` and `c`; a glob
/// names `*`.
fn names_through(code: &str, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (at, _) in code.match_indices(prefix) {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let rest = code[at + prefix.len()..].trim_start();
        match rest.strip_prefix('{') {
            Some(group) => {
                let mut depth = 0;
                let end = group
                    .char_indices()
                    .find(|&(_, c)| {
                        depth += i32::from(c == '{') - i32::from(c == '}');
                        depth < 0
                    })
                    .map_or(group.len(), |(i, _)| i);
                let mut depth = 0;
                for entry in group[..end].split(|c: char| {
                    depth += i32::from(c == '{') - i32::from(c == '}');
                    c == ',' && depth == 0
                }) {
                    out.extend(first_segment(entry.trim()));
                }
            }
            None => out.extend(first_segment(rest)),
        }
    }
    out
}

/// The first segment of a path: a name, or `*` for a glob.
fn first_segment(path: &str) -> Option<String> {
    if path.starts_with('*') {
        return Some("*".into());
    }
    let name: String = path
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty() && name != "self").then_some(name)
}

/// The root's items a module file names: `module` is its path from the workspace root, `src`
/// its crate's source folder.
fn root_items_named(module: &str, src: &str, text: &str, defined: &[String]) -> Vec<String> {
    let code: String = production(text)
        .iter()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    // A module the root declares (`src/NAME.rs`, `src/NAME/mod.rs`) reaches it as `super`.
    let inside = module.strip_prefix(src).unwrap_or(module);
    let declared_by_root =
        !inside.contains('/') || (inside.matches('/').count() == 1 && inside.ends_with("/mod.rs"));
    let mut names = names_through(&code, "crate::");
    if declared_by_root {
        names.extend(names_through(&code, "super::"));
    }
    let mut found: Vec<String> = names
        .into_iter()
        .filter(|n| (n == "*" && !defined.is_empty()) || defined.contains(n))
        .collect();
    found.sort();
    found.dedup();
    found
}

#[test]
fn the_checker_sees_a_root_s_items_and_the_modules_that_name_them() {
    let root = "\
//! A crate.
pub mod a;
pub use a::Kept;
/// Defined here.
pub struct Here;
pub(crate) const fn made() -> u8 { 1 }
const LIMIT: usize = 3;
pub static mut COUNT: u8 = 0;
macro_rules! m { () => {}; }
impl Here {
    fn inner() {}
}
#[cfg(test)]
mod tests {
    fn helper() {}
}
";
    assert_eq!(defined_items(root), ["Here", "made", "LIMIT", "COUNT", "m"]);
    let defined = defined_items(root);
    let module = "\
use crate::{a::Kept, Here, made as make};
use super::LIMIT; // crate::COUNT in a comment
fn f() -> crate::Kept { crate::a::g(); self::super::x() }
#[cfg(test)]
mod tests {
    use crate::COUNT;
}
";
    assert_eq!(
        root_items_named("c/src/b.rs", "c/src/", module, &defined),
        ["Here", "LIMIT", "made"]
    );
    // `super` from a module two levels down is not the root.
    assert_eq!(
        root_items_named("c/src/b/d.rs", "c/src/", "use super::LIMIT;", &defined),
        Vec::<String>::new()
    );
    assert_eq!(
        root_items_named("c/src/b/d.rs", "c/src/", "use crate::*;", &defined),
        ["*"]
    );
}

#[test]
fn crate_roots_only_declare_and_re_export() {
    let mut broken: Vec<(String, String)> = Vec::new();
    for (root_file, modules) in crates() {
        let text = std::fs::read_to_string(root().join(&root_file)).unwrap();
        let lines = production_lines(&text);
        println!("{lines:5}  {root_file}");
        if lines > ROOT_LIMIT {
            broken.push((
                root_file.clone(),
                format!("{lines} lines of production code (at most {ROOT_LIMIT})"),
            ));
        }
        let defined = defined_items(&text);
        let src = root_file.rsplit_once('/').unwrap().0.to_owned() + "/";
        for module in modules {
            let text = std::fs::read_to_string(root().join(&module)).unwrap();
            for name in root_items_named(&module, &src, &text, &defined) {
                broken.push((
                    root_file.clone(),
                    format!("{module} names `{name}`, which the root defines"),
                ));
            }
        }
    }
    let allowed = |root: &str| ALLOWED.iter().any(|(r, _)| *r == root);
    let over: Vec<String> = broken
        .iter()
        .filter(|(root, _)| !allowed(root))
        .map(|(root, what)| format!("{root}: {what}"))
        .collect();
    assert!(
        over.is_empty(),
        "crate roots that hold work; move it into modules named for what they do, import it \
         from there and re-export it from the root:\n{}",
        over.join("\n")
    );
    let stale: Vec<&str> = ALLOWED
        .iter()
        .filter(|(r, _)| !broken.iter().any(|(root, _)| root == r))
        .map(|(r, _)| *r)
        .collect();
    assert!(
        stale.is_empty(),
        "allowed to hold work but no longer do (or gone): take them off ALLOWED:\n{}",
        stale.join("\n")
    );
}
