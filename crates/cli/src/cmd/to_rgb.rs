//! `specconv to-rgb`: integrate a spectral EXR back to a colour image, for checks and previews.

use anyhow::Result;
use specconv_colour::Illuminant;
use specconv_convert_cmd::errors::{explain, usage};
use specconv_flags::defs;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv to-rgb albedo_spectral.exr albedo_check.exr
  specconv to-rgb albedo_spectral.exr under_a.exr --illuminant A --colorspace ACEScg
";

specconv_flags::args! {
    /// Integrate a spectral OpenEXR back to colour: XYZ, then a colour space.
    ///
    /// Spectra are integrated as the layout's reference implementation does, at any wavelengths
    /// (uneven, any unit, Hz): interpolated linearly onto the observer's 1 nm table where the
    /// bands, the table and the illuminant overlap, and summed there. Reflectances r give
    /// XYZ = Σ r·I·x̄ / Σ I·ȳ under the file's illuminant and observer (its `specconvIlluminant`
    /// and `specconvObserver` attributes, else D65 and CIE 1931); bispectral files add the
    /// re-radiated light, Σ over incident bands of T(λi→λo)·I(λi). Emission (`S0.` channels) is
    /// read in the convention the file records (`specconvEmissionUnits`; older specconv files:
    /// normalised; other writers: the layout's reference, XYZ = Σ S0·x̄). Polarised files use S0;
    /// channels outside the layout (an RGB preview beside the spectra) are listed, not used.
    /// XYZ is converted through OpenColorIO from CIE-XYZ-D65 to --colorspace and written as a
    /// float RGB OpenEXR (RGBA when the input has alpha) that declares that space: its
    /// chromaticities (and acesImageContainerFlag for ACES2065-1) and its name, so that other
    /// readers take the values as that colour.
    #[derive(Debug)]
    pub struct Args {
        input: PathBuf = (defs::TO_RGB_INPUT),
        output: PathBuf = (defs::TO_RGB_OUTPUT),
        colorspace: Option<String> = (defs::TO_RGB_COLORSPACE),
        illuminant: Option<Illuminant> = (defs::TO_RGB_ILLUMINANT),
        /// The global --ocio (see `specconv --help`).
        pub(crate) ocio: Option<String> = skip,
        /// --force, as the library defines it.
        force: specconv_flags::ForceArg = flatten,
    }
}

pub fn run(args: Args) -> Result<()> {
    use specconv_conversion::to_rgb::{Light, ToRgb, ToRgbOptions};
    crate::files::check_exr_output(
        &args.output,
        &args.input,
        args.force.on(),
        "to-rgb writes OpenEXR",
    )?;
    let mut options = ToRgbOptions::default();
    options.ocio = args.ocio.clone();
    options.colorspace = args.colorspace.clone();
    options.illuminant = args.illuminant;
    options.overwrite = args.force.on();
    let to_rgb = ToRgb::new(options).map_err(|e| usage(anyhow::anyhow!(explain(&e))))?;
    // A signal stops the integration between blocks, or the write before it is published.
    let r = specconv_convert_cmd::signals::one_output(|cancel| {
        to_rgb.convert_cancellable(&args.input, &args.output, cancel)
    })?;
    let light = match r.light {
        Light::Emission(units, why) => format!("emission, {units} units ({})", why.describe()),
        Light::Illuminant(i, 0) => format!("under {i}"),
        Light::Illuminant(i, k) => format!("under {i}, with {k} re-radiation channels"),
    };
    let mut notes = String::new();
    if r.polarised {
        notes += "; polarised: S0 used, S1–S3 not";
    }
    if r.emission_left_out {
        notes += "; the S0 emission beside the reflectance is not included";
    }
    if !r.unused_channels.is_empty() {
        notes += &format!(
            "; channels outside the spectral layout not used: {}",
            r.unused_channels.join(", ")
        );
    }
    let (wl, n) = (&r.wavelengths, r.wavelengths.len());
    errln!(
        "{} → {}: {}×{}, {n} bands {}–{} nm {light} ({}) to {}{notes}",
        args.input.display(),
        args.output.display(),
        r.width,
        r.height,
        wl[0],
        wl[n - 1],
        r.observer,
        r.colorspace,
    );
    Ok(())
}
