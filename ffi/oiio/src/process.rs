//! Ending the process around the C++ libraries, and the file size signal: what a program does
//! so that their exit-time destructors and SIGXFSZ do not end it otherwise.

/// Ends the process with `code` once standard output and error are flushed (Rust's streams
/// and every C stream), without running the C++ libraries' exit-time destructors. Debian's
/// OpenImageIO loads log4cplus (through DCMTK), whose thread cleanup at exit
/// (`log4cplus::threadCleanup`) dereferenced null now and then: a refusal that was exit 1
/// ended in SIGSEGV. A command's files are committed or removed before it returns its code,
/// so nothing is left to those destructors.
pub fn exit(code: i32) -> ! {
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let _ = std::io::stderr().flush();
    // SAFETY: fflush(NULL) flushes every open C output stream; _exit then ends the process
    // at once, which is what is wanted.
    unsafe {
        libc::fflush(std::ptr::null_mut());
        libc::_exit(code)
    }
}

/// Ends the process at once with `code`, as `_exit(2)` does: no exit handlers, no C++ static
/// destructors. For the thread of a signal handler: `std::process::exit` would run
/// OpenImageIO's and OpenColorIO's static destructors while another thread may still be inside
/// those libraries (a crash or a hang instead of the exit status).
pub fn exit_now(code: i32) -> ! {
    extern "C" {
        fn _exit(status: std::ffi::c_int) -> !;
    }
    // SAFETY: _exit takes any status, touches no memory of ours and does not return.
    unsafe { _exit(code) }
}

/// Makes a write past the file size limit (`ulimit -f`, which Slurm passes on to its jobs by
/// default) fail with `EFBIG`, which the writer reports and cleans up after, instead of
/// SIGXFSZ ending the process with its temporary file left behind. CPython does the same at
/// start, so the Python package needs no call.
pub fn ignore_file_size_signal() {
    // SAFETY: SIG_IGN installs no code of ours; signal(2) touches no memory of ours.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}
