//! `specconv completions SHELL`: shell completion scripts, generated from the clap definitions.

use anyhow::Result;
use specconv_convert_cmd::stdio::out_bytes;
use specconv_flags::defs;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv completions bash > /etc/bash_completion.d/specconv
  specconv completions zsh > ~/.zfunc/_specconv
";

specconv_flags::args! {
    /// Print a shell completion script, e.g. `specconv completions bash > /etc/bash_completion.d/specconv`.
    #[derive(Debug)]
    pub struct Args {
        shell: clap_complete::Shell = (defs::COMPLETIONS_SHELL),
    }
}

/// Prints the script completing `cli` (the command line's definition, handed down by the
/// dispatch that holds it).
pub fn run(args: Args, mut cli: clap::Command) -> Result<()> {
    // Made in memory: clap_complete panics when its writer fails.
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut cli, "specconv", &mut script);
    Ok(out_bytes(&script)?)
}
