//! The house rules on length, checked: no production function is longer than [`LIMIT`] lines,
//! and no crate holds more than [`CRATE_LIMIT`] lines of production code. Run with
//! `--nocapture` to print the longest and the largest.
//!
//! The rule, by line and indentation (the layout `cargo fmt` gives, which CI enforces):
//!
//! - Production code is every `.rs` file under `crates/*/src`, `ffi/*/src`, `python/src` and
//!   `src`: not `tests/`, `benches/`, `build.rs` or `fuzz/`.
//! - A function starts at a line that begins, after its indentation, with `fn NAME` (after any
//!   of `pub`, `pub(…)`, `const`, `async`, `unsafe`, `extern "…"`) and ends at the first later
//!   line that is `}` at that same indentation; its length counts both lines. A declaration
//!   without a body (ending in `;`) and a function on one line are not counted. A function
//!   inside another counts on its own, and as lines of the one around it.
//! - The item after a `#[cfg(test)]` line (the unit tests' module) is skipped to the `}` at its
//!   indentation. A test module in a file of its own (`#[cfg(test)]` then `mod NAME;`) is not
//!   production code either: its file (`NAME.rs` beside a `lib.rs`, `main.rs` or `mod.rs`,
//!   else in the folder named after the declaring file) is left out whole.
//!
//! [`ALLOWED`] lists the functions left longer, each with why; an entry that is no longer over
//! the limit fails the test too, so that the list only shrinks.

use specconv_testkit::sources::{
    closing, is_code, production, production_lines, root, skip_test_item, sources, test_modules,
};

/// The most lines a production function may have.
const LIMIT: usize = 100;

/// The most lines of production code (not blank, not a comment, unit tests left out as below)
/// a crate may have: past it, a crate does more than one job.
const CRATE_LIMIT: usize = 6000;

/// Functions over the limit that stay for now: (file, function, why).
const ALLOWED: &[(&str, &str, &str)] = &[];

/// The function a line starts, if it starts one: its indentation and name.
fn starts_function(line: &str) -> Option<(&str, &str)> {
    let rest = line.trim_start();
    let indent = &line[..line.len() - rest.len()];
    let mut rest = rest;
    loop {
        let before = rest;
        for word in ["pub ", "const ", "async ", "unsafe "] {
            rest = rest.strip_prefix(word).unwrap_or(rest);
        }
        if let Some(scoped) = rest.strip_prefix("pub(") {
            rest = scoped.split_once(") ").map_or(rest, |(_, after)| after);
        }
        if let Some(abi) = rest.strip_prefix("extern \"") {
            rest = abi.split_once("\" ").map_or(rest, |(_, after)| after);
        }
        if rest == before {
            break;
        }
    }
    let name = rest.strip_prefix("fn ")?;
    let end = name
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(name.len());
    Some((indent, &name[..end]))
}

/// Every function of `text` with a body on more than one line: (name, first line from 1,
/// length in lines).
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.trim() == "#[cfg(test)]" {
            i = skip_test_item(&lines, i);
            continue;
        }
        if let Some((indent, name)) = starts_function(line) {
            // The body opens on the signature's last line; none when it ends in `;` first.
            let open = (i..lines.len())
                .find(|&k| lines[k].contains('{') || lines[k].trim_end().ends_with(';'));
            if let Some(open) = open.filter(|&k| lines[k].contains('{')) {
                let body = lines[open];
                let on_one_line = body.trim_end().ends_with('}')
                    && body.matches('{').count() == body.matches('}').count();
                if !on_one_line {
                    let end = closing(&lines, open, indent);
                    out.push((name.to_string(), i + 1, end - i + 1));
                }
            }
        }
        i += 1;
    }
    out
}

#[test]
fn the_rule_counts_from_fn_to_its_closing_brace_and_skips_unit_tests() {
    let text = "\
pub(crate) fn three() {
    x();
}
fn one() {}
trait T {
    fn declared(&self);
    fn provided(&self) -> u8 {
        if true {
        }
        0
    }
}
pub fn signature(
    a: u8,
) -> u8
where
    u8: Copy,
{
    a
}
#[cfg(test)]
mod tests {
    fn helper() {
        x();
    }
}
";
    let found = functions(text);
    let found: Vec<(&str, usize, usize)> = found
        .iter()
        .map(|(n, l, len)| (n.as_str(), *l, *len))
        .collect();
    assert_eq!(
        found,
        [("three", 1, 3), ("provided", 7, 5), ("signature", 13, 8)]
    );
}

#[test]
fn no_production_function_is_longer_than_the_limit() {
    let mut long = Vec::new();
    let mut longest = Vec::new();
    for file in sources() {
        let text = std::fs::read_to_string(root().join(&file)).unwrap();
        for (name, line, length) in functions(&text) {
            longest.push((length, format!("{file}:{line} {name}")));
            if length > LIMIT {
                long.push((file.clone(), name, line, length));
            }
        }
    }
    longest.sort_by(|a, b| b.cmp(a));
    for (length, at) in longest.iter().take(15) {
        println!("{length:5}  {at}");
    }
    let allowed = |file: &str, name: &str| ALLOWED.iter().any(|(f, n, _)| *f == file && *n == name);
    let over: Vec<String> = long
        .iter()
        .filter(|(file, name, ..)| !allowed(file, name))
        .map(|(file, name, line, length)| format!("{file}:{line} {name}: {length} lines"))
        .collect();
    assert!(
        over.is_empty(),
        "functions longer than {LIMIT} lines; split them into functions that say what they do:\n{}",
        over.join("\n")
    );
    let stale: Vec<String> = ALLOWED
        .iter()
        .filter(|(f, n, _)| !long.iter().any(|(file, name, ..)| file == f && name == n))
        .map(|(f, n, _)| format!("{f} {n}"))
        .collect();
    assert!(
        stale.is_empty(),
        "allowed to be long but no longer over {LIMIT} lines (or gone): take them off ALLOWED:\n{}",
        stale.join("\n")
    );
}

/// The CLI's checks of the flags the docs name and of the flags against the definitions are
/// modules of their own files, declared for tests only: not production code (what makes the
/// generated docs is: specconv-dev calls it).
#[test]
fn a_test_module_in_a_file_of_its_own_is_left_out() {
    let cli = root().join("crates/cli/src");
    let found = test_modules(&cli.join("lib.rs"));
    assert_eq!(found, [cli.join("doc_flags.rs"), cli.join("flag_tests.rs")]);
    let sources = sources();
    assert!(!sources.contains(&"crates/cli/src/doc_flags.rs".to_owned()));
    assert!(!sources.contains(&"crates/cli/src/flag_tests.rs".to_owned()));
    assert!(sources.contains(&"crates/cli/src/generated.rs".to_owned()));
    assert!(sources.contains(&"crates/cli/src/lib.rs".to_owned()));
}

#[test]
fn production_lines_leave_out_blank_lines_comments_and_unit_tests() {
    let text = "/// A.\nfn a() {\n\n    // one\n    1;\n}\n#[cfg(test)]\nmod tests {\n    fn b() {}\n}\n#[cfg(test)]\nuse x;\nfn c() {}\n";
    let lines: Vec<&str> = production(text)
        .into_iter()
        .filter(|l| is_code(l))
        .collect();
    assert_eq!(lines, ["fn a() {", "    1;", "}", "fn c() {}"]);
}

#[test]
fn no_crate_is_larger_than_the_limit() {
    let mut sizes: std::collections::BTreeMap<String, usize> = Default::default();
    for file in sources() {
        // The crate: `crates/NAME`, `ffi/NAME`, `python` or the root's `src`.
        let parts: Vec<&str> = file.split('/').collect();
        let krate = match parts[0] {
            "crates" | "ffi" => format!("{}/{}", parts[0], parts[1]),
            other => other.to_string(),
        };
        let text = std::fs::read_to_string(root().join(&file)).unwrap();
        let lines = production_lines(&text);
        *sizes.entry(krate).or_default() += lines;
    }
    let mut largest: Vec<_> = sizes.iter().collect();
    largest.sort_by(|a, b| b.1.cmp(a.1));
    for (krate, lines) in &largest {
        println!("{lines:6}  {krate}");
    }
    let over: Vec<String> = largest
        .iter()
        .filter(|(_, &lines)| lines > CRATE_LIMIT)
        .map(|(krate, lines)| format!("{krate}: {lines} lines"))
        .collect();
    assert!(
        over.is_empty(),
        "crates over {CRATE_LIMIT} lines of production code; cut each where its jobs part:\n{}",
        over.join("\n")
    );
}
