//! `specconv to-rgb`: integrate a spectral EXR back to a colour image, for checks and previews.

use crate::{checks, usage};
use anyhow::{bail, Context, Result};
use specconv_colour::{Illuminant, Integration};
use specconv_exr::{Kind, SpectralImage};
use std::path::{Path, PathBuf};

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv to-rgb albedo_spectral.exr albedo_check.exr
  specconv to-rgb albedo_spectral.exr under_a.exr --illuminant A --colorspace ACEScg
";

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
/// float RGB OpenEXR (RGBA when the input has alpha).
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
    crate::files::check_output(&args.output, &["exr"], "to-rgb writes OpenEXR")?;
    checks::output_dir(&args.output)?;
    let config = checks::config(args.ocio.as_deref())?;
    if let Some(name) = &args.colorspace {
        config.color_space(name).map_err(usage)?;
    }
    crate::checks::may_write(&args.output, args.force)?;
    let img = crate::files::read_spectral(&args.input)?;
    let recorded = crate::files::provenance(&img)?;
    let observer = recorded.observer_or_default();
    let emissive = matches!(img.kind, Kind::Emissive { .. });
    let units = emissive.then(|| recorded.emission_convention());
    let illuminant = match (args.illuminant, emissive) {
        (Some(_), true) => bail!(
            "{} is an emission (S0 channels): it is its own light; drop --illuminant",
            args.input.display()
        ),
        (Some(i), false) => i,
        (None, _) => recorded.illuminant_or_default(),
    };
    let integration = match units {
        Some((units, _)) => units.integration(&img.wavelengths, observer)?,
        None => Integration::reflectance(&img.wavelengths, observer, illuminant)?,
    };
    // Bispectral: band o reflects T(o)·I(o) and re-radiates T(i→o)·I(i) from each band i.
    let lit = if img.reradiation.is_empty() {
        None
    } else {
        Some(specconv_colour::integration::illuminant_at(
            illuminant,
            &img.wavelengths,
        )?)
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
    let mut rgb = xyz_of_pixels(&img, &integration, lit.as_deref());
    processor.apply_rgb(&mut rgb)?;

    write(&args.output, &img, &rgb)?;
    let light = match units {
        Some((units, why)) => format!("emission, {units} units ({})", why.describe()),
        None if lit.is_some() => format!(
            "under {illuminant}, with {} re-radiation channels",
            img.reradiation.len()
        ),
        None => format!("under {illuminant}"),
    };
    let notes = notes(&img, emissive);
    let wl = &img.wavelengths;
    eprintln!(
        "{} → {}: {}×{}, {n} bands {}–{} nm {light} ({observer}) to {target}{notes}",
        args.input.display(),
        args.output.display(),
        img.width,
        img.height,
        wl[0],
        wl[n - 1],
    );
    Ok(())
}

/// XYZ of every pixel (f32, three per pixel) under `integration`; with `lit` (the light per
/// band), bispectral: band o reflects T(o)·I(o) and re-radiates T(i→o)·I(i) from each band i.
fn xyz_of_pixels(img: &SpectralImage, integration: &Integration, lit: Option<&[f64]>) -> Vec<f32> {
    let pixels = img.width * img.height;
    let mut xyz = vec![0.0f32; pixels * 3];
    let mut r = vec![0.0f64; img.bands.len()];
    for p in 0..pixels {
        for (b, plane) in img.bands.iter().enumerate() {
            r[b] = plane[p] as f64;
        }
        if let Some(light) = lit {
            for (i, o, plane) in &img.reradiation {
                if light[*o] > 0.0 {
                    r[*o] += plane[p] as f64 * light[*i] / light[*o];
                }
            }
        }
        let c = integration.xyz(&r);
        xyz[3 * p..3 * p + 3].copy_from_slice(&[c[0] as f32, c[1] as f32, c[2] as f32]);
    }
    xyz
}

/// Writes `rgb` as an RGB(A) OpenEXR through a temporary file: no channel the input did not
/// have (A only when the input has alpha).
fn write(output: &Path, img: &SpectralImage, rgb: &[f32]) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let (w, h) = (img.width, img.height);
    let px = |p: Vec2<usize>| {
        let i = p.y() * w + p.x();
        (rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2])
    };
    let write = || -> Result<()> {
        let pending = specconv_atomic_file::Pending::beside(output)?;
        let out = std::io::BufWriter::new(pending.file());
        match &img.alpha {
            Some(a) => Image::from_channels(
                (w, h),
                SpecificChannels::rgba(|p: Vec2<usize>| {
                    let (r, g, b) = px(p);
                    (r, g, b, a[p.y() * w + p.x()])
                }),
            )
            .write()
            .to_buffered(out)?,
            None => Image::from_channels((w, h), SpecificChannels::rgb(px))
                .write()
                .to_buffered(out)?,
        }
        Ok(pending.commit()?)
    };
    write().with_context(|| format!("cannot write {}", output.display()))
}

/// What of the file the conversion left out, for the report line.
fn notes(img: &SpectralImage, emissive: bool) -> String {
    let mut notes = String::new();
    let layout = &img.layout;
    if layout.polarised() {
        notes += "; polarised: S0 used, S1–S3 not";
    }
    if !emissive && !layout.stokes[0].is_empty() {
        notes += "; the S0 emission beside the reflectance is not included";
    }
    if !layout.other.is_empty() {
        notes += &format!(
            "; channels outside the spectral layout not used: {}",
            layout.other.join(", ")
        );
    }
    notes
}
