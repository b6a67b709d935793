//! Compact texels of pixels a renderer's reader has decoded, made in memory (Mitsuba's
//! `specconv_rgb`): no file is written or read back. A conversion's rules as far as the reader
//! kept the evidence ([`colour::decoded_space`]), its alpha rule (straight colour multiplied
//! by alpha once converted, as OpenEXR stores colour) and its rule on NaN and infinities, then
//! the compact layout's encoder ([`Compact::encode_f32`], the one `convert --layout compact`
//! calls), in parallel pieces.

use crate::choices::{Alpha, NonFinite};
use crate::colour::{self, Decoded, InputSpace};
use crate::{Error, Options, Result};
use rayon::prelude::*;
use specconv_spectral::bounded::Counts;
use specconv_spectral::compact::{Compact, TEXEL};

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
    /// What the reader says of the colour; its `colour_channels` follows from `channels`.
    pub decoded: Decoded<'a>,
    /// The reader says its alpha is straight (PNG); else premultiplied (OpenEXR).
    pub straight_alpha: bool,
}

/// What making the texels found.
#[derive(Debug)]
#[non_exhaustive]
pub struct Made {
    /// The colour space the pixels were read in, and the rule that chose it.
    pub space: InputSpace,
    /// The bounded projection's outcomes.
    pub bounded: Counts,
}

/// Makes the compact texels of `image` (six values a pixel, row-major) into `out`, with
/// `options`' colour space, alpha and NaN rules and `compact`'s encoder. A data texture (a
/// data space named, or one channel: the data-map rule) is [`Error::Data`]; a NaN or
/// infinite sample, unless `options` keep or blacken them, [`Error::NonFinite`].
pub fn compact_texels(
    config: &specconv_ocio::Config,
    image: &Image,
    options: &Options,
    compact: &Compact,
    out: &mut [f32],
) -> Result<Made> {
    let c = image.channels;
    let (w, h) = image.decoded.size;
    let pixels = w as usize * h as usize;
    if !(1..=4).contains(&c) || image.samples.len() != pixels * c || out.len() != pixels * TEXEL {
        return Err(Error::InMemory(format!(
            "{} samples of {c} channel(s) for {w}×{h} pixels and room for {} values: expected \
             1 to 4 channels (grey, grey and alpha, RGB, RGBA), a sample per channel and \
             pixel, and {TEXEL} values a pixel",
            image.samples.len(),
            out.len()
        )));
    }
    let decoded = Decoded {
        colour_channels: if c <= 2 { 1 } else { 3 },
        ..image.decoded
    };
    let space = colour::decoded_space(config, &decoded, options.colorspace.as_deref())?;
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
    let piece = |(i, texels): (usize, &mut [f32])| -> Result<Counts> {
        let first = i * PIECE;
        let count = texels.len() / TEXEL;
        let mut xyz = Vec::with_capacity(count * 3);
        let mut a = Vec::with_capacity(if premultiply { count } else { 0 });
        let black = |v: f32| match policy {
            NonFinite::Black if !v.is_finite() => 0.0,
            _ => v,
        };
        for p in first..first + count {
            let at = p * c;
            let rgb = match c {
                1 | 2 => [black(image.samples.get(at)); 3],
                _ => [0, 1, 2].map(|k| black(image.samples.get(at + k))),
            };
            xyz.extend_from_slice(&rgb);
            if let (true, Some(k)) = (premultiply, alpha) {
                a.push(black(image.samples.get(at + k)));
            }
        }
        space.to_xyz.apply_rgb(&mut xyz)?;
        for (v, alpha) in xyz.chunks_exact_mut(3).zip(&a) {
            v.iter_mut().for_each(|v| *v *= alpha);
        }
        Ok(compact.encode_f32(&xyz, texels))
    };
    let counts: Vec<Counts> = out
        .par_chunks_mut(PIECE * TEXEL)
        .enumerate()
        .map(piece)
        .collect::<Result<_>>()?;
    let mut bounded = Counts::default();
    for c in counts {
        bounded += c;
    }
    Ok(Made { space, bounded })
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
