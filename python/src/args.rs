//! Arguments as Python passes them, turned into the library's types with this package's
//! errors: paths as `os.fspath` gives them (str, bytes or `os.PathLike`), and whole numbers
//! of any sign read as Python ints so that a negative count is an `OptionError` that names its
//! keyword, not an `OverflowError` of the conversion to an unsigned type.

use crate::errors::Kind;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::PathBuf;

/// A path: a `str`, `bytes` (a file name in the file system's encoding, any bytes on Unix) or
/// an `os.PathLike` of either, as `os.fspath` reads it.
#[derive(Debug, Clone)]
pub struct FsPath(pub PathBuf);

impl<'a, 'py> FromPyObject<'a, 'py> for FsPath {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        use std::os::unix::ffi::OsStrExt;
        let py = ob.py();
        let path = py
            .import("os")?
            .call_method1("fspath", (ob,))
            .map_err(|_| {
                let type_name = ob
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".to_string(), |n| n.to_string());
                Kind::Option.err(format!(
                    "a path is a str, bytes or os.PathLike, not {type_name}"
                ))
            })?;
        if let Ok(bytes) = path.cast::<PyBytes>() {
            return Ok(FsPath(std::ffi::OsStr::from_bytes(bytes.as_bytes()).into()));
        }
        // A str: encoded as the file system encodes names (surrogate escapes kept).
        let encoded = py
            .import("os")?
            .call_method1("fsencode", (path,))?
            .cast_into::<PyBytes>()?;
        Ok(FsPath(
            std::ffi::OsStr::from_bytes(encoded.as_bytes()).into(),
        ))
    }
}

impl From<FsPath> for PathBuf {
    fn from(p: FsPath) -> PathBuf {
        p.0
    }
}

/// A whole number for the keyword `keyword` as the type the library counts it in: a negative
/// value, or one beyond the type, is an `OptionError` that says what the keyword takes.
pub fn whole<T: TryFrom<i128> + Copy + std::fmt::Display>(
    keyword: &str,
    value: i128,
    largest: T,
) -> PyResult<T> {
    T::try_from(value).map_err(|_| {
        Kind::Option.err(format!(
            "{keyword} must be a whole number from 0 to {largest}, not {value}"
        ))
    })
}
