//! A spectral texture shaded after K interreflections with itself (`preview`): each pixel's
//! reflectance r met K + 1 times under a light, as display sRGB, and optionally its CIEDE2000
//! from plain RGB multiplication. The input is read block by block; only the 8-bit colour and
//! the ΔE of each pixel are held.

use crate::provenance::Provenance;
use crate::Error;
use rayon::prelude::*;
use specconv_colour::integration::Onto;
use specconv_colour::lab::{ciede2000, xyz_to_lab};
use specconv_colour::mat3::mul_vec as apply;
use specconv_colour::rgb::{srgb_encode, SRGB};
use specconv_colour::{Colorimetry, Illuminant};
use specconv_evaluation::simulate::SelfBounce;
use specconv_exr::blocks::BlockReader;
use specconv_exr::Kind;
use std::path::Path;

/// What to shade.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct PreviewOptions {
    /// The light (`None`: the file's illuminant, else D65).
    pub illuminant: Option<Illuminant>,
    /// Interreflections K: the reflectance is met K + 1 times.
    pub bounces: u32,
    /// Also the CIEDE2000 from plain RGB multiplication, per pixel.
    pub diff_rgb: bool,
}

/// A shaded texture.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Shaded {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The light.
    pub light: Illuminant,
    /// Display sRGB after the bounces, row-major (black where a band is not finite).
    pub display: Vec<[u8; 3]>,
    /// Per pixel, the CIEDE2000 from RGB multiplication (`diff_rgb`; NaN where a band is not
    /// finite, 0 without `diff_rgb`).
    pub delta_e: Vec<f64>,
    /// Pixels with a NaN or infinite band.
    pub non_finite: usize,
    /// An emission file (shown with no bounces: its own colour), in the units it records;
    /// `None` for reflectance.
    pub emission: Option<specconv_colour::EmissionUnits>,
}

/// Shades `input` (a reflectance file, not bispectral; or an emission file with no bounces,
/// shown as its own colour).
pub fn shade(input: &Path, options: &PreviewOptions) -> Result<Shaded, Error> {
    let read_error = |source| crate::compact::spectral_read_error(input, source);
    let mut reader = BlockReader::open(input).map_err(read_error)?;
    let h = reader.header().clone();
    match (&h.kind, options.bounces, options.illuminant) {
        (Kind::Reflective, ..) => {}
        (Kind::Emissive { .. }, 0, None) => return shade_emission(input, reader),
        (Kind::Emissive { .. }, 0, Some(_)) => {
            return Err(Error::EmissionIsItsOwnLight {
                input: input.to_path_buf(),
            })
        }
        _ => {
            return Err(Error::NotReflectance {
                input: input.to_path_buf(),
            })
        }
    }
    if !h.reradiation.is_empty() {
        return Err(Error::Bispectral {
            input: input.to_path_buf(),
        });
    }
    let recorded =
        Provenance::from_attributes(&h.attributes).map_err(|source| Error::BadProvenance {
            path: input.to_path_buf(),
            source,
        })?;
    let (observer, own) = (
        recorded.observer_or_default(),
        recorded.illuminant_or_default(),
    );
    let light = options.illuminant.unwrap_or(own);
    // As every reader: the spectra interpolated onto the observer's 1 nm table, where both
    // illuminants' tables reach (the layout's reference integration, so K = 0 is `to-rgb`).
    let limits = [own.range(), light.range()]
        .into_iter()
        .flatten()
        .reduce(|a, b| (a.0.max(b.0), a.1.min(b.1)));
    let colorimetry = |e| Error::Colorimetry(e);
    let onto = Onto::new(&h.wavelengths, limits).map_err(colorimetry)?;
    let grid = onto.grid;
    let texture = Colorimetry::new(grid, observer, own).map_err(colorimetry)?;
    let lit = Colorimetry::new(grid, observer, light).map_err(colorimetry)?;
    let bounce = SelfBounce::new(&texture, &lit, options.bounces)?;

    let to_display = SRGB.from_xyz(SRGB.white_xyz());
    let mut display = vec![[0u8; 3]; h.width * h.height];
    let mut delta_e = vec![0.0f64; h.width * h.height];
    while let Some(block) = reader.next_block() {
        let b = block.map_err(read_error)?;
        let shaded = shade_pixels(
            &b.bands,
            b.width * b.height,
            (&onto, &bounce, &to_display),
            options.diff_rgb,
        );
        for (row, values) in shaded.chunks_exact(b.width).enumerate() {
            let start = (b.y + row) * h.width + b.x;
            for (i, (d, e)) in values.iter().enumerate() {
                display[start + i] = *d;
                delta_e[start + i] = *e;
            }
        }
    }
    let non_finite = delta_e.iter().filter(|d| d.is_nan()).count();
    Ok(Shaded {
        width: h.width,
        height: h.height,
        light,
        display,
        delta_e,
        non_finite,
        emission: None,
    })
}

/// An emission file as its own colour: each pixel's XYZ as `to-rgb` integrates it (the units
/// it records), as display sRGB.
fn shade_emission(input: &Path, mut reader: BlockReader) -> Result<Shaded, Error> {
    let h = reader.header().clone();
    let recorded =
        Provenance::from_attributes(&h.attributes).map_err(|source| Error::BadProvenance {
            path: input.to_path_buf(),
            source,
        })?;
    let units = recorded.emission_convention().0;
    let integration = units
        .integration(&h.wavelengths, recorded.observer_or_default())
        .map_err(Error::Colorimetry)?;
    let to_display = SRGB.from_xyz(SRGB.white_xyz());
    let mut display = vec![[0u8; 3]; h.width * h.height];
    let mut non_finite = 0;
    while let Some(block) = reader.next_block() {
        let b = block.map_err(|source| Error::Read {
            path: input.to_path_buf(),
            source,
        })?;
        let xyz = crate::to_rgb::xyz_of_block(&b, &[], &integration, None);
        for (p, c) in xyz.chunks_exact(3).enumerate() {
            let (x, y) = (b.x + p % b.width, b.y + p / b.width);
            let c = [c[0], c[1], c[2]].map(f64::from);
            if !c.iter().all(|v| v.is_finite()) {
                non_finite += 1;
                continue;
            }
            display[y * h.width + x] = apply(&to_display, c)
                .map(|v| (srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8);
        }
    }
    Ok(Shaded {
        width: h.width,
        height: h.height,
        light: recorded.illuminant_or_default(),
        display,
        delta_e: vec![0.0; h.width * h.height],
        non_finite,
        emission: Some(units),
    })
}

/// Per pixel of `bands` (planes of `pixels` values): display sRGB (`to_display`: XYZ to linear
/// sRGB) after the bounces and, with `diff_rgb`, the CIEDE2000 from RGB multiplication (NaN
/// where the pixel is not finite).
fn shade_pixels(
    bands: &[Vec<f32>],
    pixels: usize,
    (onto, bounce, to_display): (&Onto, &SelfBounce, &[[f64; 3]; 3]),
    diff_rgb: bool,
) -> Vec<([u8; 3], f64)> {
    let white = bounce.white();
    (0..pixels)
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![0f32; bands.len()],
                    vec![0f64; onto.grid.len()],
                    vec![0f32; onto.grid.len()],
                )
            },
            |(values, fine, r), p| {
                for (v, plane) in values.iter_mut().zip(bands) {
                    *v = plane[p];
                }
                if !values.iter().all(|v| v.is_finite()) {
                    return ([0; 3], f64::NAN);
                }
                onto.apply(values, fine);
                r.iter_mut()
                    .zip(fine.iter())
                    .for_each(|(r, &v)| *r = v as f32);
                let xyz = bounce.spectral(r);
                let display = apply(to_display, xyz)
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
