//! `specconv expand`: a compact texture written out in the spectral layout.

use anyhow::Result;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv convert --layout compact albedo.tx albedo_compact.exr
  specconv expand albedo_compact.exr albedo_spectral.exr
";

/// Write a compact texture (`convert --layout compact`) out in the spectral layout.
///
/// Each texel of the compact file holds its colour and the three dual unknowns of the bounded
/// projection; the header holds the model's maps on the output grid and the decoding rule
/// (docs/compact.md). Level 0 is decoded by that rule and the smaller levels are filtered from
/// its spectra, as `convert` filters its own; samples are rounded, compressed and tiled as
/// `convert` with the compact file's settings would have, and the header keeps its provenance.
/// The values are `convert`'s, within one half step (the dual unknowns are stored as float32).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A compact texture (`specconvLayout` = "compact 1").
    input: PathBuf,
    /// The spectral OpenEXR to write (.exr).
    output: PathBuf,
    /// Replace an existing output.
    #[arg(long)]
    force: bool,
    /// NaN and infinite texels: refuse, black, box3 or none (keep), as `convert --fixnan`
    /// treats its input's pixels; by default the rule the compact file's conversion recorded.
    #[arg(long, value_name = "HOW")]
    fixnan: Option<specconv_conversion::NonFinite>,
}

pub fn run(args: Args) -> Result<()> {
    crate::files::check_exr_output(
        &args.output,
        &args.input,
        args.force,
        "expand writes OpenEXR",
    )?;
    let r = crate::signals::one_output(|cancel| {
        specconv_conversion::expand(&args.input, &args.output, args.force, args.fixnan, cancel)
    })?;
    let wl = &r.wavelengths;
    errln!(
        "{} → {}: {}×{}, {} levels, {} bands {}–{} nm ({} texels projected)",
        args.input.display(),
        args.output.display(),
        r.width,
        r.height,
        r.levels,
        wl.len(),
        wl[0],
        wl[wl.len() - 1],
        r.projected,
    );
    Ok(())
}
