//! One block of level 0 made from the input's pixels ([`Reading`]): repaired, converted to
//! colour and uplifted to spectra, then finished ([`crate::blocks`]).

use crate::blocks::{finish_block, level_sums, Counts, Made};
use crate::colour::ToXyz;
use crate::error::{Error, Result};
use crate::job::Job;
use crate::survey;
use specconv_exr::{Block, SpectralFile};
use std::sync::atomic::Ordering;

/// Values above this count as above 1: 0.1 % of headroom, so that the rounding of colour
/// conversion does not make white count.
pub const ABOVE_ONE: f32 = 1.001;

/// A pixel's RGB from its colour channels (`input::Channels::colour`): a single grey channel is repeated; `None` when
/// the image has no colour channel.
#[inline]
pub fn colour_of(px: &[f32], colour: &[usize]) -> Option<[f32; 3]> {
    match colour {
        [r, g, b] => Some([px[*r], px[*g], px[*b]]),
        [grey, ..] => Some([px[*grey]; 3]),
        [] => None,
    }
}

/// How a strip's pixels become colour: the channels read, their repair, the conversion.
pub struct Reading<'a> {
    pub(crate) to_xyz: &'a ToXyz,
    pub(crate) colour: &'a [usize],
    pub(crate) alpha: Option<usize>,
    /// The colour is straight: multiplied by alpha once converted, as OpenEXR stores colour
    /// premultiplied.
    pub(crate) premultiply: bool,
    pub(crate) repair: &'a survey::Repair,
}

/// Uplifts one block of a strip whose first row is row `strip_y` of level 0: its spectra, its
/// alpha (when read) and what its pixels had.
fn uplift_block(
    job: &Job,
    reading: &Reading,
    b: &Block,
    strip: &specconv_oiio::Pixels,
    strip_y: usize,
) -> Result<(Vec<f32>, Option<Vec<f32>>, Counts)> {
    let count = b.width * b.height;
    let mut rgb = Vec::with_capacity(count * 3);
    let mut a = reading.alpha.map(|_| Vec::with_capacity(count));
    let mut counts = Counts::default();
    let mut fixed: Vec<f32>;
    for y in 0..b.height {
        for x in b.x..b.x + b.width {
            let mut px = strip.pixel(x as u32, y as u32);
            if reading.repair.fixes(px, reading.colour, reading.alpha) {
                fixed = reading
                    .repair
                    .fixed(px, (reading.colour, reading.alpha), (x, strip_y + y));
                px = &fixed;
            }
            rgb.extend_from_slice(&colour_of(px, reading.colour).unwrap_or([0.0; 3]));
            if let (Some(a), Some(c)) = (a.as_mut(), reading.alpha) {
                a.push(px[c]);
            }
        }
    }
    // Above 1: by an input channel, or by Y after the conversion.
    let channel_above: Vec<bool> = rgb
        .chunks_exact(3)
        .map(|c| c.iter().any(|&v| v > ABOVE_ONE))
        .collect();
    // A compact file's colour goes to its working space (straight where it is the input's).
    match &job.storage.compact {
        Some(compact) => reading.to_xyz.apply_to_working(compact, &mut rgb)?,
        None => reading.to_xyz.apply_rgb(&mut rgb)?,
    }
    if let (true, Some(a)) = (reading.premultiply, &a) {
        for (c, alpha) in rgb.chunks_exact_mut(3).zip(a) {
            c.iter_mut().for_each(|v| *v *= alpha);
        }
    }
    for (c, above) in rgb.chunks_exact(3).zip(&channel_above) {
        let y = match &job.storage.compact {
            Some(compact) => compact.colour_of([c[0], c[1], c[2]])[1],
            None => c[1],
        };
        counts.non_finite += u64::from(!c.iter().all(|v| v.is_finite()));
        counts.above_one += u64::from(*above || y > ABOVE_ONE);
    }
    let n = job.values();
    let mut bands = vec![0.0f32; count * n];
    match &job.storage.compact {
        // The colour in the working space, unrounded: the smaller levels are filtered from
        // it (as maketx filters), and each level is stored at the end (`store_compact`).
        Some(_) => {
            for (t, c) in bands.chunks_exact_mut(n).zip(rgb.chunks_exact(3)) {
                t[..3].copy_from_slice(c);
            }
        }
        None => job
            .method()
            .uplift_f32_tallied(&rgb, &mut bands, &mut counts.tally),
    }
    Ok((bands, a, counts))
}

/// Colour-converts, uplifts and compresses one block from its strip's pixels; `resized`: only
/// uplifts it, keeping its spectra for the level 0 made of them.
pub(crate) fn encode_block(
    file: &SpectralFile,
    job: &Job,
    reading: &Reading,
    b: &Block,
    strip: &specconv_oiio::Pixels,
    resized: bool,
) -> Result<Made> {
    let (bands, a, mut counts) = uplift_block(job, reading, b, strip, b.y)?;
    let n = job.values();
    // Compressing a fine-band block takes as long as uplifting it.
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    // The smaller levels are filtered from the spectra before they are rounded.
    let kept = (file.levels() > 1 || resized).then(|| match &a {
        Some(a) => bands
            .chunks_exact(n)
            .zip(a)
            .flat_map(|(s, &alpha)| s.iter().copied().chain([alpha]))
            .collect(),
        None => bands.clone(),
    });
    if resized {
        return Ok(Made {
            index: b.chunk,
            chunk: None,
            counts,
            kept,
            sums: Vec::new(),
        });
    }
    let mut bands = bands;
    if let Some(compact) = &job.storage.compact {
        counts.tally.bounded += compact.store(&mut bands, job.storage.precision);
    }
    // Level 0's sums, before rounding, for the average.
    let sums = level_sums(&bands, a.as_deref(), n);
    let (chunk, saturated) = finish_block(file, job, b, bands, a.as_deref())?;
    counts.saturated = saturated;
    Ok(Made {
        index: b.chunk,
        chunk: Some(chunk),
        counts,
        kept,
        sums,
    })
}
