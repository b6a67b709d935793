//! The specconv command line. It parses and dispatches (`command_line`) and runs each command
//! (`cmd`); `convert` is specconv-convert-cmd's and `farm` specconv-farm-cmd's, and the work
//! happens in the library crates. Every error of every command is printed as one line,
//! `specconv: error: WHAT: CAUSE: …`, each cause once (specconv-convert-cmd's `errors`), and
//! the exit status is one of [`exit`]'s.
#![forbid(unsafe_code)]

#[macro_use]
extern crate specconv_convert_cmd;

mod cmd;
mod command_line;
#[cfg(test)]
mod doc_flags;
mod files;
#[cfg(test)]
mod flag_tests;
pub mod generated;
mod man;
mod methods;
mod picture;

pub use command_line::main;
/// The exit statuses, for the program's tests and its man pages.
pub use specconv_convert_cmd::exit;

/// The man pages, one per command: (file name in man/, roff).
pub fn man_pages() -> Vec<(String, Vec<u8>)> {
    man::pages()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command_line::Cli;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    /// Every example of every page parses as a command line of this program (after a pipe,
    /// before a redirection), so the examples cannot drift from the options.
    #[test]
    fn every_example_parses() {
        let mut n = 0;
        for cmd in std::iter::once(Cli::command()).chain(Cli::command().get_subcommands().cloned())
        {
            let Some(text) = cmd.get_after_long_help().map(|t| t.to_string()) else {
                continue;
            };
            for line in text.lines().map(str::trim) {
                let Some(start) = line.find("specconv ") else {
                    continue;
                };
                if line.starts_with('#') {
                    continue;
                }
                let command = &line[start..];
                let command = command.split(" 2>").next().unwrap();
                let command = command.split(" > ").next().unwrap();
                let words = shell_words(command);
                crate::command_line::parse(words.iter().map(std::ffi::OsString::from))
                    .unwrap_or_else(|e| {
                        panic!(
                            "{line}: {}",
                            specconv_convert_cmd::errors::clap_error_line(&e)
                        )
                    });
                n += 1;
            }
        }
        assert!(n >= 25, "{n} examples");
    }

    /// Words as a POSIX shell splits them, for the quoting the examples use.
    fn shell_words(line: &str) -> Vec<String> {
        let (mut words, mut word, mut quote, mut any) = (Vec::new(), String::new(), None, false);
        for c in line.chars() {
            match (quote, c) {
                (None, '\'' | '"') => (quote, any) = (Some(c), true),
                (Some(q), c) if c == q => quote = None,
                (None, c) if c.is_whitespace() => {
                    if any {
                        words.push(std::mem::take(&mut word));
                    }
                    any = false;
                }
                (_, c) => {
                    word.push(c);
                    any = true;
                }
            }
        }
        if any {
            words.push(word);
        }
        words
    }

    /// Every page has EXIT STATUS, ENVIRONMENT and EXAMPLES, and every page it names exists.
    #[test]
    fn every_man_page_has_its_sections_and_names_only_pages_that_exist() {
        let pages = man_pages();
        let names: Vec<&str> = pages.iter().map(|(n, _)| n.as_str()).collect();
        assert!(names.len() >= 11, "{names:?}");
        for (name, page) in &pages {
            let text = String::from_utf8_lossy(page);
            for section in [
                ".SH NAME",
                ".SH SYNOPSIS",
                ".SH OPTIONS",
                ".SH EXAMPLES",
                ".SH \"EXIT STATUS\"",
                ".SH ENVIRONMENT",
                ".SH \"SEE ALSO\"",
            ] {
                assert!(
                    text.contains(section),
                    "{name} lacks {section}: give the command `after_long_help = EXAMPLES`"
                );
            }
            for code in [
                exit::OK,
                exit::FAILED,
                exit::USAGE,
                exit::INTERRUPTED,
                exit::PIPE,
            ] {
                assert!(
                    text.contains(&format!(".TP\n\\fB{code}\\fR\n")),
                    "{name}: {code}"
                );
            }
            // References look like specconv\-info(1) in running text and \fBspecconv\-info\fR(1).
            let plain = text
                .replace("\\fB", "")
                .replace("\\fR", "")
                .replace("\\-", "-");
            for word in plain.split(|c: char| c.is_whitespace() || c == ',') {
                if let Some(page) = word.strip_suffix("(1)") {
                    assert!(
                        names.contains(&format!("{page}.1").as_str()),
                        "{name} names {word}, which is not a page"
                    );
                }
            }
        }
    }

    /// Every variable the program reads is in ENVIRONMENT: the sources are searched for
    /// names read with std::env (build- and test-only variables aside).
    #[test]
    fn the_environment_section_names_every_variable_read() {
        let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
        let not_at_run_time = [
            "SPECCONV_UPDATE_GENERATED",
            "SPECCONV_REGENERATE_BINDINGS",
            // Build scripts (ffi/shim-build) read what cargo gives them.
            "OUT_DIR",
            // The measured spectra's folder, read by unit tests beside their module.
            "SPECCONV_SHARED",
            // The tests' Python (the reader's unit tests in crates/asset run it as a child).
            "SPECCONV_PYTHON",
        ];
        let mut read = std::collections::BTreeSet::new();
        let mut dirs = vec![root.join("crates"), root.join("ffi"), root.join("src")];
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let p = entry.unwrap().path();
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                if p.is_dir() {
                    // Tests, benches, examples and the test kit are not the program.
                    if !["tests", "benches", "examples", "target", "testkit"]
                        .contains(&name.as_str())
                    {
                        dirs.push(p);
                    }
                } else if name.ends_with(".rs") {
                    let text = std::fs::read_to_string(&p).unwrap();
                    for (i, _) in text
                        .match_indices("var_os(\"")
                        .chain(text.match_indices("var(\""))
                    {
                        let rest = &text[i..];
                        let start = rest.find('"').unwrap() + 1;
                        let len = rest[start..].find('"').unwrap();
                        read.insert(rest[start..start + len].to_string());
                    }
                    // Names passed through a helper such as cache_dir's `env`.
                    for (i, _) in text.match_indices("env(\"") {
                        let rest = &text[i + 5..];
                        let len = rest.find('"').unwrap();
                        read.insert(rest[..len].to_string());
                    }
                }
            }
        }
        let listed: Vec<&str> = man::ENVIRONMENT.iter().map(|(v, _)| *v).collect();
        for var in read {
            if !not_at_run_time.contains(&var.as_str()) {
                assert!(
                    listed.contains(&var.as_str()),
                    "{var} is read but not in man::ENVIRONMENT"
                );
            }
        }
        for var in ["OCIO", "SPECCONV_FONT", "SPECCONV_CACHE_DIR"] {
            assert!(listed.contains(&var), "{var}");
        }
    }
}
