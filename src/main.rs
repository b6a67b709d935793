//! The `specconv` binary: everything lives in `specconv-cli`; this only hands over the exit code,
//! ending the process without the C++ libraries' exit-time destructors ([`specconv_oiio::exit`]).
fn main() {
    specconv_oiio::exit(specconv_cli::main());
}
