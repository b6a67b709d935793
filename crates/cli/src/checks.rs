//! What a command checks once, before its first input: settings that cannot work for any
//! input fail here as usage errors (exit status 2), on one line, before anything is read or
//! written, instead of once per input.

use crate::usage;
use anyhow::Result;
use specconv_conversion::ocio::Config;

/// The OCIO config of `--ocio`, else `$OCIO`, else the built-in ACES config.
pub fn config(ocio: Option<&str>) -> Result<Config> {
    Config::resolve(ocio).map_err(usage)
}

/// A colour space named on the command line (`--colorspace`) exists in `config` and reaches
/// CIE XYZ, so every input read in it can be converted; or is a data space, which names data
/// textures (never uplifted: convert's `--data` says what becomes of them).
pub fn input_colorspace(config: &Config, name: Option<&str>) -> Result<()> {
    let explained =
        |e: specconv_conversion::ocio::Error| usage(anyhow::anyhow!(crate::explain(&e.into())));
    if let Some(name) = name {
        let cs = config.color_space(name).map_err(explained)?;
        if !cs.is_data {
            config.processor_to_xyz(&cs.name).map_err(explained)?;
        }
    }
    Ok(())
}
