//! `specconv preview`: a spectral texture as it looks after K interreflections with itself.

use crate::files;
use crate::picture::Format;
use anyhow::Result;
use serde::Serialize;
use specconv_colour::Illuminant;
use specconv_convert_cmd::errors::explain;
use specconv_convert_cmd::stdio::serialize_path;
use specconv_figures::picture;
use specconv_flags::defs;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv preview albedo_spectral.exr -o albedo_k3.png --bounces 3
  specconv preview albedo_spectral.exr -o diff.png --bounces 3 --diff-rgb --illuminant A
";

specconv_flags::args! {
    /// Preview a spectral texture after K interreflections with itself, as an 8-bit sRGB PNG.
    ///
    /// Each pixel's reflectance r becomes the light that has met it K + 1 times, r^(K+1), under
    /// the light: XYZ = Σ r^(K+1)·I·x̄ / Σ I·ȳ, so a white stays white (Y = 1) at every K and
    /// K = 0 is the texture's own colour (as `to-rgb`). XYZ is shown as display sRGB for a D65
    /// white, without adaptation to the light, clipped to [0, 1]. An emission file (`S0.`
    /// channels) has no reflectance to bounce: at K = 0 it is shown as its own colour, as `to-rgb`
    /// integrates it in the units it records.
    ///
    /// --diff-rgb writes instead a heat map of the CIEDE2000 between that and plain RGB
    /// multiplication, the answer of an RGB renderer: per linear Rec.709 channel, the light's
    /// colour times the pixel's albedo to the power K + 1, where the albedo is the pixel's colour
    /// (r under the file's illuminant, Rec.709 primaries with the file's white as 1, 1, 1) and the
    /// light's colour is that of a white reflector under --illuminant. Under the file's own
    /// illuminant the light is (1, 1, 1) and the reference is the K = 0 colour raised to K + 1 per
    /// channel. CIELAB's white is the white reflector under the light. The colour bar on the right
    /// runs from 0 to the largest ΔE (at least 1); max and mean are printed.
    #[derive(Debug)]
    pub struct Args {
        input: PathBuf = (defs::PREVIEW_INPUT),
        output: PathBuf = (defs::PREVIEW_OUTPUT),
        illuminant: Option<Illuminant> = (defs::PREVIEW_ILLUMINANT),
        bounces: u32 = (defs::PREVIEW_BOUNCES),
        diff_rgb: bool = (defs::PREVIEW_DIFF_RGB),
        json: bool = (defs::PREVIEW_JSON),
        /// --force, as the library defines it.
        force: specconv_flags::ForceArg = flatten,
    }
}

#[derive(Serialize)]
struct PreviewRecord {
    #[serde(serialize_with = "serialize_path")]
    input: PathBuf,
    #[serde(serialize_with = "serialize_path")]
    output: PathBuf,
    width: usize,
    height: usize,
    bounces: u32,
    illuminant: String,
    /// Pixels with a NaN or infinite band, drawn black and left out of the ΔE statistics.
    non_finite: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    delta_e_max: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    delta_e_mean: Option<f64>,
}

pub fn run(args: Args) -> Result<()> {
    use specconv_conversion::preview::{shade, PreviewOptions};
    Format::of(&args.output, "-o", &[Format::Png])?;
    let replace = specconv_atomic_file::Replace::when(args.force.on());
    files::check_writable(&args.output, &[args.input.as_path()], replace)?;
    let mut options = PreviewOptions::default();
    options.illuminant = args.illuminant;
    options.bounces = args.bounces;
    options.diff_rgb = args.diff_rgb;
    let shaded = shade(&args.input, &options).map_err(|e| anyhow::anyhow!(explain(&e)))?;
    let (w, h, light) = (shaded.width, shaded.height, shaded.light);
    let non_finite = shaded.non_finite;
    let finite: Vec<f64> = shaded
        .delta_e
        .iter()
        .copied()
        .filter(|d| !d.is_nan())
        .collect();
    let max = finite.iter().copied().fold(0.0, f64::max);
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;

    let png = if args.diff_rgb {
        specconv_figures::heat::heat_map(
            (w, h),
            &shaded.delta_e,
            max.max(1.0),
            &format!("ΔE00, K={}", args.bounces),
        )?
    } else {
        let rgb: Vec<u8> = shaded.display.iter().flatten().copied().collect();
        picture::encode_png(&rgb, w as u32, h as u32)?
    };
    files::write_atomically(&args.output, &png, &[args.input.as_path()], replace)?;

    let summary = PreviewRecord {
        input: args.input.clone(),
        output: args.output.clone(),
        width: w,
        height: h,
        bounces: args.bounces,
        illuminant: light.to_string(),
        non_finite,
        delta_e_max: args.diff_rgb.then_some(max),
        delta_e_mean: args.diff_rgb.then_some(mean),
    };
    if args.json {
        outln!("{}", serde_json::to_string(&summary)?)?;
    } else {
        let diff = if args.diff_rgb {
            format!(", CIEDE2000 from RGB multiplication: max {max:.3}, mean {mean:.3}")
        } else {
            String::new()
        };
        let bad = if non_finite > 0 {
            format!(", {non_finite} pixels NaN or infinite (black)")
        } else {
            String::new()
        };
        let lit = match shaded.emission {
            Some(units) => format!("its own emission ({units} units)"),
            None => format!(
                "{} bounce{} under {light}",
                args.bounces,
                if args.bounces == 1 { "" } else { "s" }
            ),
        };
        errln!(
            "{} → {}: {w}×{h}, {lit}{diff}{bad}",
            args.input.display(),
            args.output.display(),
        );
    }
    Ok(())
}
