//! Data textures written through ([`copy`]): a texture that holds numbers (a roughness or
//! normal map, [`crate::colour::DataTexture`]) is never uplifted; asked to, it is written as
//! the tiled, MIP-mapped OpenEXR texture maketx would make of it, its values unconverted.

use super::{Error, Result};
use specconv_atomic_file::Replace;
use specconv_oiio::TextureSpec;
use std::path::Path;

/// How [`copy`] writes.
#[derive(Debug, Clone)]
pub struct Copy<'a> {
    /// The subimage of the input to write through.
    pub subimage: u32,
    /// Tile width and height.
    pub tile: (u32, u32),
    /// OpenEXR compression, as OpenImageIO names it.
    pub compression: &'a str,
    /// Replace an existing output.
    pub overwrite: bool,
    /// Attributes recorded in the output (the caller's provenance).
    pub attributes: &'a [(String, String)],
}

/// Writes `input` through to `output` as a tiled, MIP-mapped data texture with OpenImageIO's
/// `make_texture` (box-filtered levels, the input's metadata and wrap modes kept), through a
/// temporary published only when complete; never over the input. Returns the levels written.
pub fn copy(input: &Path, output: &Path, how: &Copy) -> Result<usize> {
    specconv_atomic_file::readable_file(input)?;
    specconv_atomic_file::check_plan(&[input], &[output], Replace::when(how.overwrite))?;
    let io = |source| Error::Io {
        path: output.to_path_buf(),
        source,
    };
    let mut pending = specconv_atomic_file::Pending::beside(output).map_err(io)?;
    let spec = TextureSpec {
        subimage: how.subimage,
        tile: how.tile,
        compression: how.compression.to_owned(),
        attributes: how.attributes.to_vec(),
    };
    // OpenImageIO writes its own temporary and renames it over the path it is given: a path
    // of the pending file's, which stays locked until the result is published.
    let written = pending.path_for_writer().to_path_buf();
    specconv_oiio::make_texture(input, &written, &spec)?;
    let levels = specconv_oiio::ImageReader::open(&written)?
        .info()
        .levels
        .len();
    pending.publish(Replace::when(how.overwrite)).map_err(io)?;
    Ok(levels)
}
