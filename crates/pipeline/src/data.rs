//! Data textures written through ([`copy`]): a texture that holds numbers (a roughness or
//! normal map, [`crate::colour::DataTexture`]) is never uplifted; asked to, it is written as
//! the tiled, MIP-mapped OpenEXR texture maketx would make of it, its values unconverted.

use crate::{replace_of, Error, Result};
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
    specconv_atomic_file::check_plan(&[input], &[output], replace_of(how.overwrite))?;
    let io = |source| Error::Io {
        path: output.to_path_buf(),
        source,
    };
    let pending = specconv_atomic_file::Pending::beside(output).map_err(io)?;
    let spec = TextureSpec {
        subimage: how.subimage,
        tile: how.tile,
        compression: how.compression.to_owned(),
        attributes: how.attributes.to_vec(),
    };
    specconv_oiio::make_texture(input, pending.path(), &spec)?;
    // OpenImageIO renamed its own file over the temporary: that one is what gets published.
    std::fs::File::open(pending.path())
        .and_then(|f| f.sync_all())
        .map_err(io)?;
    let levels = specconv_oiio::ImageReader::open(pending.path())?
        .info()
        .levels
        .len();
    pending.publish(replace_of(how.overwrite)).map_err(io)?;
    Ok(levels)
}
