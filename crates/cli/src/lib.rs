//! The specconv command line. It parses, dispatches and reports; the work happens in the
//! library crates. Every error is printed once as `specconv: error: …` with its causes, and the
//! exit code says how it went: 0 all done, 1 something failed, 2 usage error.
#![forbid(unsafe_code)]

use clap::{CommandFactory, Parser, Subcommand};
use std::io::Write;

mod cmd;
mod files;
mod font;
mod methods;
mod picture;
mod plot;
mod swatches;

/// Turn textures in any colour space into spectral reflectance images, with the clustered-PCA
/// uplift of Otsu, Yamamoto and Hachisuka 2018.
///
/// `specconv [OPTIONS] INPUT OUTPUT` converts a texture (see `specconv convert --help`); the
/// other commands train and evaluate models and inspect files and colour configs.
#[derive(Debug, Parser)]
#[command(
    name = "specconv",
    version,
    max_term_width = 100,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    convert: cmd::convert::Args,
}

#[derive(Debug, Subcommand)]
enum Command {
    Convert(cmd::convert::Args),
    Train(cmd::train::Args),
    Eval(cmd::eval::Args),
    Report(cmd::report::Args),
    Info(cmd::info::Args),
    Colorspaces(cmd::colorspaces::Args),
    ToRgb(cmd::to_rgb::Args),
    Completions(cmd::completions::Args),
    Simulate(cmd::simulate::Args),
    Preview(cmd::preview::Args),
}

/// Runs the command line and returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    let result = match cli.command {
        None => cmd::convert::run(cli.convert),
        Some(Command::Convert(args)) => cmd::convert::run(args),
        Some(command) => run(command).map(|()| 0),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            report(&e);
            1
        }
    }
}

fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Convert(_) => unreachable!("dispatched above"),
        Command::Train(args) => cmd::train::run(args),
        Command::Eval(args) => cmd::eval::run(args),
        Command::Report(args) => cmd::report::run(args),
        Command::Info(args) => cmd::info::run(args),
        Command::Colorspaces(args) => cmd::colorspaces::run(args),
        Command::ToRgb(args) => cmd::to_rgb::run(args),
        Command::Completions(args) => cmd::completions::run(args),
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Preview(args) => cmd::preview::run(args),
    }
}

/// Prints an error with its chain of causes on one line each.
fn report(e: &anyhow::Error) {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "specconv: error: {e}");
    for cause in e.chain().skip(1) {
        let _ = writeln!(err, "  caused by: {cause}");
    }
}

/// The man page, generated from the clap definitions (man/specconv.1 is checked against it).
pub fn man_page() -> Vec<u8> {
    let mut out = Vec::new();
    clap_mangen::Man::new(Cli::command())
        .render(&mut out)
        .expect("rendering to memory cannot fail");
    for sub in Cli::command().get_subcommands() {
        let name = format!("specconv-{}", sub.get_name());
        let sub = sub.clone().name(name);
        clap_mangen::Man::new(sub)
            .render(&mut out)
            .expect("rendering to memory cannot fail");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    /// Regenerate with `SPECCONV_UPDATE_MAN=1 cargo test -p specconv-cli man_page`.
    #[test]
    fn man_page_matches_the_cli() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../man/specconv.1");
        let page = man_page();
        if std::env::var_os("SPECCONV_UPDATE_MAN").is_some() {
            std::fs::write(path, &page).unwrap();
        }
        let committed = std::fs::read(path).unwrap_or_default();
        assert!(
            committed == page,
            "man/specconv.1 is out of date: run SPECCONV_UPDATE_MAN=1 cargo test -p specconv-cli man_page"
        );
    }
}
