//! The docs name only flags the program has: every `--flag` of a command line in README.md and
//! docs/*.md (code spans and code lines that start with `specconv` or a flag) is one of some
//! command's flags or aliases, and a word after a flag that takes one of a list of values is
//! one of them. Other tools' flags (`maketx --nomipmap`, `oiiotool --diff`, `pip install -v`)
//! are in spans that start with their name, and are not ours to check.

use crate::command_line::Cli;
use clap::CommandFactory;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Other tools' flags the docs name in a span of their own (`--colorconvert`, beside the words
/// "maketx's"): not ours, and never to become ours unnoticed.
const OTHERS: [(&str, &str); 5] = [
    ("array", "sbatch"),
    ("bench", "cargo"),
    ("target", "cargo"),
    ("colorconvert", "maketx"),
    ("no-autopremult", "oiiotool"),
];

/// Every long flag and alias of every command, with the values it accepts when it lists them.
fn flags() -> BTreeMap<String, BTreeSet<String>> {
    fn walk(cmd: &clap::Command, out: &mut BTreeMap<String, BTreeSet<String>>) {
        for a in cmd.get_arguments() {
            let values: BTreeSet<String> = a
                .get_possible_values()
                .iter()
                .flat_map(|v| {
                    v.get_name_and_aliases()
                        .map(str::to_string)
                        .collect::<Vec<_>>()
                })
                .collect();
            for long in a.get_long_and_visible_aliases().into_iter().flatten() {
                out.entry(long.to_string())
                    .or_default()
                    .extend(values.clone());
            }
        }
        for s in cmd.get_subcommands() {
            walk(s, out);
        }
    }
    let mut cmd = Cli::command();
    cmd.build();
    let mut out = BTreeMap::new();
    walk(&cmd, &mut out);
    out
}

/// The command lines of a Markdown text: code spans and code-block lines that start with
/// `specconv` or with a flag.
fn command_lines(text: &str) -> Vec<String> {
    let ours = |s: &str| {
        let s = s.trim_start_matches(['$', ' ']);
        s.starts_with("specconv ") || s.starts_with("--")
    };
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.starts_with("    ") && ours(line.trim()) {
            lines.push(line.trim().to_string());
            continue;
        }
        for (i, span) in line.split('`').enumerate() {
            if i % 2 == 1 && ours(span) {
                lines.push(span.to_string());
            }
        }
    }
    lines
}

#[test]
fn every_flag_the_docs_name_exists() {
    let known = flags();
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let mut files = vec![root.join("README.md")];
    for f in std::fs::read_dir(root.join("docs")).unwrap() {
        let f = f.unwrap().path();
        if f.extension().is_some_and(|e| e == "md") {
            files.push(f);
        }
    }
    let (mut wrong, mut checked) = (Vec::new(), 0);
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        for line in command_lines(&text) {
            let words: Vec<&str> = line.split_whitespace().collect();
            for (k, word) in words.iter().enumerate() {
                let Some(flag) = word.strip_prefix("--") else {
                    continue;
                };
                let flag = flag.split('=').next().unwrap();
                let flag = flag.trim_end_matches([',', ')', '.', ';', ':', '\\'].as_ref());
                if flag.is_empty() || !flag.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
                    continue;
                }
                checked += 1;
                let other = OTHERS.iter().any(|(f, _)| *f == flag);
                if other && !line.starts_with("specconv") {
                    assert!(
                        !known.contains_key(flag),
                        "--{flag} is ours now: drop it from OTHERS"
                    );
                    continue;
                }
                let Some(values) = known.get(flag) else {
                    wrong.push(format!("{name}: --{flag} (in `{line}`)"));
                    continue;
                };
                // A plain word after a flag of listed values is one of them.
                let next = words
                    .get(k + 1)
                    .map(|w| w.trim_end_matches([',', ')', '.', ';']));
                if let Some(v) = next.filter(|v| {
                    !values.is_empty()
                        && !v.is_empty()
                        && v.chars()
                            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
                        && !v.starts_with('-')
                }) {
                    if !values.contains(v) {
                        wrong.push(format!("{name}: --{flag} {v} (in `{line}`)"));
                    }
                }
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "the docs name what is not:\n{}",
        wrong.join("\n")
    );
    assert!(checked > 200, "{checked} flags checked");
}
