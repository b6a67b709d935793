//! What a scene needs from files and colour management ([`scene::Resolve`]): measured
//! spectra read from CSV, and colours and texture pixels converted to XYZ exactly as `convert`
//! converts every pixel. A colour's `colorspace` is a name of the scene's OCIO config (as
//! --colorspace; absent: the config's sRGB texture space, convert's default for integer
//! pixels). A texture pixel is read by OpenImageIO and its colour space chosen by convert's
//! rules (specconv_pipeline::colour: `colorspace`, else what the file declares, the config's
//! file rules, the format's default). The colour is a material's: straight alpha is not applied.

use crate::files;
use anyhow::{anyhow, bail, Context, Result};
use specconv_colour::SpectralTable;
use specconv_conversion::images::{ImageReader, Region};
use specconv_conversion::ocio::Config;
use specconv_study::scene::{self, Cause};
use std::path::{Path, PathBuf};

/// The resolver of one scene: its folder and OCIO config (loaded when first needed).
pub struct Resources {
    ocio: Option<String>,
    dir: PathBuf,
    config: Option<Config>,
}

impl Resources {
    /// `ocio` as the scene gives it: a built-in name such as `aces`, or a file relative to `dir`;
    /// absent, as `convert` without --ocio ($OCIO, else the built-in ACES config).
    pub fn new(ocio: Option<&str>, dir: &Path) -> Resources {
        Resources {
            ocio: ocio.map(str::to_string),
            dir: dir.to_path_buf(),
            config: None,
        }
    }

    fn config(&mut self) -> Result<&Config> {
        if self.config.is_none() {
            let path = self.ocio.as_ref().map(|o| {
                if specconv_conversion::ocio::is_builtin_name(o) {
                    o.clone()
                } else {
                    self.dir.join(o).display().to_string()
                }
            });
            self.config = Some(Config::resolve(path.as_deref())?);
        }
        Ok(self.config.as_ref().expect("loaded above"))
    }

    fn colour_xyz(&mut self, rgb: [f64; 3], space: Option<&str>) -> Result<[f64; 3]> {
        let config = self.config()?;
        let name = match space {
            Some(s) => config.color_space(s)?.name,
            None => config.srgb_texture()?.ok_or_else(|| {
                anyhow!("the OCIO config has no sRGB texture space; give the colour's `colorspace`")
            })?,
        };
        let mut px = rgb.map(|v| v as f32);
        config.processor_to_xyz(&name)?.apply_rgb(&mut px)?;
        Ok(px.map(f64::from))
    }
}

impl scene::Resolve for Resources {
    fn spectra(&mut self, path: &Path) -> Result<SpectralTable, Cause> {
        Ok(files::read_spectra(path)?)
    }

    fn colour(&mut self, rgb: [f64; 3], space: Option<&str>) -> Result<[f64; 3], Cause> {
        Ok(self.colour_xyz(rgb, space)?)
    }

    fn texture_pixel(
        &mut self,
        path: &Path,
        pixel: [u32; 2],
        space: Option<&str>,
    ) -> Result<[f64; 3], Cause> {
        let config = self.config()?;
        Ok(pixel_xyz(path, pixel, space, config)?)
    }
}

/// XYZ (white Y = 1) of pixel `[x, y]` (from the top left) of the full-resolution level.
fn pixel_xyz(
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
    let space = specconv_conversion::images::input_space(config, &reader, colorspace)?;
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
    let colour =
        specconv_conversion::images::colour_channels(info.channels.len(), info.alpha_channel);
    let Some(rgb) = specconv_conversion::images::colour_of(values, &colour) else {
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
