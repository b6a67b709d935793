//! Compact texels of pixels a renderer's reader has decoded, made in memory (Mitsuba's
//! `specconv_rgb`): no file is written or read back. A conversion's colour rule on the file's
//! header read without OpenImageIO ([`Header::read`], [`colour::header_space`]: the same colour space and route
//! as `convert` for the same file and config), the samples as stored (where the reader
//! converted an OpenEXR's chromaticities, the file's own samples are read), its alpha rule (straight colour multiplied
//! by alpha once converted, as OpenEXR stores colour) and its rule on NaN and infinities, then
//! the compact layout's encoder ([`Compact::texels_of_rgb`], the one `convert --layout compact`
//! calls), in parallel pieces; integer pixels once per distinct pixel.

use crate::choices::{Alpha, NonFinite};
use crate::colour::{self, Decoded, Header, InputSpace};
use crate::error::{Error, Result};
use crate::Options;
use rayon::prelude::*;
use specconv_spectral::compact::{Compact, Precision, TEXEL};
use specconv_spectral::key_hash::KeyHash;
use std::collections::HashMap;

/// Pixels per parallel piece: large enough that a piece outweighs its scheduling.
const PIECE: usize = 4096;

/// A decoded image's samples, row-major, `channels` a pixel: integers are scaled to [0, 1] as
/// OpenImageIO scales them for a conversion (value × (1 / max), in float32).
#[derive(Debug, Clone, Copy)]
pub enum Samples<'a> {
    /// 8-bit.
    U8(&'a [u8]),
    /// 16-bit.
    U16(&'a [u16]),
    /// float32 (a reader's half samples widened).
    F32(&'a [f32]),
}

impl Samples<'_> {
    fn len(&self) -> usize {
        match self {
            Samples::U8(s) => s.len(),
            Samples::U16(s) => s.len(),
            Samples::F32(s) => s.len(),
        }
    }

    /// Pixel `p`'s samples of `channels` packed in one number (integer samples only: up to
    /// four of 16 bits).
    #[inline]
    fn key(&self, p: usize, channels: usize) -> u64 {
        let at = p * channels;
        match self {
            Samples::U8(s) => s[at..at + channels]
                .iter()
                .fold(0, |k, &v| (k << 16) | u64::from(v)),
            Samples::U16(s) => s[at..at + channels]
                .iter()
                .fold(0, |k, &v| (k << 16) | u64::from(v)),
            Samples::F32(_) => unreachable!("float samples are not keyed"),
        }
    }

    #[inline]
    fn get(&self, i: usize) -> f32 {
        match self {
            Samples::U8(s) => f32::from(s[i]) * (1.0 / 255.0),
            Samples::U16(s) => f32::from(s[i]) * (1.0 / 65535.0),
            Samples::F32(s) => s[i],
        }
    }
}

/// A decoded image: its samples and what the reader says of them.
#[derive(Debug, Clone, Copy)]
pub struct Image<'a> {
    /// The samples.
    pub samples: Samples<'a>,
    /// Samples a pixel: 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGB, alpha).
    pub channels: usize,
    /// The file and its size.
    pub decoded: Decoded<'a>,
    /// The reader says its alpha is straight (PNG); else premultiplied (OpenEXR).
    pub straight_alpha: bool,
    /// The reader converts an OpenEXR's `chromaticities` to other primaries (Mitsuba's
    /// `Bitmap` moves them to Rec.709 keeping XYZ): the samples of such a file are not the
    /// file's, and are read from it instead.
    pub moves_chromaticities: bool,
}

/// What making the texels found.
#[derive(Debug)]
#[non_exhaustive]
pub struct Made {
    /// The colour space the pixels were read in, and the rule that chose it.
    pub space: InputSpace,
    /// The texels.
    pub texels: Texels,
}

/// The texels made: each pixel's, or a palette of them.
#[derive(Debug)]
pub enum Texels {
    /// Six values a pixel, row-major.
    Every(Vec<f32>),
    /// Each pixel's number (a whole float32) and the spectra at the bands of the distinct
    /// pixels' texels, `compact.grid().len()` values each: a renderer's palette
    /// ([`crate::palette`], whose rule on its size it follows).
    Palette {
        /// One a pixel.
        numbers: Vec<f32>,
        /// One a number.
        spectra: Vec<f32>,
    },
}

/// Makes the compact texels of `image` with `options`' colour space, alpha and NaN rules and
/// `compact`'s encoder. With `palette`, where the distinct pixels are few enough for a
/// renderer's palette ([`crate::palette`]'s rule), it is made from them directly: no texel is
/// written per pixel and no texel hashed again. A data texture (a data space named, or one
/// channel: the data-map rule) is [`Error::Data`]; a NaN or infinite sample, unless `options`
/// keep or blacken them, [`Error::NonFinite`].
pub fn compact_texels(
    config: &specconv_ocio::Config,
    image: &Image,
    options: &Options,
    compact: &Compact,
    palette: bool,
) -> Result<Made> {
    let (w, h) = image.decoded.size;
    let pixels = w as usize * h as usize;
    let c = image.channels;
    if !(1..=4).contains(&c) || image.samples.len() != pixels * c {
        return Err(Error::InMemory(format!(
            "{} samples of {c} channel(s) for {w}×{h} pixels: expected 1 to 4 channels (grey, \
             grey and alpha, RGB, RGBA) and a sample per channel and pixel",
            image.samples.len(),
        )));
    }
    let integer = !matches!(image.samples, Samples::F32(_));
    let header = Header::read(image.decoded.path, image.decoded.size, integer)?;
    let stored;
    let image = &match stored_samples(image, &header)? {
        Some(s) => {
            stored = s;
            Image {
                samples: Samples::F32(&stored.samples),
                channels: stored.channels,
                ..*image
            }
        }
        None => *image,
    };
    let c = image.channels;
    let colour = if c <= 2 { 1 } else { 3 };
    let space = colour::header_space(config, &header, colour, options.colorspace.as_deref())?;
    let policy = options.non_finite;
    match policy {
        NonFinite::Refuse => refuse_non_finite(image)?,
        NonFinite::Box3 => {
            return Err(Error::InMemory(
                "non_finite 'box3' repairs a file as it is read; here refuse, black or keep \
                 apply (or convert the file with --fixnan box3 and use its compact texture)"
                    .into(),
            ))
        }
        NonFinite::Black | NonFinite::Keep => {}
    }
    let alpha = (c == 2 || c == 4).then_some(c - 1);
    let premultiply = alpha.is_some()
        && match options.alpha {
            Alpha::Auto => image.straight_alpha,
            Alpha::Straight => true,
            Alpha::Premultiplied => false,
        };
    let making = Making {
        image,
        space: &space,
        compact,
        black: policy == NonFinite::Black,
        premultiply: alpha.filter(|_| premultiply),
    };
    let texels = match distinct(image) {
        // Each distinct pixel made once, then decoded once for a palette ...
        Some((firsts, numbers)) => {
            let mut made = vec![0.0f32; firsts.len() * TEXEL];
            making.make(&|j| firsts[j], &mut made)?;
            if palette && firsts.len() <= crate::palette::most(compact, pixels) {
                Texels::Palette {
                    numbers: numbers.par_iter().map(|&j| j as f32).collect(),
                    spectra: crate::palette::spectra(compact, &made),
                }
            } else {
                // ... or copied to every pixel that has it.
                let mut out = vec![0.0f32; pixels * TEXEL];
                out.par_chunks_mut(TEXEL)
                    .zip(numbers.par_iter())
                    .for_each(|(t, &j)| {
                        let j = j as usize;
                        t.copy_from_slice(&made[j * TEXEL..(j + 1) * TEXEL]);
                    });
                Texels::Every(out)
            }
        }
        None => {
            let mut out = vec![0.0f32; pixels * TEXEL];
            making.make(&|p| p, &mut out)?;
            Texels::Every(out)
        }
    };
    Ok(Made { space, texels })
}

/// The file's own samples where the reader converted them (an OpenEXR whose
/// `chromaticities` it moved to other primaries): read from the file as stored, so the
/// colour space's route applies to what the file holds, as in a conversion.
fn stored_samples(image: &Image, header: &Header) -> Result<Option<specconv_exr::RgbaSamples>> {
    if !image.moves_chromaticities || header.chromaticities.is_none() || image.channels < 3 {
        return Ok(None);
    }
    let path = image.decoded.path;
    let stored = specconv_exr::read_rgba(path).map_err(|e| {
        Error::InMemory(format!(
            "{}: its reader converted its colour by its chromaticities, and its own R, G, B \
             samples cannot be read ({e}); convert it with specconv convert --layout compact \
             and use specconv_compact",
            path.display()
        ))
    })?;
    let (w, h) = image.decoded.size;
    if stored.size != (w as usize, h as usize) {
        return Err(Error::InMemory(format!(
            "{}: its reader decoded {w}×{h} pixels and the file's first R, G, B layer has \
             {}×{}; convert it with specconv convert --layout compact and use \
             specconv_compact",
            path.display(),
            stored.size.0,
            stored.size.1
        )));
    }
    Ok(Some(stored))
}

/// What makes texels of an image's pixels.
struct Making<'a> {
    image: &'a Image<'a>,
    space: &'a InputSpace,
    compact: &'a Compact,
    /// NaN and infinities become 0.
    black: bool,
    /// The alpha channel, where the colour is multiplied by it once converted.
    premultiply: Option<usize>,
}

impl Making<'_> {
    /// The texels of the pixels `pixel(j)` into `out` (texel j at `out[6j..]`), in parallel
    /// pieces: each piece's colours converted to the working space
    /// ([`crate::colour::ToXyz::apply_to_working`]), multiplied by alpha where straight, and
    /// encoded.
    fn make(&self, pixel: &(dyn Fn(usize) -> usize + Sync), out: &mut [f32]) -> Result<()> {
        let (image, c) = (self.image, self.image.channels);
        let sample = |at: usize| match image.samples.get(at) {
            v if self.black && !v.is_finite() => 0.0,
            v => v,
        };
        out.par_chunks_mut(PIECE * TEXEL)
            .enumerate()
            .try_for_each(|(i, texels)| {
                let count = texels.len() / TEXEL;
                let mut rgb = Vec::with_capacity(count * 3);
                let mut a = Vec::with_capacity(count);
                for j in i * PIECE..i * PIECE + count {
                    let at = pixel(j) * c;
                    rgb.extend_from_slice(&match c {
                        1 | 2 => [sample(at); 3],
                        _ => [sample(at), sample(at + 1), sample(at + 2)],
                    });
                    if let Some(k) = self.premultiply {
                        a.push(sample(at + k));
                    }
                }
                // As a `-d float` file stores them: the unrounded colour in the working space.
                self.space.to_xyz.apply_to_working(self.compact, &mut rgb)?;
                for (v, alpha) in rgb.chunks_exact_mut(3).zip(&a) {
                    v.iter_mut().for_each(|v| *v *= alpha);
                }
                self.compact.texels_of_rgb(&rgb, Precision::Float, texels);
                Ok(())
            })
    }
}

/// At most this share of an image's pixels distinct, its texels are made once per distinct
/// pixel (a 2048² photograph: 352,000 of 4.2 million): a texel is a function of its pixel's
/// samples alone. Beyond it (noise), the map is dropped and every pixel made.
const DISTINCT_SHARE: usize = 4;

/// The distinct pixels of an image of integer samples (the first pixel of each, in order)
/// and each pixel's number among them by its samples ([`Samples::key`]); `None` for float
/// samples, or more than [`DISTINCT_SHARE`] of the pixels distinct.
fn distinct(image: &Image) -> Option<(Vec<usize>, Vec<u32>)> {
    if matches!(image.samples, Samples::F32(_)) {
        return None;
    }
    let pixels = image.samples.len() / image.channels;
    let most = pixels / DISTINCT_SHARE;
    let mut index: HashMap<u64, u32, KeyHash> = HashMap::with_hasher(KeyHash::default());
    let mut firsts = Vec::new();
    let mut numbers = Vec::with_capacity(pixels);
    let mut last = None;
    for p in 0..pixels {
        let key = image.samples.key(p, image.channels);
        // Neighbours repeat: the pixel before answers without a hash.
        let j = match last {
            Some((k, j)) if k == key => j,
            _ => *index.entry(key).or_insert_with(|| {
                firsts.push(p);
                (firsts.len() - 1) as u32
            }),
        };
        if firsts.len() > most {
            return None;
        }
        numbers.push(j);
        last = Some((key, j));
    }
    Some((firsts, numbers))
}

/// [`Error::NonFinite`] where a sample (colour or alpha) is NaN or infinite: the rule a
/// conversion refuses them by (`--fixnan` unset).
fn refuse_non_finite(image: &Image) -> Result<()> {
    let Samples::F32(s) = image.samples else {
        return Ok(()); // integers are finite
    };
    let c = image.channels;
    let bad = |p: &[f32]| !p.iter().all(|v| v.is_finite());
    let pixels = s.par_chunks(c).filter(|p| bad(p)).count() as u64;
    if pixels == 0 {
        return Ok(());
    }
    let first = s.chunks(c).position(bad).expect("counted");
    let width = image.decoded.size.0 as usize;
    Err(Error::NonFinite {
        input: image.decoded.path.to_path_buf(),
        pixels,
        first: (first % width, first / width),
        rows: (0, image.decoded.size.1 as usize),
    })
}
