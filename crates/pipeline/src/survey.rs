//! One pass over the input's full-resolution level before anything is written: what the
//! header must say and what the pixels need, known before the first block is made.
//!
//! - NaN and infinities in the channels read: refused (as `maketx --checknan`), repaired
//!   (`--fixnan black|box3`, as OpenImageIO's `fixNonFinite`) or, only when asked, kept.
//! - A constant texture (every pixel the same), written as one tile (`maketx
//!   --constant-color-detect`); an alpha that is 1 everywhere, dropped (`--opaque-detect`).
//! - A hash of the source pixels as read, which `-u` compares: a source replaced by another
//!   image is rebuilt whatever its modification time.

use crate::choices::NonFinite;
use crate::error::{Error, Result};
use crate::job::Job;
use specconv_oiio::{ImageReader, Pixels};
use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The header attribute that records the hash of the source pixels.
pub const SOURCE_HASH: &str = "specconvSourceHash";

/// Non-finite pixels `box3` repairs at most: each is kept until its block is made.
pub const BOX3_LIMIT: u64 = 1 << 22;

/// How non-finite values of the channels read are replaced while blocks are made.
#[derive(Debug, Default)]
pub enum Repair {
    /// Nothing replaced.
    #[default]
    None,
    /// Replaced by 0.
    Black,
    /// The repaired pixel of each (x, y) that had one.
    Box3(HashMap<(usize, usize), Vec<f32>>),
}

impl Repair {
    /// Whether pixel `px` needs repair: a repair is asked and a channel read is not finite.
    #[inline]
    pub fn fixes(&self, px: &[f32], colour: &[usize], alpha: Option<usize>) -> bool {
        !matches!(self, Repair::None) && !finite(px, colour, alpha)
    }

    /// Pixel `px` at (x, y) of level 0, repaired in its channels read (`colour`, `alpha`).
    pub fn fixed(
        &self,
        px: &[f32],
        (colour, alpha): (&[usize], Option<usize>),
        at: (usize, usize),
    ) -> Vec<f32> {
        match self {
            Repair::Box3(fixed) => {
                if let Some(p) = fixed.get(&at) {
                    return p.clone();
                }
            }
            Repair::None | Repair::Black => {}
        }
        let mut p = px.to_vec();
        for c in read_channels(colour, alpha) {
            if !p[c].is_finite() {
                p[c] = 0.0;
            }
        }
        p
    }
}

fn read_channels(colour: &[usize], alpha: Option<usize>) -> impl Iterator<Item = usize> + '_ {
    colour.iter().copied().chain(alpha)
}

#[inline]
fn finite(px: &[f32], colour: &[usize], alpha: Option<usize>) -> bool {
    read_channels(colour, alpha).all(|c| px[c].is_finite())
}

/// What the pass found.
#[derive(Debug)]
pub struct Survey {
    /// Pixels with a NaN or infinite value in a channel read, and the first of them (x, y).
    pub non_finite: u64,
    /// The first such pixel.
    pub first_non_finite: Option<(usize, usize)>,
    /// Whether they were repaired.
    pub repaired: bool,
    /// Every pixel has these values (all the channels read from the file), when it does.
    pub constant: Option<Vec<f32>>,
    /// Alpha is read and 1 everywhere.
    pub opaque: bool,
    /// The hash of the source pixels (`xxh3-128:` and 32 hex digits).
    pub hash: String,
    /// How non-finite values are repaired.
    pub repair: Repair,
}

/// Rows read from `y`, and where among them a channel read is not finite.
type Read = (usize, Pixels, Vec<(usize, usize)>);

/// Rows read at a time: about a million pixels, at least one row.
fn rows_per_read(width: usize) -> usize {
    ((1 << 20) / width.max(1)).max(1)
}

/// The hash of level 0's pixels as `reader` reads them (every channel, as float), as
/// [`Survey::hash`] records it.
pub fn source_hash(reader: &mut ImageReader) -> Result<String> {
    let (width, height) = (reader.info().width(), reader.info().height());
    let mut hash = Hasher::new(width, height);
    let step = rows_per_read(width as usize) as u32;
    let mut y = 0;
    while y < height {
        let end = (y + step).min(height);
        hash.update(&reader.read_scanlines(0, y..end)?);
        y = end;
    }
    Ok(hash.finish())
}

struct Hasher(xxhash_rust::xxh3::Xxh3);

impl Hasher {
    fn new(width: u32, height: u32) -> Hasher {
        let mut h = xxhash_rust::xxh3::Xxh3::new();
        h.update(&width.to_le_bytes());
        h.update(&height.to_le_bytes());
        Hasher(h)
    }

    fn update(&mut self, px: &Pixels) {
        let bytes: Vec<u8> = px.data.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.0.update(&bytes);
    }

    fn finish(&self) -> String {
        format!("xxh3-128:{:032x}", self.0.digest128())
    }
}

/// What a survey is asked: the rule on NaN and infinities (`--fixnan`, or what a compact file
/// records for `expand`), the file's name for errors, and a flag that cancels it.
#[derive(Clone, Copy)]
pub struct Asked<'a> {
    /// The rule on NaN and infinities.
    pub non_finite: NonFinite,
    /// The file surveyed.
    pub input: &'a Path,
    /// Set from another thread to stop.
    pub cancel: &'a AtomicBool,
}

impl<'a> From<&'a Job<'a>> for Asked<'a> {
    fn from(job: &'a Job<'a>) -> Asked<'a> {
        Asked {
            non_finite: job.options.non_finite,
            input: job.input,
            cancel: job.cancel,
        }
    }
}

/// Surveys level 0 through `reader` (left at its end: reread it from the start).
pub fn survey(
    job: Asked,
    reader: &mut ImageReader,
    channels: (&[usize], Option<usize>),
) -> Result<Survey> {
    let (width, height) = (
        reader.info().width() as usize,
        reader.info().height() as usize,
    );
    let mut hash = Hasher::new(width as u32, height as u32);
    let mut found = Survey::start(job.non_finite, channels.1.is_some());
    let mut same = Same {
        first: None,
        constant: true,
    };
    // Strip k − 1 waits for strip k: box3 repairs its last row from strip k's first.
    let mut previous: Option<Read> = None;
    let mut above: Option<Vec<f32>> = None;
    let step = rows_per_read(width);
    let mut y = 0;
    while y <= height {
        // A survey of a large texture takes seconds: an interrupt is heard between reads.
        if job.cancel.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(Error::Cancelled);
        }
        let strip = if y < height {
            let end = (y + step).min(height);
            let px = reader.read_scanlines(0, y as u32..end as u32)?;
            hash.update(&px);
            let bad = found.scan(&mut same, &px, (width, y), channels);
            found.check_non_finite(&job, (y, end))?;
            Some((y, px, bad))
        } else {
            None
        };
        if let Some(read) = previous.take() {
            above = Some(found.repair_box3(read, strip.as_ref(), above.as_deref(), channels));
        }
        previous = strip;
        if y == height {
            break;
        }
        y = (y + step).min(height);
    }
    found.repaired &= found.non_finite > 0;
    found.constant = if same.constant { same.first } else { None };
    found.hash = hash.finish();
    Ok(found)
}

/// Whether every pixel so far has the first one's values (in the channels read).
struct Same {
    first: Option<Vec<f32>>,
    constant: bool,
}

impl Same {
    #[inline]
    fn take(&mut self, p: &[f32], (colour, alpha): (&[usize], Option<usize>)) {
        if !self.constant {
            return;
        }
        match &self.first {
            None => self.first = Some(p.to_vec()),
            Some(f) => {
                self.constant =
                    read_channels(colour, alpha).all(|c| f[c].to_bits() == p[c].to_bits());
            }
        }
    }
}

impl Survey {
    /// Nothing found yet; alpha opaque until a pixel says otherwise, when it is read.
    fn start(policy: NonFinite, alpha: bool) -> Survey {
        Survey {
            non_finite: 0,
            first_non_finite: None,
            repaired: matches!(policy, NonFinite::Black | NonFinite::Box3),
            constant: None,
            opaque: alpha,
            hash: String::new(),
            repair: match policy {
                NonFinite::Black => Repair::Black,
                NonFinite::Box3 => Repair::Box3(HashMap::new()),
                NonFinite::Refuse | NonFinite::Keep => Repair::None,
            },
        }
    }

    /// Counts the non-finite pixels of `px` (rows from `y`, `width` pixels a row), and whether
    /// alpha stays 1 and the pixels the same; returns where a channel read is not finite.
    fn scan(
        &mut self,
        same: &mut Same,
        px: &Pixels,
        (width, y): (usize, usize),
        (colour, alpha): (&[usize], Option<usize>),
    ) -> Vec<(usize, usize)> {
        let mut bad = Vec::new();
        for (i, p) in px.data.chunks_exact(px.channels).enumerate() {
            let at = (i % width, y + i / width);
            if !finite(p, colour, alpha) {
                self.non_finite += 1;
                self.first_non_finite.get_or_insert(at);
                bad.push(at);
            }
            if self.opaque && alpha.is_some_and(|a| p[a] != 1.0) {
                self.opaque = false;
            }
            same.take(p, (colour, alpha));
        }
        bad
    }

    /// Refuses the input once `rows` were read when non-finite values are refused, or are more
    /// than box3 repairs.
    fn check_non_finite(&self, job: &Asked, rows: (usize, usize)) -> Result<()> {
        let policy = job.non_finite;
        if policy == NonFinite::Refuse && self.non_finite > 0 {
            return Err(Error::NonFinite {
                input: job.input.to_path_buf(),
                pixels: self.non_finite,
                first: self.first_non_finite.expect("counted"),
                rows,
            });
        }
        if policy == NonFinite::Box3 && self.non_finite > BOX3_LIMIT {
            return Err(Error::TooManyNonFinite {
                input: job.input.to_path_buf(),
                limit: BOX3_LIMIT,
            });
        }
        Ok(())
    }

    /// Repairs (for box3) the bad pixels of the strip `read`, between the row `above` it and
    /// the first of the strip read `next`; returns its last row, the next strip's above.
    fn repair_box3(
        &mut self,
        (y0, px, bad): Read,
        next: Option<&Read>,
        above: Option<&[f32]>,
        channels: (&[usize], Option<usize>),
    ) -> Vec<f32> {
        let below = next.map(|(_, next, _)| row(next, 0));
        if let Repair::Box3(fixed) = &mut self.repair {
            for &(x, py) in &bad {
                let rows = (above, below.as_deref());
                let p = box3(&px, y0, (x, py), rows, fixed, channels);
                fixed.insert((x, py), p);
            }
        }
        row(&px, px.height as usize - 1)
    }
}

/// Row `y` of a strip, every channel.
fn row(px: &Pixels, y: usize) -> Vec<f32> {
    let w = px.width as usize * px.channels;
    px.data[y * w..(y + 1) * w].to_vec()
}

/// Pixel (x, y) of level 0 repaired from its 3×3 neighbours: the strip holds rows from `y0`,
/// `rows` are the rows just above and below it (if any). As OpenImageIO's `fixNonFinite`
/// box3 (which repairs in place, in order): a neighbour before (x, y) in row order counts as
/// already repaired (`fixed`).
fn box3(
    px: &Pixels,
    y0: usize,
    (x, y): (usize, usize),
    (above, below): (Option<&[f32]>, Option<&[f32]>),
    fixed: &HashMap<(usize, usize), Vec<f32>>,
    (colour, alpha): (&[usize], Option<usize>),
) -> Vec<f32> {
    let (w, ch) = (px.width as usize, px.channels);
    let strip_rows = px.height as usize;
    let value = |nx: usize, ny: usize, c: usize| -> Option<f32> {
        let v = if let Some(p) = fixed.get(&(nx, ny)) {
            Some(p[c])
        } else if ny < y0 {
            above.map(|r| r[nx * ch + c])
        } else if ny >= y0 + strip_rows {
            below.map(|r| r[nx * ch + c])
        } else {
            Some(px.pixel(nx as u32, (ny - y0) as u32)[c])
        };
        v.filter(|v| v.is_finite())
    };
    let mut out = px.pixel(x as u32, (y - y0) as u32).to_vec();
    for c in read_channels(colour, alpha) {
        if out[c].is_finite() {
            continue;
        }
        let (mut sum, mut count) = (0.0f32, 0u32);
        for ny in y.saturating_sub(1)..=y + 1 {
            for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                if (nx, ny) == (x, y) {
                    continue;
                }
                if let Some(v) = value(nx, ny, c) {
                    sum += v;
                    count += 1;
                }
            }
        }
        out[c] = if count == 0 { 0.0 } else { sum / count as f32 };
    }
    out
}
