//! The specconv command line. It parses, dispatches and reports; the work happens in the
//! library crates. Every error of every command is printed as one line,
//! `specconv: error: WHAT: CAUSE: …`, each cause once, and the exit status is one of [`exit`]'s.
#![forbid(unsafe_code)]

use clap::{CommandFactory, Parser, Subcommand};

#[macro_use]
mod stdio;
mod checks;
mod cmd;
#[cfg(test)]
mod doc_flags;
mod files;
pub mod generated;
mod man;
mod methods;
mod options;
mod picture;
mod progress;
mod records;
mod shard;
mod signals;

/// Turn textures in any colour space into spectral reflectance images, with the clustered-PCA
/// uplift of Otsu, Yamamoto and Hachisuka 2018.
///
/// `specconv [OPTIONS] INPUT OUTPUT` converts a texture (see `specconv convert --help`); the
/// other commands train and evaluate models and inspect files and colour configs.
#[derive(Debug, Parser)]
#[command(
    name = "specconv",
    version = version(),
    max_term_width = 100,
    subcommand_negates_reqs = true,
    after_long_help = EXAMPLES
)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    global: Global,
    #[command(flatten)]
    convert: cmd::convert::Args,
}

/// `--version` (and `-V`): one line ([`cmd::models::version_line`]).
fn version() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(cmd::models::version_line)
}

/// Options every command takes, before or after the subcommand's name.
#[derive(Debug, clap::Args)]
struct Global {
    // Its help is the library's; global: before or after the subcommand.
    #[arg(
        long,
        global = true,
        value_name = "CONFIG",
        visible_aliases = specconv_conversion::Key::Ocio.about().flags[0].aliases.iter().copied(),
        help = specconv_conversion::Key::Ocio.about().help
    )]
    ocio: Option<String>,
}

/// The exit statuses of every command (README "Exit status", man pages' EXIT STATUS).
pub mod exit {
    /// Everything asked for was done (in a batch: converted or up to date).
    pub const OK: i32 = 0;
    /// Something the command read or wrote failed (in a batch: at least one input; the
    /// others were still converted).
    pub const FAILED: i32 = 1;
    /// The command line cannot work for any input: an unknown option or value, a colour
    /// space or OCIO config that cannot be used, a missing output directory, a model that
    /// cannot be read. Checked before the first input; nothing was written.
    pub const USAGE: i32 = 2;
    /// Stopped by SIGINT or SIGTERM; no partial output was left.
    pub const INTERRUPTED: i32 = 130;
    /// Standard output was closed before the command was done (`| head -1`): 128 + SIGPIPE,
    /// what a shell reports for a process SIGPIPE killed. The input being converted was
    /// finished or left as it was; no other was started.
    pub const PIPE: i32 = 141;
    /// The table as the README and the man pages print it.
    pub const TABLE: [(i32, &str); 5] = [
        (OK, "everything asked for was done (in a batch: every input converted, up to date, or a data texture skipped or written through by --data)"),
        (
            FAILED,
            "an input, output or other file failed (in a batch: at least one input failed; the others were converted)",
        ),
        (
            USAGE,
            "the command line cannot work for any input: an unknown option or value, a colour space or OCIO config that cannot be used, a missing output directory, an unreadable model; checked before the first input, nothing written",
        ),
        (INTERRUPTED, "interrupted by SIGINT or SIGTERM; no partial output left"),
        (
            PIPE,
            "standard output was closed (a reader such as `head` stopped reading): the command stopped quietly; the input being converted was finished or left as it was, no other was started",
        ),
    ];
}

/// An error in how the command was asked for, which no input can fix: exit status 2.
#[derive(Debug)]
pub(crate) struct Usage(pub String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// Turns any error into a usage error (exit status 2), keeping its one-line text.
pub(crate) fn usage(e: impl Into<anyhow::Error>) -> anyhow::Error {
    Usage(one_line(e.into().as_ref())).into()
}

/// An error and its causes on one line, `WHAT: CAUSE: …`, each said once: a cause whose text
/// the line already holds is left out (wrappers that display their source would repeat it);
/// a cause's leading `NAME: ` is left out when the line ends with NAME (`cannot read F` and
/// `F: no such file` make `cannot read F: no such file`); and a cause that names what the
/// line's last part ends with replaces that part (`cannot read F` and `F is not a spectral
/// EXR` make `F is not a spectral EXR`).
pub(crate) fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let hint = std::iter::successors(Some(e), |c| c.source()).find_map(hint);
    specconv_conversion::message(e) + hint.as_deref().unwrap_or_default()
}

/// A library error as the command line says it: [`one_line`] (with the option that would fix
/// it), or for the errors of one option, that option's own words.
pub(crate) fn explain(e: &specconv_conversion::Error) -> String {
    use specconv_conversion::Error;
    match e {
        Error::ZipLevelWithoutZip { compression } => format!(
            "--zip-level sets the deflate level of zip and zips; --compression {compression} \
             has none (drop --zip-level or use --compression zip)"
        ),
        Error::EmptyTile { width, height } => {
            format!("--tile {width} {height}: tiles must be at least 1×1")
        }
        Error::NoThreads => "-j/--threads must be at least 1".into(),
        _ => one_line(e),
    }
}

/// What to pass to fix a cause, in this program's flags: the libraries say which setting
/// ([`specconv_conversion::remedy_of`]: a [`specconv_conversion::Remedy`] and its options),
/// the command line names each option by its flag ([`flag`]).
fn hint(cause: &(dyn std::error::Error + 'static)) -> Option<String> {
    use specconv_conversion::{Key, Remedy};
    let remedy = specconv_conversion::remedy_of(cause)?;
    let f = flag;
    Some(match remedy {
        Remedy::RepairNonFinite => format!(
            "; repair them with {0} box3 (or black), or write them as they are with {0} {1}",
            f(Key::NonFinite),
            specconv_conversion::Named::name(specconv_conversion::NonFinite::Keep)
        ),
        Remedy::RepairBlack => format!("; repair them with {} black", f(Key::NonFinite)),
        Remedy::ReplaceOrSkip => format!(
            "; pass {} to replace it (or -u to skip outputs that are up to date)",
            f(Key::Overwrite)
        ),
        Remedy::Replace => format!("; pass {} to replace it", f(Key::Overwrite)),
        Remedy::NameColourSpace => format!("; pass {}", f(Key::Colorspace)),
        Remedy::NameEncodingColourSpace => format!(
            "; pass {} with the colour space the texture is encoded in",
            f(Key::Colorspace)
        ),
        Remedy::NameChannelsOrLayer => format!(
            "; choose with {0} LAYER or {0} NAME,NAME,NAME",
            f(Key::Channels)
        ),
        Remedy::NameLayer => format!("; choose one with {} LAYER", f(Key::Channels)),
        // to-rgb's and preview's option, not a conversion's.
        Remedy::DropIlluminant => "; drop --illuminant".into(),
        // Output naming, the command line's own.
        Remedy::TileTemplate => ", or use --output-template with {udim}".into(),
        Remedy::AlreadySpectral => format!(
            "; use it as it is (`specconv info` shows its bands), `specconv to-rgb` gives its \
             colour, and converting its colour source with {} START:END:STEP gives another grid \
             ({} R,G,B reads a colour preview it holds instead)",
            f(Key::Bands),
            f(Key::Channels)
        ),
        Remedy::ExpandCompact => format!(
            "; `specconv expand` writes its spectra as a spectral OpenEXR ({} R,G,B reads its \
             colour as an image instead)",
            f(Key::Channels)
        ),
        Remedy::DataTexture => format!(
            "; {0} skip leaves it out, {0} copy writes it through as a data texture, and {1} \
             NAME reads it as colour if it is one",
            f(Key::Data),
            f(Key::Colorspace)
        ),
        Remedy::FewerThreads => format!("; lower {}", f(Key::Threads)),
        Remedy::SmallerBlocks | Remedy::LessMemory | Remedy::FewerBands => {
            let flags: Vec<String> = remedy.keys().iter().map(|&k| f(k)).collect();
            format!(" ({})", flags.join(", "))
        }
        Remedy::BandsInside { start, end, step } => format!(
            "; choose bands inside that range (e.g. {} {start}:{end}:{step})",
            f(Key::Bands)
        ),
        Remedy::ZipLevelInRange => format!("; give {} 0 to 9", f(Key::ZipLevel)),
        // A training setting, not a conversion's.
        Remedy::OneClusterModel => " (`specconv train --clusters 1`)".into(),
        // [`explain`] words these errors whole, in the option's own terms.
        Remedy::DropZipLevel | Remedy::NonEmptyTiles | Remedy::SomeThreads => return None,
        _ => return None,
    })
}

/// How the command line spells an option: its first flag as `convert` defines it, with its
/// short form and the names of its values where it takes several (`-j/--threads`,
/// `--tile W H`, `--fixnan`).
fn flag(key: specconv_conversion::Key) -> String {
    use specconv_conversion::Takes;
    let Some(first) = key.about().flags.first() else {
        return String::new();
    };
    let long = format!("--{}", first.long);
    let named = match first.short {
        Some(short) => format!("-{short}/{long}"),
        None => long,
    };
    match first.takes {
        Takes::Pair(a, b) => format!("{named} {a} {b}"),
        _ => named,
    }
}

/// Examples of `specconv --help` and of man/specconv.1.
const EXAMPLES: &str = "\
Examples:
  specconv albedo.tx albedo_spectral.exr
  specconv --ocio aces textures/*.tx -o spectral
  find textures -name '*.tx' | specconv - -o spectral --json > convert.jsonl
  specconv --ocio studio.ocio colorspaces
  specconv info --json textures/*.tx
";

// Each command's examples end its `--help` and make its man page's EXAMPLES.
#[derive(Debug, Subcommand)]
enum Command {
    #[command(after_long_help = cmd::convert::EXAMPLES)]
    Convert(cmd::convert::Args),
    #[command(after_long_help = cmd::train::EXAMPLES)]
    Train(cmd::train::Args),
    #[command(after_long_help = cmd::eval::EXAMPLES)]
    Eval(cmd::eval::Args),
    #[command(after_long_help = cmd::report::EXAMPLES)]
    Report(cmd::report::Args),
    #[command(after_long_help = cmd::info::EXAMPLES)]
    Info(cmd::info::Args),
    #[command(after_long_help = cmd::colorspaces::EXAMPLES)]
    Colorspaces(cmd::colorspaces::Args),
    #[command(after_long_help = cmd::to_rgb::EXAMPLES)]
    ToRgb(cmd::to_rgb::Args),
    #[command(after_long_help = cmd::expand::EXAMPLES)]
    Expand(cmd::expand::Args),
    #[command(after_long_help = cmd::models::EXAMPLES)]
    Models(cmd::models::Args),
    #[command(after_long_help = cmd::completions::EXAMPLES)]
    Completions(cmd::completions::Args),
    #[command(after_long_help = cmd::simulate::EXAMPLES)]
    Simulate(cmd::simulate::Args),
    #[command(after_long_help = cmd::preview::EXAMPLES)]
    Preview(cmd::preview::Args),
    #[command(after_long_help = cmd::farm::EXAMPLES, disable_help_subcommand = true)]
    Farm(cmd::farm::Args),
    #[command(after_long_help = cmd::asset::EXAMPLES)]
    Asset(cmd::asset::Args),
}

/// Runs the command line and returns the process exit code.
pub fn main() -> i32 {
    // First: from here on, SIGINT and SIGTERM end every command with status 130.
    signals::install();
    let cli = match parse(std::env::args_os()) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            return match e.print() {
                Ok(()) => exit::OK,
                Err(e) => failed(stdio::StdoutFailed::new(e).into()),
            };
        }
        Err(e) => {
            print_error(&clap_error_line(&e));
            return exit::USAGE;
        }
    };
    let code = run(cli).unwrap_or_else(failed);
    // An interrupted copy may leave its abandoned thread inside OpenImageIO: the libraries'
    // static destructors would wait for it (or crash under it). Everything is said (each
    // write is flushed) and removed by now; end at once, as the signal handler does.
    if code == exit::INTERRUPTED {
        specconv_conversion::exit_now(code)
    }
    code
}

/// Says why a command failed, once, and returns its exit status. A closed standard output
/// says nothing: the reader has gone.
fn failed(e: anyhow::Error) -> i32 {
    if let Some(out) = stdio::StdoutFailed::in_chain(&e) {
        if !out.closed() {
            print_error(&out.to_string());
        }
        return out.status();
    }
    print_error(&one_line(e.as_ref()));
    if e.chain().any(|c| c.is::<signals::Interrupted>()) {
        exit::INTERRUPTED
    } else if e.chain().any(|c| c.is::<Usage>()) {
        exit::USAGE
    } else {
        exit::FAILED
    }
}

/// Parses the command line. Global options (--ocio) go before or after the subcommand; the
/// conversion's options without a subcommand are refused with one.
fn parse(args: impl IntoIterator<Item = std::ffi::OsString>) -> Result<Cli, clap::Error> {
    use clap::FromArgMatches;
    let mut command = Cli::command();
    let matches = command.try_get_matches_from_mut(args)?;
    if let Some((name, _)) = matches.subcommand() {
        let stray = command.get_arguments().find(|a| {
            !a.is_global_set()
                && matches.value_source(a.get_id().as_str())
                    == Some(clap::parser::ValueSource::CommandLine)
        });
        if let Some(id) = stray.map(|a| a.get_id().to_string()) {
            return Err(command.error(
                clap::error::ErrorKind::ArgumentConflict,
                format!(
                    "the conversion's option '{id}' was given before the subcommand '{name}'; \
                     put it after `specconv convert`, or give no subcommand"
                ),
            ));
        }
    }
    Cli::from_arg_matches(&matches).map_err(|e| e.format(&mut command))
}

/// A command-line error from clap as one line: its message, value lists and tips, without
/// the usage block (`--help` shows it).
fn clap_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut parts = Vec::new();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    while let Some(line) = lines.next() {
        if line.starts_with("Usage:") {
            // The usage block runs to the next blank line, already dropped; skip its lines.
            for next in lines.by_ref() {
                if next.starts_with("For more information") {
                    parts.push(next.to_string());
                    break;
                }
            }
            continue;
        }
        parts.push(line.strip_prefix("error: ").unwrap_or(line).to_string());
    }
    parts.join("; ")
}

/// Dispatches to the command; `Ok` holds the exit status of commands that decide it
/// themselves (a batch where some inputs failed).
fn run(cli: Cli) -> anyhow::Result<i32> {
    let ocio = cli.global.ocio;
    let done = |r: anyhow::Result<()>| r.map(|()| exit::OK);
    // --ocio is global; the commands that use it hold it as a field clap skips.
    macro_rules! with_ocio {
        ($args:expr) => {{
            let mut args = $args;
            args.ocio = ocio;
            args
        }};
    }
    match cli.command {
        None => cmd::convert::run(with_ocio!(cli.convert)),
        Some(Command::Convert(args)) => cmd::convert::run(with_ocio!(args)),
        Some(Command::Train(args)) => done(cmd::train::run(args)),
        Some(Command::Eval(args)) => done(cmd::eval::run(args)),
        Some(Command::Report(args)) => done(cmd::report::run(args)),
        Some(Command::Info(args)) => cmd::info::run(with_ocio!(args)),
        Some(Command::Colorspaces(args)) => done(cmd::colorspaces::run(with_ocio!(args))),
        Some(Command::ToRgb(args)) => done(cmd::to_rgb::run(with_ocio!(args))),
        Some(Command::Expand(args)) => cmd::expand::run(args),
        Some(Command::Models(args)) => done(cmd::models::run(args)),
        Some(Command::Completions(args)) => done(cmd::completions::run(args)),
        Some(Command::Simulate(args)) => done(cmd::simulate::run(args)),
        Some(Command::Preview(args)) => done(cmd::preview::run(args)),
        Some(Command::Farm(args)) => cmd::farm::run(args, ocio),
        Some(Command::Asset(args)) => cmd::asset::run(with_ocio!(args)),
    }
}

/// The one error format of every command: `specconv: error: ` and one line.
pub(crate) fn print_error(line: &str) {
    // A file name in it cannot make it pass for other lines.
    errln!(
        "specconv: error: {}",
        specconv_atomic_file::shown::escaped(line)
    );
}

/// The man pages, one per command: (file name in man/, roff).
pub fn man_pages() -> Vec<(String, Vec<u8>)> {
    man::pages()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_of_several_lines_is_one() {
        let e = std::io::Error::other("TOML parse error at line 1, column 5\n  |\n1 | a = \n  |     ^\nstring values must be quoted\n");
        assert_eq!(
            one_line(&e),
            "TOML parse error at line 1, column 5; string values must be quoted"
        );
    }

    #[test]
    fn options_are_spelt_by_their_flags() {
        use specconv_conversion::Key;
        assert_eq!(flag(Key::Threads), "-j/--threads");
        assert_eq!(flag(Key::Tile), "--tile W H");
        assert_eq!(flag(Key::Overwrite), "--force");
        assert_eq!(flag(Key::NonFinite), "--fixnan");
        // Every option the command line has a flag for is spelt by one it accepts.
        for key in Key::ALL {
            let Some(long) = key.about().flags.first() else {
                continue;
            };
            assert!(flag(key).contains(&format!("--{}", long.long)), "{key:?}");
        }
    }

    #[test]
    fn the_remedies_of_the_library_are_said_in_flags() {
        use specconv_conversion::Error;
        let said = |e: &(dyn std::error::Error + 'static)| one_line(e);
        let threads = Error::TooManyThreads {
            threads: 9,
            limit: 8,
            cores: 2,
        };
        assert!(
            said(&threads).ends_with("; lower -j/--threads"),
            "{}",
            said(&threads)
        );
        let memory = Error::TooMuchMemory {
            needed: 1 << 40,
            have: 1 << 30,
        };
        assert!(said(&memory).ends_with(" (--bands, --tile W H, -j/--threads)"));
        let grid = specconv_colour::Error::NotCovered {
            what: "the cie1931 observer".into(),
            first: 360.0,
            last: 830.0,
            grid: "300:700:10".parse().unwrap(),
        };
        assert!(
            said(&grid).ends_with("; choose bands inside that range (e.g. --bands 360:700:10)"),
            "{}",
            said(&grid)
        );
        let pca = specconv_spectral::Error::NeedsOneCluster { clusters: 8 };
        assert!(said(&pca).ends_with(" (`specconv train --clusters 1`)"));
        // Errors whose whole message the command line words itself take no hint.
        assert_eq!(said(&Error::NoThreads), Error::NoThreads.to_string());
        assert_eq!(
            explain(&Error::NoThreads),
            "-j/--threads must be at least 1"
        );
    }

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn errors_read_as_one_line_with_each_cause_once() {
        let e = anyhow::anyhow!("/t/a.exr: no such file").context("cannot read /t/a.exr");
        assert_eq!(one_line(e.as_ref()), "cannot read /t/a.exr: no such file");
        let e = anyhow::anyhow!("/t/a.exr is not a spectral EXR").context("cannot read /t/a.exr");
        assert_eq!(one_line(e.as_ref()), "/t/a.exr is not a spectral EXR");
        let e = anyhow::anyhow!("OpenEXR: truncated")
            .context("cannot read /t/a.exr")
            .context("patch 2");
        assert_eq!(
            one_line(e.as_ref()),
            "patch 2: cannot read /t/a.exr: OpenEXR: truncated"
        );
        // A word is not a file name: `patch tex` and `cannot read the texture…` both stay.
        let e = anyhow::anyhow!("/t/a.png: no such file")
            .context("cannot read the texture /t/a.png")
            .context("patch tex");
        assert_eq!(
            one_line(e.as_ref()),
            "patch tex: cannot read the texture /t/a.png: no such file"
        );
        // A wrapper that displays its source (thiserror's `#[error("{0}")]` with `#[from]`).
        #[derive(Debug)]
        struct Wrap(std::io::Error);
        impl std::fmt::Display for Wrap {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                self.0.fmt(f)
            }
        }
        impl std::error::Error for Wrap {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.0)
            }
        }
        let e =
            anyhow::Error::new(Wrap(std::io::Error::other("disk full"))).context("cannot write x");
        assert_eq!(one_line(e.as_ref()), "cannot write x: disk full");
        let u = usage(e);
        assert!(u.is::<Usage>());
        assert_eq!(u.to_string(), "cannot write x: disk full");
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
                crate::parse(words.iter().map(std::ffi::OsString::from))
                    .unwrap_or_else(|e| panic!("{line}: {}", crate::clap_error_line(&e)));
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
