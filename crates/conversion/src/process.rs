//! What a front-end does to its process around the C++ libraries: writes past the file size
//! limit made errors, the process ended at once, cancelled copies waited for.

use crate::pipeline;

/// Makes writes past the file size limit (`ulimit -f`) fail with an error the writer reports,
/// its temporary file removed, instead of SIGXFSZ killing the process: for a program's first
/// step (Python ignores SIGXFSZ already).
pub fn ignore_file_size_signal() {
    specconv_oiio::ignore_file_size_signal()
}

/// Ends the process at once with `code`, without exit handlers or C++ static destructors: for
/// a signal handler's thread while OpenImageIO or OpenColorIO may be in use on another
/// (`std::process::exit` would run their destructors under it: a crash or a hang instead of
/// the exit status).
pub fn exit_now(code: i32) -> ! {
    specconv_oiio::exit_now(code)
}

/// Waits, at most `timeout`, for what cancelled data copies left running inside OpenImageIO
/// (a copy returns within 20 ms of its cancel flag; its writer cannot be stopped midway and
/// removes its files when it ends); whether nothing runs now. A front-end that ends the
/// process with `exit` rather than [`exit_now`] (Python) calls it first: the libraries' static
/// destructors must not run under a writer.
pub fn settle_copies(timeout: std::time::Duration) -> bool {
    pipeline::data::settle(timeout)
}
