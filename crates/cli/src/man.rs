//! Man pages, one per command, generated from the clap definitions with clap_mangen: NAME,
//! SYNOPSIS, DESCRIPTION and OPTIONS from clap; EXAMPLES from each command's `after_long_help`
//! (which `--help` shows too); EXIT STATUS from [`crate::exit::TABLE`]; ENVIRONMENT from
//! [`ENVIRONMENT`]; SEE ALSO naming the other pages. man/ holds them; a test checks for drift.

use crate::Cli;
use clap::CommandFactory;

/// Every environment variable the program reads, and what for.
pub const ENVIRONMENT: [(&str, &str); 9] = [
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
    render(&mut out, &|w| man.render_synopsis_section(w));
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
    for (code, meaning) in crate::exit::TABLE {
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
