//! Patches from a texture pixel, read and converted to XYZ exactly as `convert` reads every
//! pixel: OpenImageIO reads it, the config chooses the input colour space by convert's rules
//! (specconv_pipeline::colour: `colorspace` as --colorspace, else what the file declares, the
//! config's file rules, the format's default), and its route takes it to CIE-XYZ-D65. The
//! colour is a material's: straight alpha is not applied.

use anyhow::{bail, Context, Result};
use specconv_ocio::Config;
use specconv_oiio::{ImageReader, Region};
use std::path::Path;

/// XYZ (white Y = 1) of pixel `[x, y]` (from the top left) of the full-resolution level.
pub fn pixel_xyz(
    path: &Path,
    [x, y]: [u32; 2],
    colorspace: Option<&str>,
    config: &Config,
) -> Result<[f64; 3]> {
    let mut reader = ImageReader::open(path)
        .with_context(|| format!("cannot read the texture {}", path.display()))?;
    let info = reader.info().clone();
    let (w, h) = (info.width(), info.height());
    if x >= w || y >= h {
        bail!(
            "pixel = [{x}, {y}] is outside {} ({w}×{h}): x runs from 0 to {}, y from 0 to {} \
             (top left)",
            path.display(),
            w - 1,
            h - 1
        );
    }
    let space = specconv_pipeline::input_space(config, &reader, colorspace)?;
    let px = reader.read_region(
        0,
        Region {
            x0: x,
            y0: y,
            x1: x + 1,
            y1: y + 1,
        },
    )?;
    let values = px.pixel(0, 0);
    // The colour channels as convert takes them.
    let colour = specconv_pipeline::colour_channels(info.channels.len(), info.alpha_channel);
    let Some(rgb) = specconv_pipeline::colour_of(values, &colour) else {
        bail!("{} has no colour channels", path.display());
    };
    if !rgb.iter().all(|v| v.is_finite()) {
        bail!(
            "pixel [{x}, {y}] of {} is {rgb:?}, not a colour; choose another pixel",
            path.display()
        );
    }
    let xyz = space.to_xyz.convert(rgb)?;
    if !xyz.iter().all(|v| v.is_finite()) {
        bail!(
            "pixel [{x}, {y}] of {} ({rgb:?} in {}) has no finite XYZ",
            path.display(),
            space.name
        );
    }
    Ok(xyz.map(f64::from))
}
