//! `specconv preview`: a spectral texture as it looks after K interreflections with itself.

use crate::files;
use crate::font::FAMILY;
use crate::picture::{self, Format};
use anyhow::{bail, Context, Result};
use plotters::prelude::*;
use rayon::prelude::*;
use serde::Serialize;
use specconv_colour::integration::Onto;
use specconv_colour::lab::{ciede2000, xyz_to_lab};
use specconv_colour::mat3::mul_vec as apply;
use specconv_colour::rgb::{srgb_encode, SRGB};
use specconv_colour::{Colorimetry, Illuminant};
use specconv_exr::{Kind, SpectralImage};
use specconv_study::simulate::SelfBounce;
use std::path::{Path, PathBuf};

/// The most bounces asked for: r^(K+1) of any reflectance below 1 is black long before.
const MAX_BOUNCES: u32 = 100;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv preview albedo_spectral.exr -o albedo_k3.png --bounces 3
  specconv preview albedo_spectral.exr -o diff.png --bounces 3 --diff-rgb --illuminant A
";

/// Preview a spectral texture after K interreflections with itself, as an 8-bit sRGB PNG.
///
/// Each pixel's reflectance r becomes the light that has met it K + 1 times, r^(K+1), under
/// the light: XYZ = Σ r^(K+1)·I·x̄ / Σ I·ȳ, so a white stays white (Y = 1) at every K and
/// K = 0 is the texture's own colour (as `to-rgb`). XYZ is shown as display sRGB for a D65
/// white, without adaptation to the light, clipped to [0, 1].
///
/// --diff-rgb writes instead a heat map of the CIEDE2000 between that and plain RGB
/// multiplication, the answer of an RGB renderer: per linear Rec.709 channel, the light's
/// colour times the pixel's albedo to the power K + 1, where the albedo is the pixel's colour
/// (r under the file's illuminant, Rec.709 primaries with the file's white as 1, 1, 1) and the
/// light's colour is that of a white reflector under --illuminant. Under the file's own
/// illuminant the light is (1, 1, 1) and the reference is the K = 0 colour raised to K + 1 per
/// channel. CIELAB's white is the white reflector under the light. The colour bar on the right
/// runs from 0 to the largest ΔE (at least 1); max and mean are printed.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A spectral OpenEXR of reflectances (Fichet et al. 2021 layout), e.g. from convert.
    input: PathBuf,
    /// The picture to write (.png).
    #[arg(short, long, value_name = "OUT.png")]
    output: PathBuf,
    /// The light: D65, E, A, D50, FL2, FL11 or blackbody:KELVIN. Default: the file's
    /// illuminant (its specconvIlluminant attribute, else D65).
    #[arg(long)]
    illuminant: Option<Illuminant>,
    /// Interreflections K: the reflectance is met K + 1 times (0: the texture as it is).
    #[arg(long, value_name = "K", default_value_t = 0,
          value_parser = clap::value_parser!(u32).range(..=i64::from(MAX_BOUNCES)))]
    bounces: u32,
    /// Write the CIEDE2000 heat map against plain RGB multiplication instead.
    #[arg(long)]
    diff_rgb: bool,
    /// Print a JSON summary (sizes, light, and ΔE max and mean with --diff-rgb) on stdout.
    #[arg(long)]
    json: bool,
    /// Replace an existing output.
    #[arg(long)]
    force: bool,
}

#[derive(Serialize)]
struct Summary {
    input: PathBuf,
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
    Format::of(&args.output, "-o", &[Format::Png])?;
    crate::checks::output_dir(&args.output)?;
    crate::checks::may_write(&args.output, args.force)?;
    let img = crate::files::read_spectral(&args.input)?;
    previewable(&img, &args.input)?;
    let recorded =
        files::provenance(&img).with_context(|| format!("in {}", args.input.display()))?;
    let (observer, own) = (
        recorded.observer_or_default(),
        recorded.illuminant_or_default(),
    );
    let light = args.illuminant.unwrap_or(own);
    // As every reader: the spectra interpolated onto the observer's 1 nm table, where both
    // illuminants' tables reach (the layout's reference integration, so K = 0 is `to-rgb`).
    let limits = [own.range(), light.range()]
        .into_iter()
        .flatten()
        .reduce(|a, b| (a.0.max(b.0), a.1.min(b.1)));
    let onto = Onto::new(&img.wavelengths, limits)?;
    let grid = onto.grid;
    let texture = Colorimetry::new(grid, observer, own)?;
    let lit = Colorimetry::new(grid, observer, light)?;
    let bounce = SelfBounce::new(&texture, &lit, args.bounces)?;

    let (w, h) = (img.width, img.height);
    let pixels = shade(&img, &onto, &bounce, args.diff_rgb);
    let non_finite = pixels.iter().filter(|p| p.1.is_nan()).count();
    let finite: Vec<f64> = pixels.iter().map(|p| p.1).filter(|d| !d.is_nan()).collect();
    let max = finite.iter().copied().fold(0.0, f64::max);
    let mean = finite.iter().sum::<f64>() / finite.len().max(1) as f64;

    let png = if args.diff_rgb {
        heat_map(w, h, &pixels, max.max(1.0), args.bounces)?
    } else {
        let rgb: Vec<u8> = pixels.iter().flat_map(|p| p.0).collect();
        picture::encode_png(&rgb, w as u32, h as u32)?
    };
    files::write_atomically(&args.output, &png, &[args.input.as_path()])?;

    let summary = Summary {
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
        println!("{}", serde_json::to_string(&summary)?);
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
        eprintln!(
            "{} → {}: {w}×{h}, {} bounce{} under {light}{diff}{bad}",
            args.input.display(),
            args.output.display(),
            args.bounces,
            if args.bounces == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

/// Refuses what preview cannot show: emission and bispectral files.
fn previewable(img: &SpectralImage, input: &Path) -> Result<()> {
    if !matches!(img.kind, Kind::Reflective) {
        bail!(
            "{} holds emission (S0 channels), not reflectances: it has no colour to bounce; \
             preview reflectance files (T channels)",
            input.display()
        );
    }
    if !img.reradiation.is_empty() {
        bail!(
            "{} is bispectral (re-radiation channels): its bounces need the whole re-radiation \
             matrix, which preview does not follow; `to-rgb` shows its colour",
            input.display()
        );
    }
    Ok(())
}

/// Per pixel: display sRGB after the bounces and, with `diff_rgb`, the CIEDE2000 from RGB
/// multiplication (NaN where the pixel is not finite).
fn shade(
    img: &SpectralImage,
    onto: &Onto,
    bounce: &SelfBounce,
    diff_rgb: bool,
) -> Vec<([u8; 3], f64)> {
    let to_display = SRGB.from_xyz(SRGB.white_xyz());
    let white = bounce.white();
    (0..img.width * img.height)
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![0f32; img.bands.len()],
                    vec![0f64; onto.grid.len()],
                    vec![0f32; onto.grid.len()],
                )
            },
            |(bands, fine, r), p| {
                for (v, plane) in bands.iter_mut().zip(&img.bands) {
                    *v = plane[p];
                }
                if !bands.iter().all(|v| v.is_finite()) {
                    return ([0; 3], f64::NAN);
                }
                onto.apply(bands, fine);
                r.iter_mut()
                    .zip(fine.iter())
                    .for_each(|(r, &v)| *r = v as f32);
                let xyz = bounce.spectral(r);
                let display = apply(&to_display, xyz)
                    .map(|v| (srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8);
                let d = if diff_rgb {
                    ciede2000(xyz_to_lab(xyz, white), xyz_to_lab(bounce.rgb(r), white))
                } else {
                    0.0
                };
                (display, d)
            },
        )
        .collect()
}

/// Black → red → yellow → white as ΔE goes from 0 to 1 (of the scale): readable in grey too.
fn heat(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let c = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    [c(3.0 * t), c(3.0 * t - 1.0), c(3.0 * t - 2.0)]
}

const BAR: u32 = 110;

/// The ΔE image with a colour bar and its scale to the right.
fn heat_map(w: usize, h: usize, pixels: &[([u8; 3], f64)], scale: f64, k: u32) -> Result<Vec<u8>> {
    let (width, height) = (w as u32 + BAR, (h as u32).max(200));
    let mut rgb = picture::render((width, height), |root| {
        root.fill(&WHITE)?;
        let (x0, top, bottom) = (w as i32 + 12, 24, height as i32 - 12);
        let style = |size| (FAMILY, size).into_font().color(&BLACK);
        root.draw(&Text::new(format!("ΔE00, K={k}"), (x0, 4), style(12.0)))?;
        for y in top..=bottom {
            let t = f64::from(bottom - y) / f64::from(bottom - top);
            let [r, g, b] = heat(t);
            root.draw(&Rectangle::new(
                [(x0, y), (x0 + 18, y + 1)],
                RGBColor(r, g, b).filled(),
            ))?;
        }
        for (t, y) in [(1.0, top), (0.5, (top + bottom) / 2), (0.0, bottom - 10)] {
            root.draw(&Text::new(
                format!("{:.2}", t * scale),
                (x0 + 24, y),
                style(12.0),
            ))?;
        }
        Ok(())
    })?;
    for y in 0..h {
        for x in 0..w {
            let i = 3 * (y * width as usize + x);
            rgb[i..i + 3].copy_from_slice(&heat(pixels[y * w + x].1 / scale));
        }
    }
    picture::encode_png(&rgb, width, height)
}
