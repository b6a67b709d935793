//! What a scene needs from files and colour management ([`scene::Resolve`]): measured
//! spectra read from CSV, and colours and texture pixels converted to XYZ exactly as `convert`
//! converts every pixel. A colour's `colorspace` is a name of the scene's OCIO config (as
//! --colorspace; absent: the config's sRGB texture space, convert's default for integer
//! pixels). A texture pixel is read by OpenImageIO and its colour space chosen by convert's
//! rules (specconv_conversion::images::pixel_xyz: the precedence of colour evidence of
//! docs/colour.md). The colour is a material's: straight alpha is not applied.

use crate::files;
use anyhow::{anyhow, Result};
use specconv_colour::SpectralTable;
use specconv_conversion::ColourConfig;
use specconv_evaluation::scene::{self, Cause};
use std::path::{Path, PathBuf};

/// The resolver of one scene: its folder and OCIO config (loaded when first needed), and the
/// files it read (which an output may never replace).
pub struct Resources {
    ocio: Option<String>,
    dir: PathBuf,
    config: Option<ColourConfig>,
    /// Every spectra file and texture the scene read.
    pub read: Vec<PathBuf>,
}

impl Resources {
    /// `ocio` as the scene gives it: a built-in name such as `aces`, or a file relative to `dir`;
    /// absent, as `convert` without --ocio ($OCIO, else the built-in ACES config).
    pub fn new(ocio: Option<&str>, dir: &Path) -> Resources {
        Resources {
            ocio: ocio.map(str::to_string),
            dir: dir.to_path_buf(),
            config: None,
            read: Vec::new(),
        }
    }

    fn config(&mut self) -> Result<&ColourConfig> {
        if self.config.is_none() {
            let path = self.ocio.as_ref().map(|o| {
                if specconv_conversion::is_builtin_config(o) {
                    o.clone()
                } else {
                    self.dir.join(o).display().to_string()
                }
            });
            self.config = Some(ColourConfig::resolve(path.as_deref())?);
        }
        Ok(self.config.as_ref().expect("loaded above"))
    }

    fn colour_xyz(&mut self, rgb: [f64; 3], space: Option<&str>) -> Result<[f64; 3]> {
        let config = self.config()?;
        let name = match space {
            Some(s) => config.colour_space(s)?.name,
            None => config.srgb_texture()?.ok_or_else(|| {
                anyhow!("the OCIO config has no sRGB texture space; give the colour's `colorspace`")
            })?,
        };
        let mut px = rgb.map(|v| v as f32);
        // Said as it is: the remedies of a conversion's errors name convert's flags, not the
        // scene's keys (a data space as a colour's `colorspace`).
        let said = |e: specconv_conversion::Error| anyhow!(specconv_conversion::message(&e));
        config
            .to_xyz(&name)
            .map_err(said)?
            .apply_rgb(&mut px)
            .map_err(said)?;
        Ok(px.map(f64::from))
    }
}

impl scene::Resolve for Resources {
    fn spectra(&mut self, path: &Path) -> Result<SpectralTable, Cause> {
        self.read.push(path.to_path_buf());
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
        self.read.push(path.to_path_buf());
        let config = self.config()?;
        Ok(specconv_conversion::images::pixel_xyz(
            config, path, pixel, space,
        )?)
    }
}
