//! The OCIO config every front-end reads colour through, as plain data: the same config rule
//! as a conversion (`ocio`, else `$OCIO`, else the built-in ACES config), its colour spaces
//! and roles, and the route of a colour space to CIE XYZ (D65). OpenColorIO's own types stay
//! inside this crate.

use crate::error::Error;
use std::path::PathBuf;

/// An OCIO config, loaded and validated ([`ColourConfig::resolve`]).
#[derive(Debug)]
pub struct ColourConfig(pub(crate) specconv_ocio::Config);

/// Where a config came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ConfigOrigin {
    /// A file named by the caller (`--ocio FILE`, `ocio=`).
    File(PathBuf),
    /// A file named by `$OCIO`.
    Env(PathBuf),
    /// A built-in config, by the name that picked it (`aces` when none was given).
    Builtin(String),
}

/// A colour space of a config.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct ColourSpace {
    /// Its name.
    pub name: String,
    /// Other names it answers to.
    pub aliases: Vec<String>,
    /// Its family (`Utility`, `ACES`, …), empty when none.
    pub family: String,
    /// Its encoding (`scene-linear`, `sdr-video`, …), empty when none.
    pub encoding: String,
    /// A data space (`Raw`): numbers, not colour; never uplifted.
    pub is_data: bool,
    /// Display-referred rather than scene-referred.
    pub is_display: bool,
}

impl ColourSpace {
    fn of(c: specconv_ocio::ColorSpace) -> ColourSpace {
        ColourSpace {
            name: c.name,
            aliases: c.aliases,
            family: c.family,
            encoding: c.encoding,
            is_data: c.is_data,
            is_display: c.is_display,
        }
    }
}

/// Whether `name` picks a built-in config (`aces`, an `ocio://` name) rather than a file.
pub fn is_builtin_config(name: &str) -> bool {
    specconv_ocio::is_builtin_name(name)
}

impl ColourConfig {
    /// The config of `ocio` (a file, `aces`, an `ocio://` name), else of `$OCIO`, else the
    /// built-in ACES config: the rule of every conversion.
    pub fn resolve(ocio: Option<&str>) -> Result<ColourConfig, Error> {
        Ok(ColourConfig(specconv_ocio::Config::resolve(ocio)?))
    }

    /// Where it came from.
    pub fn origin(&self) -> ConfigOrigin {
        use specconv_ocio::ConfigSource;
        match self.0.source() {
            ConfigSource::File(p) => ConfigOrigin::File(p.clone()),
            ConfigSource::Env(p) => ConfigOrigin::Env(p.clone()),
            ConfigSource::Builtin { name, .. } => ConfigOrigin::Builtin(name.clone()),
        }
    }

    /// Where it came from, in words: the file (`(from $OCIO)` added for `$OCIO`'s), or the
    /// built-in config's name and what it is.
    pub fn describe_origin(&self) -> String {
        self.0.source().to_string()
    }

    /// Its colour spaces, in the config's order.
    pub fn colour_spaces(&self) -> Result<Vec<ColourSpace>, Error> {
        Ok(self
            .0
            .color_spaces()?
            .into_iter()
            .map(ColourSpace::of)
            .collect())
    }

    /// The colour space of this name or alias (an error names close ones).
    pub fn colour_space(&self, name: &str) -> Result<ColourSpace, Error> {
        Ok(ColourSpace::of(self.0.color_space(name)?))
    }

    /// The colour space a role names, if the config defines the role.
    pub fn role(&self, role: &str) -> Result<Option<String>, Error> {
        Ok(self.0.role(role)?)
    }

    /// The config's sRGB texture space (what integer pixels that declare nothing are read
    /// as), if it has one.
    pub fn srgb_texture(&self) -> Result<Option<String>, Error> {
        Ok(self.0.srgb_texture()?)
    }

    /// The route from `colour_space` to CIE XYZ (D65, white Y = 1), as a conversion converts
    /// pixels: through the config's `cie_xyz_d65_interchange` role, else `aces_interchange`.
    /// A data space has none.
    pub fn to_xyz(&self, colour_space: &str) -> Result<XyzTransform, Error> {
        Ok(XyzTransform(self.0.processor_to_xyz(colour_space)?))
    }

    /// The config's name for `name` (a name, alias or role of the config, else a Color Interop
    /// Forum ID: `data` is the config's data space), as a file's declared name is read
    /// (docs/colour.md); `Ok(None)` for `unknown`, `Ok(Some(Err(why)))` for a name neither knows.
    pub fn named_space(&self, name: &str) -> Result<Option<Result<String, String>>, Error> {
        Ok(crate::pipeline::colour::named_space(&self.0, name)?)
    }

    /// A colour space named for inputs (a conversion's `colorspace`) exists and reaches
    /// CIE XYZ, so every input read in it can be converted; or is a data space, which names
    /// data textures (never uplifted).
    pub fn check_input_colour_space(&self, name: &str) -> Result<(), Error> {
        let cs = self.0.color_space(name)?;
        if !cs.is_data {
            self.0.processor_to_xyz(&cs.name)?;
        }
        Ok(())
    }
}

/// A colour space's route to CIE XYZ (D65) ([`ColourConfig::to_xyz`]).
#[derive(Debug)]
pub struct XyzTransform(specconv_ocio::Processor);

impl XyzTransform {
    /// Converts interleaved RGB triples to XYZ in place (OpenColorIO computes in float32).
    pub fn apply_rgb(&self, rgb: &mut [f32]) -> Result<(), Error> {
        Ok(self.0.apply_rgb(rgb)?)
    }
}
