//! What a front-end may ask of an image without converting it: its weight in a plan, the
//! colour of one pixel. [`crate::describe`] says all the rest.

use crate::colour_config::ColourConfig;
use crate::pipeline::{colour_channels, colour_of, input_space};
use crate::wrapped::ImageError;
use specconv_oiio::{ImageReader, Region};
use std::path::{Path, PathBuf};

/// Why one pixel's colour cannot be had.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PixelError {
    /// The image cannot be opened.
    #[error("cannot read the texture {}", path.display())]
    Open {
        /// The image.
        path: PathBuf,
        /// Why.
        source: ImageError,
    },
    /// Its pixels cannot be read.
    #[error(transparent)]
    Read(#[from] ImageError),
    /// The pixel is not in the image.
    #[error(
        "pixel = [{x}, {y}] is outside {} ({width}×{height}): x runs from 0 to {}, y from 0 to {} \
         (top left)",
        path.display(),
        width - 1,
        height - 1
    )]
    Outside {
        /// The image.
        path: PathBuf,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// The image's width.
        width: u32,
        /// The image's height.
        height: u32,
    },
    /// The image has no channel that carries colour.
    #[error("{} has no colour channels", path.display())]
    NoColour {
        /// The image.
        path: PathBuf,
    },
    /// The pixel holds NaN or an infinity.
    #[error("pixel [{x}, {y}] of {} is {rgb:?}, not a colour; choose another pixel", path.display())]
    NotAColour {
        /// The image.
        path: PathBuf,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// What it holds.
        rgb: [f32; 3],
    },
    /// Its colour has no finite XYZ in its colour space.
    #[error("pixel [{x}, {y}] of {} ({rgb:?} in {space}) has no finite XYZ", path.display())]
    NoXyz {
        /// The image.
        path: PathBuf,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// What it holds.
        rgb: [f32; 3],
        /// Its colour space.
        space: String,
    },
    /// Its colour space cannot be chosen or reached.
    #[error(transparent)]
    Colour(#[from] crate::pipeline::Error),
}

/// XYZ (white Y = 1) of pixel `[x, y]` (from the top left) of the full-resolution level, read
/// as a conversion reads it: the same colour channels and colour-space rule (`colorspace`,
/// else what the file declares, the config's file rules, the format's default). The colour
/// is a material's: straight alpha is not applied.
pub fn pixel_xyz(
    config: &ColourConfig,
    path: &Path,
    [x, y]: [u32; 2],
    colorspace: Option<&str>,
) -> Result<[f64; 3], PixelError> {
    let mut reader = ImageReader::open(path).map_err(|e| PixelError::Open {
        path: path.to_path_buf(),
        source: e.into(),
    })?;
    let info = reader.info().clone();
    let (width, height) = (info.width(), info.height());
    if x >= width || y >= height {
        return Err(PixelError::Outside {
            path: path.to_path_buf(),
            x,
            y,
            width,
            height,
        });
    }
    let space = input_space(&config.0, &reader, colorspace)?;
    let region = Region {
        x0: x,
        y0: y,
        x1: x + 1,
        y1: y + 1,
    };
    let px = reader.read_region(0, region).map_err(ImageError)?;
    let colour = colour_channels(info.channels.len(), info.alpha_channel);
    let Some(rgb) = colour_of(px.pixel(0, 0), &colour) else {
        return Err(PixelError::NoColour {
            path: path.to_path_buf(),
        });
    };
    if !rgb.iter().all(|v| v.is_finite()) {
        return Err(PixelError::NotAColour {
            path: path.to_path_buf(),
            x,
            y,
            rgb,
        });
    }
    let xyz = space.to_xyz.convert(rgb)?;
    if !xyz.iter().all(|v| v.is_finite()) {
        return Err(PixelError::NoXyz {
            path: path.to_path_buf(),
            x,
            y,
            rgb,
            space: space.name,
        });
    }
    Ok(xyz.map(f64::from))
}
