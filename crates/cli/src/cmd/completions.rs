//! `specconv completions SHELL`: shell completion scripts, generated from the clap definitions.

use anyhow::Result;
use clap::CommandFactory;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv completions bash > /etc/bash_completion.d/specconv
  specconv completions zsh > ~/.zfunc/_specconv
";

/// Print a shell completion script, e.g. `specconv completions bash > /etc/bash_completion.d/specconv`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The shell to complete for.
    shell: clap_complete::Shell,
}

pub fn run(args: Args) -> Result<()> {
    // Made in memory: clap_complete panics when its writer fails.
    let mut script = Vec::new();
    clap_complete::generate(
        args.shell,
        &mut crate::command_line::Cli::command(),
        "specconv",
        &mut script,
    );
    Ok(crate::stdio::out_bytes(&script)?)
}
