//! The `specconv` binary: everything lives in `specconv-cli`; this only hands over the exit code.
fn main() {
    std::process::exit(specconv_cli::main());
}
