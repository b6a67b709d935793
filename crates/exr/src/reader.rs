//! Spectral files read whole ([`read`], [`read_level`]) and plain RGBA files read as stored
//! ([`read_rgba`]).

use crate::blocks;
use crate::channels::ChannelKinds;
use crate::error::{Error, Result};
use crate::spec::Kind;

/// A spectral image read whole (for previews, conversion back to colour and tests).
#[derive(Debug, Clone)]
pub struct SpectralImage {
    /// Width of the image in pixels (of its data window, largest level).
    pub width: usize,
    /// Height of the image in pixels.
    pub height: usize,
    /// Band wavelengths in nm, increasing; `bands[i]` is the plane of `wavelengths[i]`.
    pub wavelengths: Vec<f64>,
    /// Reflective when the file has `T.` bands (those are read), else emissive with the file's
    /// `emissiveUnits` (empty when it has none).
    pub kind: Kind,
    /// One plane per band, row-major: `T.` channels, else `S0.` channels.
    pub bands: Vec<Vec<f32>>,
    /// Re-radiation planes of a bispectral file: (from band, to band, plane), indices into
    /// `wavelengths`; empty otherwise.
    pub reradiation: Vec<(usize, usize, Vec<f32>)>,
    /// The `A` plane, row-major like the bands; `None` when the file has no `A` channel.
    pub alpha: Option<Vec<f32>>,
    /// Every channel by kind, as [`ChannelKinds::of`] sees the names (also what was not read).
    pub channel_kinds: ChannelKinds,
    /// Text attributes of the header.
    pub attributes: Vec<(String, String)>,
    /// Number of MIP levels in the file (1 when it has none).
    pub levels: usize,
}

/// Reads the largest level of a spectral EXR: its `T.` bands (with re-radiation, if any), else
/// its `S0.` bands. Polarisation (S1–S3), emission beside reflectance and channels outside
/// the layout are listed in [`SpectralImage::channel_kinds`], not read.
pub fn read(path: &std::path::Path) -> Result<SpectralImage> {
    read_level(path, 0)
}

/// As [`read`], MIP level `level` of the file (0 is the largest; [`blocks::Header::levels`]
/// says how many there are).
pub fn read_level(path: &std::path::Path, level: usize) -> Result<SpectralImage> {
    let mut reader = blocks::BlockReader::open_level(path, level)?;
    let header = reader.header().clone();
    let plane = || vec![0.0f32; header.width * header.height];
    let mut bands = vec![plane(); header.wavelengths.len()];
    let mut rerad = vec![plane(); header.reradiation.len()];
    let mut alpha = header.alpha.then(plane);
    while let Some(b) = reader.next_block() {
        let b = b?;
        if b.x + b.width > header.width || b.y + b.height > header.height || b.width == 0 {
            return Err(Error::Invalid(format!(
                "{}: a block at ({}, {}) of {}×{} lies outside the {}×{} image",
                path.display(),
                b.x,
                b.y,
                b.width,
                b.height,
                header.width,
                header.height
            )));
        }
        let place = |to: &mut Vec<f32>, from: &[f32]| {
            for (row, values) in from.chunks_exact(b.width).enumerate() {
                let start = (b.y + row) * header.width + b.x;
                to[start..start + b.width].copy_from_slice(values);
            }
        };
        for (to, from) in bands.iter_mut().zip(&b.bands) {
            place(to, from);
        }
        for (to, from) in rerad.iter_mut().zip(&b.reradiation) {
            place(to, from);
        }
        if let (Some(to), Some(from)) = (alpha.as_mut(), &b.alpha) {
            place(to, from);
        }
    }
    Ok(SpectralImage {
        width: header.width,
        height: header.height,
        wavelengths: header.wavelengths,
        kind: header.kind,
        bands,
        reradiation: header
            .reradiation
            .into_iter()
            .zip(rerad)
            .map(|((from, to), p)| (from, to, p))
            .collect(),
        alpha,
        channel_kinds: header.channel_kinds,
        attributes: header.attributes,
        levels: header.levels,
    })
}

/// An OpenEXR file's R, G, B (and A) samples as stored, widened to float32 (half widens
/// exactly): no colour conversion, whatever its header declares.
#[derive(Debug, Clone)]
pub struct RgbaSamples {
    /// Width and height.
    pub size: (usize, usize),
    /// 3 (R, G, B) or 4 (and A).
    pub channels: usize,
    /// Row-major, `channels` a pixel.
    pub samples: Vec<f32>,
}

/// The R, G, B and A channels of the first layer of an OpenEXR file that has them, full
/// resolution, as stored.
pub fn read_rgba(path: &std::path::Path) -> Result<RgbaSamples> {
    use exr::image::read::image::ReadLayers as _;
    use exr::image::read::layers::ReadChannels as _;
    let file = std::io::BufReader::new(specconv_atomic_file::open_file(path)?);
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, channels: &exr::image::RgbaChannels| {
                let c = if channels.3.is_some() { 4 } else { 3 };
                RgbaSamples {
                    size: (size.width(), size.height()),
                    channels: c,
                    samples: vec![0.0; size.area() * c],
                }
            },
            |out: &mut RgbaSamples, at, (r, g, b, a): (f32, f32, f32, f32)| {
                let c = out.channels;
                let i = (at.y() * out.size.0 + at.x()) * c;
                out.samples[i..i + 3].copy_from_slice(&[r, g, b]);
                if c == 4 {
                    out.samples[i + 3] = a;
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(file)?;
    Ok(image.layer_data.channel_data.pixels)
}
