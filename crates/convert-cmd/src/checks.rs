//! What a command checks once, before its first input: settings that cannot work for any
//! input fail here as usage errors (exit status 2), on one line, before anything is read or
//! written, instead of once per input.

use crate::errors::usage;
use anyhow::Result;
use specconv_conversion::ColourConfig;

/// The OCIO config of `--ocio`, else `$OCIO`, else the built-in ACES config.
pub fn config(ocio: Option<&str>) -> Result<ColourConfig> {
    ColourConfig::resolve(ocio).map_err(usage)
}

/// A colour space named on the command line (`--colorspace`) exists in `config` and reaches
/// CIE XYZ, so every input read in it can be converted; or is a data space, which names data
/// textures (never uplifted: convert's `--data` says what becomes of them).
pub fn input_colorspace(config: &ColourConfig, name: Option<&str>) -> Result<()> {
    if let Some(name) = name {
        config
            .check_input_colour_space(name)
            .map_err(|e| usage(anyhow::anyhow!(crate::errors::explain(&e))))?;
    }
    Ok(())
}
