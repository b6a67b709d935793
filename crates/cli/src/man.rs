//! Man pages, one per command, generated from the clap definitions with clap_mangen: NAME,
//! SYNOPSIS, DESCRIPTION and OPTIONS from clap; EXAMPLES from each command's `after_long_help`
//! (which `--help` shows too); EXIT STATUS from [`specconv_convert_cmd::exit::TABLE`]; ENVIRONMENT from
//! [`ENVIRONMENT`]; SEE ALSO naming the other pages. `specconv-dev generate` writes them to man/
//! (its `--check` in CI fails on drift).

use crate::command_line::Cli;
use clap::CommandFactory;

/// Every environment variable the program reads, and what for.
pub const ENVIRONMENT: [(&str, &str); 11] = [
    (
        "OCIO",
        "The OCIO config used when --ocio is not given (convert, info, colorspaces, to-rgb, and simulate scenes without `ocio`): a file, `aces` or a built-in name such as ocio://default or ocio://studio-config-latest; unset or empty: the built-in ACES config.",
    ),
    (
        "SPECCONV_MODEL",
        "The site's default model, a built-in name or a model file: used by every command, the Python package, farm tasks (recorded at submit) and the Mitsuba plugins whenever no model is named; unset or empty: the built-in default. `specconv models` says which model is in force and why.",
    ),
    (
        "SPECCONV_CACHE_DIR",
        "Where computed tables (the jakob2019 coefficient tables) are cached; default $XDG_CACHE_HOME/specconv, else $HOME/.cache/specconv.",
    ),
    ("XDG_CACHE_HOME", "See SPECCONV_CACHE_DIR."),
    ("HOME", "See SPECCONV_CACHE_DIR."),
    (
        "SPECCONV_FONT",
        "A TrueType font for the text of pictures (report --plot, simulate --image, preview); default DejaVu Sans (Debian: fonts-dejavu-core).",
    ),
    (
        "SLURM_ARRAY_TASK_ID",
        "The shard `convert --shard auto/N` converts (Slurm sets it in each task of a job array).",
    ),
    (
        "SLURM_CPUS_PER_TASK",
        "The threads a `farm` task converts with (Slurm sets it from --cpus-per-task; default the job's request).",
    ),
    (
        "SPECCONV_USD_PYTHON",
        "The Python interpreter `asset` reads USD stages and MaterialX documents with: it must have Pixar's usd-core and, for `.mtlx` documents, MaterialX (`python3 -m pip install usd-core MaterialX`); default python3.",
    ),
    (
        "SPECCONV_USD_TIMEOUT",
        "Seconds `asset` lets usd-core (or MaterialX) take to read a stage or write its layer (default 300).",
    ),
    (
        "SPECCONV_PROGRESS_SECONDS",
        "Seconds between the plain progress lines of a batch whose standard error is a file (default 5).",
    ),
];

/// The pages: (file name, roff), the top command's first.
pub fn pages() -> Vec<(String, Vec<u8>)> {
    // No `help` subcommand in the pages: `--help` is the way, and it has no page.
    let mut top = Cli::command().disable_help_subcommand(true);
    top.build();
    let subs: Vec<clap::Command> = top.get_subcommands().cloned().collect();
    let names: Vec<String> = subs
        .iter()
        .map(|s| format!("specconv-{}", s.get_name()))
        .collect();
    let mut pages = vec![("specconv.1".to_string(), page(&top, "specconv", &names))];
    for (sub, name) in subs.into_iter().zip(&names) {
        let others: Vec<String> = std::iter::once("specconv".to_string())
            .chain(names.iter().filter(|n| *n != name).cloned())
            .collect();
        let cmd = sub.display_name(name.clone());
        pages.push((format!("{name}.1"), page(&cmd, name, &others)));
        // A command with commands of its own (farm) has a page for each, as git's do; a hidden
        // one (`farm task`, which only a job's script runs) has none.
        let shown: Vec<&clap::Command> =
            cmd.get_subcommands().filter(|s| !s.is_hide_set()).collect();
        let nested: Vec<String> = shown
            .iter()
            .map(|s| format!("{name}-{}", s.get_name()))
            .collect();
        for (inner, inner_name) in shown.into_iter().zip(&nested) {
            let others: Vec<String> = std::iter::once(name.clone())
                .chain(nested.iter().filter(|n| *n != inner_name).cloned())
                .collect();
            let inner = inner.clone().display_name(inner_name.clone());
            pages.push((format!("{inner_name}.1"), page(&inner, inner_name, &others)));
        }
    }
    pages
}

fn page(cmd: &clap::Command, name: &str, see_also: &[String]) -> Vec<u8> {
    let man = clap_mangen::Man::new(cmd.clone())
        .title(name)
        .source(format!("specconv {}", env!("CARGO_PKG_VERSION")));
    let mut out = Vec::new();
    let render = |out: &mut Vec<u8>, f: &dyn Fn(&mut Vec<u8>) -> std::io::Result<()>| {
        f(out).expect("rendering to memory cannot fail")
    };
    render(&mut out, &|w| man.render_title(w));
    render(&mut out, &|w| man.render_name_section(w));
    out.extend_from_slice(synopsis(cmd).as_bytes());
    render(&mut out, &|w| man.render_description_section(w));
    render(&mut out, &|w| man.render_options_section(w));
    if cmd.has_subcommands() {
        render(&mut out, &|w| man.render_subcommands_section(w));
    }
    let mut roff = String::new();
    if let Some(examples) = cmd.get_after_long_help() {
        roff += ".SH EXAMPLES\n.nf\n";
        for line in examples.to_string().lines().skip_while(|l| {
            l.trim().is_empty() || l.trim_end().ends_with(':') && l.starts_with("Examples")
        }) {
            roff += &escape(line);
            roff += "\n";
        }
        roff += ".fi\n";
    }
    roff += ".SH \"EXIT STATUS\"\n";
    for (code, meaning) in specconv_convert_cmd::exit::TABLE {
        roff += &format!(".TP\n\\fB{code}\\fR\n{}\n", escape(meaning));
    }
    roff += ".SH ENVIRONMENT\n";
    for (var, meaning) in ENVIRONMENT {
        roff += &format!(".TP\n\\fB{}\\fR\n{}\n", escape(var), escape(meaning));
    }
    roff += ".SH \"SEE ALSO\"\n";
    let refs: Vec<String> = see_also
        .iter()
        .map(|n| format!("\\fB{}\\fR(1)", escape(n)))
        .collect();
    roff += &refs.join(", ");
    roff += "\n";
    out.extend_from_slice(roff.as_bytes());
    if cmd.get_version().is_some() {
        render(&mut out, &|w| man.render_version_section(w));
    }
    out
}

/// The SYNOPSIS section: every shown flag with the names of its values (`--ocio CONFIG`,
/// `--tile W H`, `--opaque-detect[=BOOL]`), then the operands and any subcommand. clap_mangen's
/// own synopsis leaves the values out, so `[--ocio]` read as a switch.
fn synopsis(cmd: &clap::Command) -> String {
    let mut cmd = cmd.clone();
    cmd.build();
    let name = cmd
        .get_bin_name()
        .unwrap_or_else(|| cmd.get_name())
        .to_string();
    let mut words = vec![format!("\\fB{}\\fR", escape(&name))];
    let mut flags: Vec<&clap::Arg> = cmd
        .get_arguments()
        .filter(|a| !a.is_hide_set() && !a.is_positional())
        .collect();
    flags.sort_by_key(|a| (a.get_display_order(), a.get_short(), a.get_long()));
    for a in flags {
        let names: Vec<String> = a
            .get_short()
            .map(|s| format!("-{s}"))
            .into_iter()
            .chain(a.get_long().map(|l| format!("--{l}")))
            .map(|n| format!("\\fB{}\\fR", escape(&n)))
            .collect();
        let (open, close) = if a.is_required_set() {
            ("", "")
        } else {
            ("[", "]")
        };
        words.push(format!(
            "{open}{}{}{close}",
            names.join("|"),
            value_words(a)
        ));
    }
    for a in cmd.get_positionals().filter(|a| !a.is_hide_set()) {
        let (open, close) = if a.is_required_set() {
            ("<", ">")
        } else {
            ("[", "]")
        };
        let value = a
            .get_value_names()
            .map(|v| v.iter().map(|n| n.as_str()).collect::<Vec<_>>().join(" "))
            .unwrap_or_else(|| a.get_id().to_string());
        words.push(format!("{open}\\fI{}\\fR{close}", escape(&value)));
    }
    if cmd.has_subcommands() {
        words.push("[\\fIcommand\\fR]".into());
    }
    format!(".SH SYNOPSIS\n{}\n", words.join(" "))
}

/// What follows a flag in the synopsis: ` VALUE`, ` W H`, `[=BOOL]`, or nothing for a switch.
fn value_words(a: &clap::Arg) -> String {
    let Some(range) = a.get_num_args().filter(|r| r.takes_values()) else {
        return String::new();
    };
    let names = a
        .get_value_names()
        .map(|v| {
            v.iter()
                .map(|n| format!("\\fI{}\\fR", escape(n.as_str())))
                .collect::<Vec<_>>()
        })
        .unwrap_or_else(|| {
            vec![format!(
                "\\fI{}\\fR",
                escape(&a.get_id().to_string().to_uppercase())
            )]
        });
    match (range.min_values() > 0, a.is_require_equals_set()) {
        (true, _) => format!(" {}", names.join(" ")),
        (false, true) => format!("[={}]", names.join(" ")),
        (false, false) => format!(" [{}]", names.join(" ")),
    }
}

/// Text as roff reads it literally: backslashes and hyphens escaped, no line taken for a
/// request.
fn escape(text: &str) -> String {
    let s = text.replace('\\', "\\\\").replace('-', "\\-");
    if s.starts_with('.') || s.starts_with('\'') {
        format!("\\&{s}")
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every page's SYNOPSIS names the values of each flag that takes one (`--ocio CONFIG`,
    /// `--tile W H`), as its OPTIONS do: a flag shown bare reads as a switch.
    #[test]
    fn every_synopsis_names_the_values() {
        let mut checked = 0;
        for (name, page) in crate::man_pages() {
            let page = String::from_utf8(page).unwrap();
            let synopsis = page
                .split(".SH SYNOPSIS\n")
                .nth(1)
                .and_then(|s| s.lines().next())
                .unwrap_or_else(|| panic!("{name}: no SYNOPSIS"));
            let mut cmd = Cli::command();
            cmd.build();
            // The page's command: `specconv-farm-submit.1` is farm's submit.
            let path: Vec<&str> = name.trim_end_matches(".1").split('-').skip(1).collect();
            let mut sub = &cmd;
            for part in &path {
                sub = match sub.find_subcommand(part) {
                    Some(s) => s,
                    // A command whose name has a hyphen (`to-rgb`).
                    None => sub.find_subcommand(path.join("-")).unwrap_or(sub),
                };
            }
            for a in sub.get_arguments().filter(|a| !a.is_hide_set()) {
                let (Some(long), Some(values)) = (a.get_long(), a.get_value_names()) else {
                    continue;
                };
                if a.is_positional() || !a.get_num_args().unwrap().takes_values() {
                    continue;
                }
                let shown = format!("\\fB{}\\fR", escape(&format!("--{long}")));
                let at = synopsis
                    .find(&shown)
                    .unwrap_or_else(|| panic!("{name}: --{long} not in {synopsis}"));
                let after = &synopsis[at + shown.len()..];
                let value = format!("\\fI{}\\fR", escape(values[0].as_str()));
                assert!(
                    after
                        .trim_start_matches([' ', '[', '='])
                        .starts_with(&value),
                    "{name}: --{long} has no {} in the synopsis: {}",
                    values[0],
                    &after[..after.len().min(60)]
                );
                checked += 1;
            }
        }
        assert!(checked > 60, "{checked} flags checked");
    }
}
