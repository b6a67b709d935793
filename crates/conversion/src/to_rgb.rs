//! A spectral EXR integrated back to colour: XYZ as every reader of the layout integrates it,
//! then a colour space of the OCIO config, written as an RGB(A) OpenEXR. The input is read
//! block by block; only the colour result (three floats a pixel, and alpha) is held.

use crate::error::ConversionError;
use crate::provenance::{ConventionFrom, Provenance};
use crate::Error;
use specconv_atomic_file::{PlanError, Replace};
use specconv_colour::{EmissionUnits, Illuminant, Integration, Observer};
use specconv_exr::blocks::{Block, BlockReader};
use specconv_exr::Kind;
use specconv_ocio::Config;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// What `to-rgb` is asked to do.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ToRgbOptions {
    /// The OCIO config (as [`crate::Options::ocio`]).
    pub ocio: Option<String>,
    /// The output's colour space (`None`: the config's `scene_linear` role).
    pub colorspace: Option<String>,
    /// Light reflectances under this illuminant instead of the file's own (reflectance only).
    pub illuminant: Option<Illuminant>,
    /// Replace an existing output.
    pub overwrite: bool,
}

/// The light a file's values became colour under.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// Emission: its own light, in a units convention, and why that one.
    Emission(EmissionUnits, ConventionFrom),
    /// Reflectance under an illuminant, with this many re-radiation (bispectral) channels.
    Illuminant(Illuminant, usize),
}

/// What an integration did.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RgbReport {
    /// Width of the image.
    pub width: usize,
    /// Height of the image.
    pub height: usize,
    /// The band wavelengths read, nm.
    pub wavelengths: Vec<f64>,
    /// The light.
    pub light: Light,
    /// The observer.
    pub observer: Observer,
    /// The output's colour space.
    pub colorspace: String,
    /// The file holds polarisation (S1–S3), not used.
    pub polarised: bool,
    /// The file's emission beside its reflectance was not included.
    pub emission_left_out: bool,
    /// Channels outside the spectral layout, not used (an RGB preview beside the spectra).
    pub unused_channels: Vec<String>,
}

/// An integration set up once: the config loaded and the output colour space checked.
pub struct ToRgb {
    options: ToRgbOptions,
    config: Config,
}

impl ToRgb {
    /// Loads the config and checks the output colour space.
    pub fn new(options: ToRgbOptions) -> Result<ToRgb, Error> {
        let config = Config::resolve(options.ocio.as_deref())?;
        if let Some(name) = &options.colorspace {
            config.color_space(name)?;
        }
        Ok(ToRgb { options, config })
    }

    /// Integrates `input` and writes `output`.
    pub fn convert(&self, input: &Path, output: &Path) -> Result<RgbReport, Error> {
        self.convert_cancellable(input, output, &AtomicBool::new(false))
    }

    /// As [`ToRgb::convert`]; setting `cancel` (from a signal handler, another thread) stops
    /// it between blocks of the input or before the output is published, with
    /// [`Error::is_cancelled`] and nothing written.
    pub fn convert_cancellable(
        &self,
        input: &Path,
        output: &Path,
        cancel: &AtomicBool,
    ) -> Result<RgbReport, Error> {
        let cancelled = || -> Result<(), Error> {
            if cancel.load(Ordering::SeqCst) {
                return Err(Error::Conversion(ConversionError::Cancelled));
            }
            Ok(())
        };
        specconv_atomic_file::readable_file(input)?;
        specconv_atomic_file::check_plan(&[input], &[output], self.replace())?;
        let mut reader = BlockReader::open(input).map_err(read_error(input))?;
        let h = reader.header().clone();
        let recorded =
            Provenance::from_attributes(&h.attributes).map_err(|source| Error::BadProvenance {
                path: input.to_path_buf(),
                source,
            })?;
        let observer = recorded.observer_or_default();
        let emissive = matches!(h.kind, Kind::Emissive { .. });
        let light = self.light(input, &h, &recorded)?;
        let (integration, lit) = integration(&light, &h, observer)?;
        let (xyz_space, colorspace) = self.spaces()?;
        let processor = self.config.processor(&xyz_space, &colorspace)?;
        let declared = specconv_exr::rgb::Declaration {
            // The texture's metadata back, by the rule that carried it in.
            text: crate::metadata::of(h.attributes.clone()),
            ..declaration(&self.config, &colorspace, &xyz_space)?
        };
        let (mut rgb, alpha) = integrate(
            (&mut reader, &h, input),
            (&integration, lit.as_deref()),
            &cancelled,
        )?;
        processor.apply_rgb(&mut rgb)?;
        let image = ((h.width, h.height), rgb.as_slice(), alpha.as_deref());
        self.write(output, image, &declared, &cancelled)?;
        let kinds = &h.channel_kinds;
        Ok(RgbReport {
            width: h.width,
            height: h.height,
            wavelengths: h.wavelengths.clone(),
            light,
            observer,
            colorspace,
            polarised: kinds.polarised(),
            emission_left_out: !emissive && !kinds.stokes[0].is_empty(),
            unused_channels: kinds.other.clone(),
        })
    }

    fn replace(&self) -> Replace {
        Replace::when(self.options.overwrite)
    }

    /// The light the file's values become colour under: emission its own (in the units
    /// convention recorded), reflectance the illuminant asked for or the one recorded. An
    /// illuminant asked for emission is refused.
    fn light(
        &self,
        input: &Path,
        h: &specconv_exr::blocks::Header,
        recorded: &Provenance,
    ) -> Result<Light, Error> {
        let emissive = matches!(h.kind, Kind::Emissive { .. });
        Ok(match (self.options.illuminant, emissive) {
            (Some(_), true) => {
                return Err(Error::EmissionIsItsOwnLight {
                    input: input.to_path_buf(),
                })
            }
            (_, true) => {
                let (units, from) = recorded.emission_convention();
                Light::Emission(units, from)
            }
            (Some(i), false) => Light::Illuminant(i, h.reradiation.len()),
            (None, false) => {
                Light::Illuminant(recorded.illuminant_or_default(), h.reradiation.len())
            }
        })
    }

    /// The config's XYZ space and the output's colour space (asked for, or `scene_linear`).
    fn spaces(&self) -> Result<(String, String), Error> {
        let xyz_space = self
            .config
            .role("cie_xyz_d65_interchange")?
            .ok_or(Error::NoRole {
                role: "cie_xyz_d65_interchange",
                purpose: " to convert XYZ from",
            })?;
        let colorspace = match self.options.colorspace.clone() {
            Some(c) => c,
            None => self.config.role("scene_linear")?.ok_or(Error::NoRole {
                role: "scene_linear",
                purpose: "",
            })?,
        };
        Ok((xyz_space, colorspace))
    }

    /// Writes `rgb` (and alpha) of `size` to a temporary beside `output`, declared as
    /// `declared`, and publishes it unless cancelled by then.
    fn write(
        &self,
        output: &Path,
        (size, rgb, alpha): ((usize, usize), &[f32], Option<&[f32]>),
        declared: &specconv_exr::rgb::Declaration,
        cancelled: &dyn Fn() -> Result<(), Error>,
    ) -> Result<(), Error> {
        let write_error = |source| Error::Write {
            path: output.to_path_buf(),
            source,
        };
        let io_error = |e: std::io::Error| write_error(specconv_exr::Error::Exr(e.into()));
        let pending = specconv_atomic_file::Pending::beside(output).map_err(io_error)?;
        specconv_exr::rgb::write_rgb_declared(
            std::io::BufWriter::new(pending.file()),
            size,
            rgb,
            alpha,
            declared,
        )
        .map_err(write_error)?;
        // The last moment to stop: dropped, the temporary goes.
        cancelled()?;
        pending.publish(self.replace()).map_err(|e| match e.kind() {
            std::io::ErrorKind::AlreadyExists => Error::Plan(PlanError::Exists {
                output: output.to_path_buf(),
                more: 0,
            }),
            _ => io_error(e),
        })
    }
}

/// [`Error::Read`] of `input`.
fn read_error(input: &Path) -> impl Fn(specconv_exr::Error) -> Error + '_ {
    |source| crate::compact::spectral_read_error(input, source)
}

/// How the file's values become XYZ under `light`; and, for a bispectral file under an
/// illuminant, the light per band that its re-radiation is lit by.
fn integration(
    light: &Light,
    h: &specconv_exr::blocks::Header,
    observer: Observer,
) -> Result<(Integration, Option<Vec<f64>>), Error> {
    let integration = match light {
        Light::Emission(units, _) => units.integration(&h.wavelengths, observer),
        Light::Illuminant(i, _) => Integration::reflectance(&h.wavelengths, observer, *i),
    }
    .map_err(Error::Colorimetry)?;
    // Bispectral: band o reflects T(o)·I(o) and re-radiates T(i→o)·I(i) from each band i.
    let lit = match light {
        Light::Illuminant(i, _) if !h.reradiation.is_empty() => Some(
            specconv_colour::integration::illuminant_at(*i, &h.wavelengths)
                .map_err(Error::Colorimetry)?,
        ),
        _ => None,
    };
    Ok((integration, lit))
}

/// Every block of `reader` (the file `input`, its header `h`) integrated to XYZ: the image's
/// XYZ, three floats a pixel, and its alpha when it has one. `cancelled` is asked before each
/// block.
fn integrate(
    (reader, h, input): (&mut BlockReader, &specconv_exr::blocks::Header, &Path),
    (integration, lit): (&Integration, Option<&[f64]>),
    cancelled: &dyn Fn() -> Result<(), Error>,
) -> Result<(Vec<f32>, Option<Vec<f32>>), Error> {
    let mut rgb = vec![0.0f32; h.width * h.height * 3];
    let mut alpha = h.alpha.then(|| vec![0.0f32; h.width * h.height]);
    while let Some(block) = reader.next_block() {
        cancelled()?;
        let block = block.map_err(read_error(input))?;
        let xyz = xyz_of_block(&block, &h.reradiation, integration, lit);
        place(&mut rgb, h.width, &block, &xyz, 3);
        if let (Some(to), Some(from)) = (alpha.as_mut(), &block.alpha) {
            place(to, h.width, &block, from, 1);
        }
    }
    Ok((rgb, alpha))
}

/// D65 as OCIO's CIE-XYZ-D65 has it (x 0.3127, y 0.3290, Y = 1).
const D65: [f64; 3] = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];

/// What a file of values in `colorspace` declares, so that other readers (OpenImageIO,
/// colour-science, `info`) take them as that space: its name always; for a linear space its
/// `chromaticities` — the canonical ones of ACES2065-1 (with `acesImageContainerFlag`), ACEScg,
/// Rec.709 and Rec.2020 when the config's conversion is theirs (Bradford to D65), else the
/// primaries and white as the config places them in XYZ D65, which give the same conversion.
/// A non-linear space (an sRGB-encoded one) gets no chromaticities: they mean linear values.
fn declaration(
    config: &Config,
    colorspace: &str,
    xyz_space: &str,
) -> Result<specconv_exr::rgb::Declaration, Error> {
    use specconv_colour::rgb;
    let cs = config.color_space(colorspace)?;
    let mut declared = specconv_exr::rgb::Declaration {
        colorspace_name: Some(cs.name.clone()),
        ..Default::default()
    };
    if cs.is_data {
        return Ok(declared);
    }
    let to_xyz = config.processor(&cs.name, xyz_space)?;
    let xyz = |c: [f32; 3]| -> Result<[f64; 3], Error> { Ok(to_xyz.convert(c)?.map(f64::from)) };
    let columns = [
        xyz([1.0, 0.0, 0.0])?,
        xyz([0.0, 1.0, 0.0])?,
        xyz([0.0, 0.0, 1.0])?,
    ];
    let linear_at = |c: [f32; 3]| -> Result<bool, Error> {
        let got = xyz(c)?;
        Ok((0..3).all(|k| {
            let want: f64 = (0..3).map(|j| columns[j][k] * f64::from(c[j])).sum();
            (got[k] - want).abs() <= 1e-4
        }))
    };
    if !(linear_at([0.5, 0.5, 0.5])? && linear_at([0.2, 0.05, 0.7])?) {
        return Ok(declared);
    }
    let same = |m: &[[f64; 3]; 3]| {
        (0..3).all(|row| (0..3).all(|col| (m[row][col] - columns[col][row]).abs() <= 1e-4))
    };
    let xy = |v: [f64; 3]| {
        let sum = v[0] + v[1] + v[2];
        [(v[0] / sum) as f32, (v[1] / sum) as f32]
    };
    for space in [rgb::ACES2065_1, rgb::ACESCG, rgb::SRGB, rgb::REC2020] {
        if space.to_xyz_adapted(D65).is_some_and(|m| same(&m)) {
            let [[rx, ry], [gx, gy], [bx, by]] = space.primaries.map(|p| p.map(|v| v as f32));
            let [wx, wy] = space.white.map(|v| v as f32);
            declared.chromaticities = Some([rx, ry, gx, gy, bx, by, wx, wy]);
            declared.aces_container = space.primaries == rgb::ACES2065_1.primaries;
            return Ok(declared);
        }
    }
    let white = xyz([1.0, 1.0, 1.0])?;
    let [r, g, b, w] = [columns[0], columns[1], columns[2], white].map(xy);
    declared.chromaticities = Some([r[0], r[1], g[0], g[1], b[0], b[1], w[0], w[1]]);
    Ok(declared)
}

/// Copies a block's values (`per` a pixel) into the image's row-major buffer.
fn place(to: &mut [f32], width: usize, b: &Block, from: &[f32], per: usize) {
    for (row, values) in from.chunks_exact(b.width * per).enumerate() {
        let start = ((b.y + row) * width + b.x) * per;
        to[start..start + b.width * per].copy_from_slice(values);
    }
}

/// XYZ of every pixel of a block (three f32 a pixel) under `integration`; with `lit` (the light
/// per band), bispectral: band o reflects T(o)·I(o) and re-radiates T(i→o)·I(i) from each band i.
pub(crate) fn xyz_of_block(
    b: &Block,
    reradiation: &[(usize, usize)],
    integration: &Integration,
    lit: Option<&[f64]>,
) -> Vec<f32> {
    let pixels = b.width * b.height;
    let mut xyz = vec![0.0f32; pixels * 3];
    let mut r = vec![0.0f64; b.bands.len()];
    for p in 0..pixels {
        for (v, plane) in r.iter_mut().zip(&b.bands) {
            *v = plane[p] as f64;
        }
        if let Some(light) = lit {
            for ((i, o), plane) in reradiation.iter().zip(&b.reradiation) {
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

impl std::fmt::Debug for ToRgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ToRgb")
            .field("options", &self.options)
            .finish_non_exhaustive()
    }
}
