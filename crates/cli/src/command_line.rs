//! The command line as clap defines it (the top command, its global options, the commands),
//! parsed and dispatched to each command's `run`.

use crate::cmd;
use clap::{CommandFactory, Parser, Subcommand};
use specconv_convert_cmd::errors::{clap_error_line, one_line, print_error, Usage};
use specconv_convert_cmd::{convert, exit, signals, stdio};
use specconv_farm_cmd as farm;

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
    pub(crate) command: Option<Command>,
    #[command(flatten)]
    global: Global,
    #[command(flatten)]
    pub(crate) convert: convert::Args,
}

/// `--version` (and `-V`): one line ([`cmd::models::version_line`]).
fn version() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(cmd::models::version_line)
}

/// Options every command takes, before or after the subcommand's name: the library's --ocio.
type Global = specconv_flags::OptionArgs<specconv_flags::Configuring>;

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
pub(crate) enum Command {
    #[command(after_long_help = convert::EXAMPLES)]
    Convert(convert::Args),
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
    #[command(after_long_help = farm::EXAMPLES, disable_help_subcommand = true)]
    Farm(farm::Args),
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

/// Parses the command line. Global options (--ocio) go before or after the subcommand; the
/// conversion's options without a subcommand are refused with one.
pub(crate) fn parse(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Result<Cli, clap::Error> {
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

/// Dispatches to the command; `Ok` holds the exit status of commands that decide it
/// themselves (a batch where some inputs failed).
fn run(cli: Cli) -> anyhow::Result<i32> {
    let ocio = cli.global.options.ocio;
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
        None => convert::run(with_ocio!(cli.convert)),
        Some(Command::Convert(args)) => convert::run(with_ocio!(args)),
        Some(Command::Train(args)) => done(cmd::train::run(args)),
        Some(Command::Eval(args)) => done(cmd::eval::run(args)),
        Some(Command::Report(args)) => done(cmd::report::run(args)),
        Some(Command::Info(args)) => cmd::info::run(with_ocio!(args)),
        Some(Command::Colorspaces(args)) => done(cmd::colorspaces::run(with_ocio!(args))),
        Some(Command::ToRgb(args)) => done(cmd::to_rgb::run(with_ocio!(args))),
        Some(Command::Expand(args)) => cmd::expand::run(args),
        Some(Command::Models(args)) => done(cmd::models::run(args)),
        Some(Command::Completions(args)) => done(cmd::completions::run(args, Cli::command())),
        Some(Command::Simulate(args)) => done(cmd::simulate::run(args)),
        Some(Command::Preview(args)) => done(cmd::preview::run(args)),
        Some(Command::Farm(args)) => farm::run(args, ocio),
        Some(Command::Asset(args)) => cmd::asset::run(with_ocio!(args)),
    }
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
