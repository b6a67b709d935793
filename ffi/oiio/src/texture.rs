//! A tiled, MIP-mapped OpenEXR texture written through OpenImageIO's `make_texture`.

use std::ffi::CString;
use std::path::Path;

use oiio_sys as sys;

use crate::error::{Error, Result};
use crate::shim::{last_error, path_to_cstring};

/// How [`make_texture`] stores the texture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextureSpec {
    /// The subimage of the input to write through.
    pub subimage: u32,
    /// Tile width and height.
    pub tile: (u32, u32),
    /// OpenEXR compression, as OpenImageIO names it (`zip`, `piz`, …).
    pub compression: String,
    /// String attributes added to the header.
    pub attributes: Vec<(String, String)>,
}

/// Writes `input` through, its values unconverted, as a tiled, MIP-mapped OpenEXR texture at
/// `output` with OpenImageIO's `ImageBufAlgo::make_texture` (what maketx runs): box-filtered
/// levels, the input's metadata and wrap modes kept, `spec`'s attributes added. OpenImageIO
/// writes its own temporary beside `output` (`output`'s extension replaced by
/// `.XXXXXXXX.temp` and the extension) and renames it over `output`, so `output` should be a
/// temporary path of the caller's, published when this returns.
pub fn make_texture(input: &Path, output: &Path, spec: &TextureSpec) -> Result<()> {
    let path = input.to_path_buf();
    let refuse = |message: &str| Error::InvalidRequest {
        path: path.clone(),
        message: message.into(),
    };
    let (Some(c_in), Some(c_out)) = (path_to_cstring(input), path_to_cstring(output)) else {
        return Err(refuse("the path contains a NUL byte"));
    };
    let c_compression =
        CString::new(spec.compression.as_str()).map_err(|_| refuse("bad compression"))?;
    let mut names = Vec::new();
    let mut values = Vec::new();
    for (k, v) in &spec.attributes {
        names.push(CString::new(k.as_str()).map_err(|_| refuse("an attribute holds a NUL byte"))?);
        values.push(CString::new(v.as_str()).map_err(|_| refuse("an attribute holds a NUL byte"))?);
    }
    let name_ptrs: Vec<*const std::os::raw::c_char> = names.iter().map(|c| c.as_ptr()).collect();
    let value_ptrs: Vec<*const std::os::raw::c_char> = values.iter().map(|c| c.as_ptr()).collect();
    let shim = sys::shim().map_err(|source| Error::Unavailable {
        path: path.clone(),
        source,
    })?;
    let to_i32 = |v: u32| i32::try_from(v).map_err(|_| refuse("tile or subimage out of range"));
    // SAFETY: every pointer is a valid C string, or an array of `count` of them, alive for
    // the call; the shim copies what it keeps.
    let status = unsafe {
        shim.specconv_oiio_make_texture(
            c_in.as_ptr(),
            to_i32(spec.subimage)?,
            c_out.as_ptr(),
            to_i32(spec.tile.0)?,
            to_i32(spec.tile.1)?,
            c_compression.as_ptr(),
            name_ptrs.as_ptr(),
            value_ptrs.as_ptr(),
            name_ptrs.len(),
        )
    } as u32;
    match status {
        sys::SPECCONV_OIIO_OK => Ok(()),
        sys::SPECCONV_OIIO_ERR_ARGUMENT => Err(refuse(&last_error(shim))),
        sys::SPECCONV_OIIO_ERR_READ => Err(Error::Read {
            path,
            message: last_error(shim),
        }),
        _ => Err(Error::Internal {
            path,
            message: last_error(shim),
        }),
    }
}
