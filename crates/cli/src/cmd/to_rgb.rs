//! `specconv to-rgb`: integrate a spectral EXR back to a colour image, for checks and previews.

use crate::{checks, usage};
use anyhow::{anyhow, bail, Context, Result};
use specconv_colour::{Colorimetry, Illuminant};
use specconv_exr::Kind;
use specconv_spectral::emission::emission_colorimetry;
use std::path::PathBuf;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv to-rgb albedo_spectral.exr albedo_check.exr
  specconv to-rgb albedo_spectral.exr under_a.exr --illuminant A --colorspace ACEScg
";

/// Integrate a spectral OpenEXR back to colour: XYZ under an illuminant, then a colour space.
///
/// Each pixel's reflectance r gives XYZ = Σ r·I·x̄ / Σ I·ȳ under the file's illuminant and
/// observer (its `specconvIlluminant` and `specconvObserver` attributes, else D65 and CIE
/// 1931), converted through OpenColorIO from CIE-XYZ-D65 to --colorspace. Emission files
/// (`S0.` channels, from `convert --emissive`) are integrated under the observer alone,
/// XYZ = Σ L·x̄ / Σ ȳ, which returns the colours they were made from, at any brightness.
/// Written as a float RGB(A) OpenEXR.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A spectral OpenEXR (Fichet et al. 2021 layout), e.g. written by specconv.
    input: PathBuf,
    /// The colour image to write (.exr).
    output: PathBuf,
    /// Colour space of the output; default: the config's scene_linear role.
    #[arg(long, value_name = "NAME")]
    colorspace: Option<String>,
    /// Light the reflectances under this illuminant instead of the file's (reflectance files
    /// only: emission is its own light).
    #[arg(long)]
    illuminant: Option<Illuminant>,
    /// The global --ocio (see `specconv --help`).
    #[arg(skip)]
    pub(crate) ocio: Option<String>,
    /// Replace an existing output.
    #[arg(long)]
    force: bool,
}

pub fn run(args: Args) -> Result<()> {
    if args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
        != Some("exr")
    {
        return Err(usage(anyhow!(
            "to-rgb writes OpenEXR: give an output ending in .exr (oiiotool converts it further)"
        )));
    }
    checks::output_dir(&args.output)?;
    let config = checks::config(args.ocio.as_deref())?;
    if let Some(name) = &args.colorspace {
        config.color_space(name).map_err(usage)?;
    }
    if args.output.exists() && !args.force {
        bail!(
            "{} exists; pass --force to replace it",
            args.output.display()
        );
    }
    let img = specconv_exr::read(&args.input)
        .with_context(|| format!("cannot read {}", args.input.display()))?;
    let (grid, observer, recorded) = crate::files::recorded_colorimetry(&img)?;
    let emissive = matches!(img.kind, Kind::Emissive { .. });
    let illuminant = match (args.illuminant, emissive) {
        (Some(_), true) => bail!(
            "{} is an emission (S0 channels): it is its own light; drop --illuminant",
            args.input.display()
        ),
        (Some(i), false) => i,
        (None, false) => recorded,
        (None, true) => Illuminant::E,
    };
    let a = if emissive {
        emission_colorimetry(grid, observer)?
    } else {
        Colorimetry::new(grid, observer, illuminant)?
    };

    let xyz_space = config
        .role("cie_xyz_d65_interchange")?
        .context("the OCIO config has no cie_xyz_d65_interchange role to convert XYZ from")?;
    let target = match args.colorspace.clone() {
        Some(c) => c,
        None => config
            .role("scene_linear")?
            .context("the OCIO config has no scene_linear role; pass --colorspace")?,
    };
    let processor = config.processor(&xyz_space, &target)?;

    let n = img.bands.len();
    let pixels = img.width * img.height;
    let mut rgb = vec![0.0f32; pixels * 3];
    let mut r = vec![0.0f64; n];
    for p in 0..pixels {
        for (b, plane) in img.bands.iter().enumerate() {
            r[b] = plane[p] as f64;
        }
        let c = a.xyz(&r);
        rgb[3 * p..3 * p + 3].copy_from_slice(&[c[0] as f32, c[1] as f32, c[2] as f32]);
    }
    processor.apply_rgb(&mut rgb)?;

    let (w, alpha) = (img.width, img.alpha.clone());
    let tmp = specconv_pipeline::temporary_path(&args.output);
    let written = exr::prelude::write_rgba_file(&tmp, img.width, img.height, |x, y| {
        let i = y * w + x;
        (
            rgb[3 * i],
            rgb[3 * i + 1],
            rgb[3 * i + 2],
            alpha.as_ref().map_or(1.0, |a| a[i]),
        )
    })
    .map_err(anyhow::Error::from)
    .and_then(|()| Ok(std::fs::rename(&tmp, &args.output)?));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.with_context(|| format!("cannot write {}", args.output.display()))?;
    let light = if emissive {
        "emission".to_string()
    } else {
        format!("under {illuminant}")
    };
    eprintln!(
        "{} → {}: {}×{}, {n} bands {light} ({observer}) to {target}",
        args.input.display(),
        args.output.display(),
        img.width,
        img.height
    );
    Ok(())
}
