//! Strings across the C shim of `ocio-sys`: its last error, strings a config owns, arguments
//! made C strings, and OpenColorIO's log.

use std::ffi::{CStr, CString};

use ocio_sys as sys;

use crate::error::{Error, Result};

pub(crate) fn last_error() -> String {
    // SAFETY: a NUL-terminated thread-local string, valid until the next shim call on this
    // thread; copied at once.
    unsafe { CStr::from_ptr(sys::specconv_ocio_last_error()) }
        .to_string_lossy()
        .trim()
        .to_owned()
}

/// Copies a string the config owns (or "" for NULL).
pub(crate) fn config_str(ptr: *const std::os::raw::c_char) -> String {
    if ptr.is_null() {
        return String::new();
    }
    // SAFETY: non-null strings from the shim are NUL-terminated and owned by a config that
    // outlives this call.
    unsafe { CStr::from_ptr(ptr) }
        .to_string_lossy()
        .into_owned()
}

pub(crate) fn cstring(s: &str) -> Result<CString> {
    CString::new(s).map_err(|_| Error::Argument(format!("'{s}' contains a NUL byte")))
}

/// OpenColorIO's log since the last call, one message a line, without OCIO's
/// `[OpenColorIO Warning]: ` prefixes. The shim keeps the log from its first call on, so that
/// nothing of OCIO's reaches standard error unless the caller says it.
pub fn take_log() -> Vec<String> {
    // SAFETY: a NUL-terminated string the shim keeps for this thread until the next call.
    let text = config_str(unsafe { sys::specconv_ocio_take_log() });
    text.lines()
        .map(|l| {
            l.split_once("]: ")
                .filter(|(p, _)| p.starts_with("[OpenColorIO"))
                .map_or(l, |(_, m)| m)
                .to_string()
        })
        .filter(|l| !l.is_empty())
        .collect()
}
