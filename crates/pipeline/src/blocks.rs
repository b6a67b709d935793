//! One block of the output finished: clamped where a filter pushed it out of range, summed for
//! the average, rounded as the file stores it and compressed; a smaller level's blocks are
//! made from their strip here.

use crate::error::{Error, Result};
use crate::filter::Kernel;
use crate::job::Job;
use crate::mip;
use specconv_exr::{Block, Chunk, Sample, SpectralFile};
use specconv_spectral::method::Tally;
use std::sync::atomic::Ordering;

/// What one block's pixels had; see [`Report`].
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Counts {
    pub(crate) non_finite: u64,
    pub(crate) above_one: u64,
    pub(crate) saturated: u64,
    pub(crate) clamped: u64,
    pub(crate) tally: Tally,
}

/// One block made: its chunk (none for the input's spectra that a resized level 0 is made
/// of), what its pixels had, and (for a MIP map) its values — the spectra before rounding,
/// alpha after each spectrum when the file has it — for the smaller levels.
pub(crate) struct Made {
    pub(crate) index: usize,
    pub(crate) chunk: Option<Chunk>,
    pub(crate) counts: Counts,
    pub(crate) kept: Option<Vec<f32>>,
    /// Level 0: the sums of its values, bands then alpha (for the average); else empty.
    pub(crate) sums: Vec<f64>,
}

/// Encodes one block of a smaller level from its strip's values.
pub(crate) fn encode_made_block(
    file: &SpectralFile,
    job: &Job,
    b: &Block,
    strip: &mip::MadeStrip,
) -> Result<Made> {
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    let n = job.values();
    let values = file.values_per_pixel();
    let mut bands = Vec::with_capacity(b.width * b.height * n);
    let mut a = file
        .spec()
        .alpha
        .then(|| Vec::with_capacity(b.width * b.height));
    for y in 0..b.height {
        let row = (y * strip.width + b.x) * values;
        for px in strip.rows[row..row + b.width * values].chunks_exact(values) {
            bands.extend_from_slice(&px[..n]);
            if let Some(a) = a.as_mut() {
                a.push(px[n]);
            }
        }
    }
    let clamped = keep_in_range(job, &mut bands, a.as_deref_mut(), n);
    if let Some(compact) = &job.storage.compact {
        // A smaller level holds the filtered colour, rounded, its dual unknowns solved again.
        compact.store(&mut bands, job.storage.precision);
    }
    // A resized level 0 is made here: its sums for the average, and its values beyond the half
    // range counted (a smaller level's come from one there).
    let level0 = strip.level == 0;
    let sums = if level0 {
        level_sums(&bands, a.as_deref(), n)
    } else {
        Vec::new()
    };
    let (chunk, saturated) = finish_block(file, job, b, bands, a.as_deref())?;
    Ok(Made {
        index: b.chunk,
        chunk: Some(chunk),
        counts: Counts {
            saturated: if level0 { saturated } else { 0 },
            clamped,
            ..Counts::default()
        },
        kept: None,
        sums,
    })
}

/// Clamps what a filter with negative lobes pushed out of range: bands into the settings'
/// `band_range`, alpha into [0, 1]; returns the pixels it changed. Filters without them only
/// average, and are left alone (their values are level 0's, averaged).
fn keep_in_range(job: &Job, bands: &mut [f32], alpha: Option<&mut [f32]>, n: usize) -> u64 {
    clamp_made(job.options.filter, job.storage.band_range, bands, alpha, n)
}

/// [`keep_in_range`] for a level made with `filter`, bands kept in `(lo, hi)`.
pub(crate) fn clamp_made(
    filter: crate::Filter,
    (lo, hi): (f32, f32),
    bands: &mut [f32],
    mut alpha: Option<&mut [f32]>,
    n: usize,
) -> u64 {
    if !filter.has_negative_lobes() {
        return 0;
    }
    let mut changed = 0;
    for (i, spectrum) in bands.chunks_exact_mut(n).enumerate() {
        let mut any = false;
        for v in spectrum.iter_mut() {
            let kept = v.clamp(lo, hi);
            any |= kept != *v;
            *v = kept;
        }
        if let Some(a) = alpha.as_deref_mut() {
            let kept = a[i].clamp(0.0, 1.0);
            any |= kept != a[i];
            a[i] = kept;
        }
        changed += u64::from(any);
    }
    changed
}

/// The sums of a block's values, bands then alpha, for the average of level 0.
pub(crate) fn level_sums(bands: &[f32], alpha: Option<&[f32]>, n: usize) -> Vec<f64> {
    let mut sums = vec![0.0f64; n + usize::from(alpha.is_some())];
    for spectrum in bands.chunks_exact(n) {
        sums.iter_mut()
            .zip(spectrum)
            .for_each(|(s, &v)| *s += f64::from(v));
    }
    if let Some(a) = alpha {
        sums[n] = a.iter().map(|&v| f64::from(v)).sum();
    }
    sums
}

/// Rounds a block's spectra as the file stores them (half: finite values kept finite, and
/// the colour kept when asked) and compresses it; returns the chunk and the spectra clamped.
pub(crate) fn finish_block(
    file: &SpectralFile,
    job: &Job,
    b: &Block,
    bands: Vec<f32>,
    alpha: Option<&[f32]>,
) -> Result<(Chunk, u64)> {
    finish(
        file,
        job.storage.xyz_weights.as_ref(),
        job.values(),
        b,
        bands,
        alpha,
    )
}

/// [`finish_block`] for blocks of `n` values a pixel, rounded to half keeping the colour of
/// `xyz_weights` when given.
pub(crate) fn finish(
    file: &SpectralFile,
    xyz_weights: Option<&[Vec<f64>; 3]>,
    n: usize,
    b: &Block,
    mut bands: Vec<f32>,
    alpha: Option<&[f32]>,
) -> Result<(Chunk, u64)> {
    let mut saturated = 0;
    // A compact texel is rounded as its channels store it already (`Compact::store`).
    let named = matches!(file.spec().kind, specconv_exr::Kind::Named(_));
    if file.spec().sample == Sample::Half && !named {
        saturated = saturate_half(&mut bands, n);
        if let Some(w) = xyz_weights {
            specconv_exr::quantize::round_to_half_keeping_colour(w, &mut bands, n);
        }
    }
    Ok((file.encode(b, &bands, alpha)?, saturated))
}

/// Clamps finite values beyond the half range to ±65504, so that a finite colour never becomes
/// infinite in the file; returns the number of spectra (of `n` bands) clamped.
fn saturate_half(bands: &mut [f32], n: usize) -> u64 {
    // The largest finite half.
    let max = 65504.0f32;
    let mut clamped = 0;
    for spectrum in bands.chunks_exact_mut(n) {
        // Branch-free over the bands (a select per value), so that it vectorises.
        let mut any = false;
        for v in spectrum.iter_mut() {
            let a = v.abs();
            let hit = a > max && a != f32::INFINITY;
            *v = if hit { max.copysign(*v) } else { *v };
            any |= hit;
        }
        clamped += u64::from(any);
    }
    clamped
}
