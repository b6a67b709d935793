//! Across the C shim of `oiio-sys`: its messages and strings copied out, paths made C strings,
//! and the version of the OpenImageIO it loaded.

use std::ffi::{CStr, CString};
use std::path::Path;

use oiio_sys as sys;

use crate::LoadError;

/// The shim's message for the last failure on this thread.
pub(crate) fn last_error(shim: &sys::SpecconvOiio) -> String {
    // SAFETY: the shim returns a NUL-terminated thread-local string, valid until the next
    // shim call on this thread; it is copied at once.
    unsafe { CStr::from_ptr(shim.specconv_oiio_last_error()) }
        .to_string_lossy()
        .trim()
        .to_owned()
}

/// Borrows a NUL-terminated string that the shim keeps alive as long as the input.
pub(crate) fn shim_str(ptr: *const std::os::raw::c_char) -> String {
    if ptr.is_null() {
        return String::new();
    }
    // SAFETY: non-null pointers from the shim point at NUL-terminated strings owned by an
    // open input, which outlives this call; the contents are copied.
    unsafe { CStr::from_ptr(ptr) }
        .to_string_lossy()
        .into_owned()
}

#[cfg(unix)]
pub(crate) fn path_to_cstring(path: &Path) -> Option<CString> {
    use std::os::unix::ffi::OsStrExt;
    CString::new(path.as_os_str().as_bytes()).ok()
}

#[cfg(not(unix))]
pub(crate) fn path_to_cstring(path: &Path) -> Option<CString> {
    CString::new(path.to_str()?).ok()
}

/// Runtime OpenImageIO version as (major, minor, patch); loads OpenImageIO if no image has
/// been opened yet.
pub fn oiio_version() -> Result<(u32, u32, u32), LoadError> {
    let shim = sys::shim()?;
    // SAFETY: a plain query without arguments.
    let v = unsafe { shim.specconv_oiio_version() }.max(0) as u32;
    Ok((v / 10000, v / 100 % 100, v % 100))
}
