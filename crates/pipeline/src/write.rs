//! Writing the output, in five steps: the plan (level 0's strips, or the input's when resized,
//! in windows; the smaller levels' blocks by strip), the read-ahead (one reader, in order), the
//! encode of a window's blocks in parallel, the ordered sink (chunks to the writer in file
//! order, what their pixels had counted) and the publish (the temporary renamed into place).
//!
//! Errors are the pipeline's own all the way: the writer hands back what the producer returns
//! ([`SpectralFile::write_then`]), so a cancellation is [`Error::Cancelled`] where it is seen.

use crate::attributes::average_attributes;
use crate::blocks::{encode_made_block, Counts, Made};
use crate::error::{Error, Result};
use crate::job::Job;
use crate::mip;
use crate::strips::{strips, Strip};
use crate::uplift::{encode_block, Reading};
use rayon::prelude::*;
use specconv_atomic_file::{Pending, PlanError, Replace};
use specconv_exr::{Block, Blocks, Chunk, SpectralFile};
use specconv_oiio::{ImageReader, Pixels};
use std::collections::HashMap;
use std::io::BufWriter;
use std::sync::atomic::Ordering;
use std::sync::Mutex;

/// What the writer hands the producer: takes each chunk with its index, in any order.
type Sink<'s> = dyn FnMut(usize, Chunk) -> specconv_exr::Result<()> + Send + 's;

/// Reads, converts, uplifts and writes every window of `file`, whose level 0 is made from
/// spectra of size `source` (resized when it is not level 0's); returns the pixels uplifted and
/// what they had.
pub(super) fn write_file(
    job: &Job,
    (file, source): (&SpectralFile, (usize, usize)),
    reader: &mut ImageReader,
    reading: &Reading,
    constant: Option<&[f32]>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(u64, Counts)> {
    check_weights(job)?;
    let plan = Plan::of(job, file, source);
    // Refused with the figure before anything is read or created, not aborted midway.
    let rows = plan
        .windows
        .iter()
        .map(|w| w.iter().map(|s| s.height).sum());
    let windows = super::memory::Source::Windows {
        rows: rows.max().unwrap_or(0),
    };
    super::memory::check(super::memory::needed(file, source.0, windows))?;
    let mut input = ReadAhead {
        reader,
        constant,
        width: source.0,
    };
    // The first window is read before the output exists: a file whose pixels cannot be read
    // fails here, leaving nothing behind.
    let first = plan.windows.first().map(|w| input.read(w)).transpose()?;
    let pending = Pending::beside(job.output).map_err(|source| Error::Io {
        path: job.output.to_path_buf(),
        source,
    })?;
    let encoder = Encoder {
        job,
        file,
        reading,
        smaller: plan.smaller,
        resized: plan.resized,
    };
    let mut production = Production {
        encoder: &encoder,
        windows: &plan.windows,
        width: source.0,
        input,
        cascade: plan.cascade,
        next: first,
        made: Vec::new(),
        completed: Vec::new(),
        done: 0,
        total: plan.total,
    };
    // Level 0's sums, for the average the header gets once they are all made.
    let sums = Mutex::new(vec![0.0f64; file.values_per_pixel()]);
    let level0 = (file.level_size(0).0 * file.level_size(0).1) as u64;
    let late = || average_attributes(file, &sums.lock().expect("no panic holds it"), level0);
    let mut ordered = Ordered {
        job,
        sums: &sums,
        counts: Counts::default(),
    };
    let out = BufWriter::with_capacity(1 << 20, pending.file());
    let written = file.write_then(
        out,
        |sink| production.run(&mut ordered, sink, progress),
        late,
    );
    // Once the flag is set nothing is published, and the caller hears that it was cancelled,
    // whatever else failed meanwhile (a read, the writer's I/O).
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    written.map_err(|e| match e {
        // The file system's refusal is the output's, said plainly (a file size limit).
        Error::Output(e) => match e.into_io() {
            Ok(source) => Error::Io {
                path: job.output.to_path_buf(),
                source: specconv_atomic_file::explained(source),
            },
            Err(e) => Error::Output(e),
        },
        e => e,
    })?;
    strict(job, &ordered.counts, plan.total)?;
    publish(job, pending)?;
    Ok((plan.total, ordered.counts))
}

/// In strict mode, refuses to publish an output with pixels clipped ([`crate::report::clipped`]).
fn strict(job: &Job, counts: &Counts, pixels: u64) -> Result<()> {
    let clipped = crate::report::clipped(job.stack.emissive().is_some(), counts.above_one, pixels);
    if !job.options.strict || clipped == 0 {
        return Ok(());
    }
    Err(Error::Strict {
        input: job.input.to_path_buf(),
        warning: format!("{clipped} pixels above 1 in a reflectance conversion (clipped)"),
    })
}

/// Refuses the weights half rounding keeps the colour under when they are not on the
/// method's grid.
fn check_weights(job: &Job) -> Result<()> {
    let want = job.values();
    match &job.storage.xyz_weights {
        Some(w) if w.iter().any(|row| row.len() != want) => Err(Error::Weights {
            have: w[0].len(),
            want,
        }),
        _ => Ok(()),
    }
}

/// [`Error::Cancelled`] once the job's flag is set.
fn check_cancel(job: &Job) -> Result<()> {
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    Ok(())
}

/// How a file is made. Level 0 is read and uplifted; the smaller levels are made from its
/// spectra. Resized, the input is read and uplifted, and every level made from its spectra.
struct Plan {
    /// The strips read from the input, in windows.
    windows: Vec<Vec<Strip>>,
    /// The blocks of the smaller levels, by the (level, y) of their strip.
    smaller: HashMap<(usize, usize), Vec<Block>>,
    /// What makes the smaller levels (and a resized level 0), for a MIP map or a resize.
    cascade: Option<mip::Cascade>,
    /// The pixels read from the input.
    total: u64,
    /// Level 0 is resized from the input's spectra.
    resized: bool,
}

impl Plan {
    /// The plan of `file`, whose level 0 is made from spectra of size `source`.
    fn of(job: &Job, file: &SpectralFile, source: (usize, usize)) -> Plan {
        let resized = file.level_size(0) != source;
        let (strips, smaller): (Vec<Strip>, Vec<Strip>) = strips(file)
            .into_iter()
            .partition(|s| s.level == 0 && !resized);
        let strips = if resized {
            input_strips(file, source)
        } else {
            strips
        };
        Plan {
            total: strips.iter().map(|s| (source.0 * s.height) as u64).sum(),
            windows: windows(strips, source.0, file.values_per_pixel()),
            smaller: smaller
                .into_iter()
                .map(|s| ((s.level, s.y), s.blocks))
                .collect(),
            cascade: cascade(job, file, source, resized),
            resized,
        }
    }
}

/// The strips in windows of enough pixels (`width` a row) to keep every thread busy, at least
/// one strip each: memory is bounded by the window, whatever the image height. A window of
/// fine-grid spectra (`values` a pixel) stops at [`WINDOW_BYTES`] of them, past one strip.
fn windows(strips: Vec<Strip>, width: usize, values: usize) -> Vec<Vec<Strip>> {
    let busy = (rayon::current_num_threads() * 8 * 64 * 64) as u64;
    let budget = busy.min(WINDOW_BYTES / (values.max(1) as u64 * 4));
    let mut windows = Vec::new();
    let mut current: Vec<Strip> = Vec::new();
    let mut pixels = 0u64;
    for s in strips {
        pixels += (width * s.height) as u64;
        current.push(s);
        if pixels >= budget {
            windows.push(std::mem::take(&mut current));
            pixels = 0;
        }
    }
    if !current.is_empty() {
        windows.push(current);
    }
    windows
}

/// The most bytes of spectra (as floats) a window of several strips holds: many threads and
/// thousands of bands would otherwise make windows of tens of gigabytes.
const WINDOW_BYTES: u64 = 256 << 20;

/// What filters the smaller levels (and, `resized`, level 0) from the spectra of size
/// `source`; none for a file of one level at the input's size.
fn cascade(
    job: &Job,
    file: &SpectralFile,
    source: (usize, usize),
    resized: bool,
) -> Option<mip::Cascade> {
    (file.levels() > 1 || resized).then(|| {
        let sizes: Vec<_> = resized
            .then_some(source)
            .into_iter()
            .chain((0..file.levels()).map(|l| file.level_size(l)))
            .collect();
        mip::Cascade::new(
            &sizes,
            file.block_height(),
            file.values_per_pixel(),
            job.options.filter,
            resized,
        )
    })
}

/// The input, read a window of strips at a time by one reader, in order (so scanline formats
/// such as PNG decode once).
struct ReadAhead<'r> {
    reader: &'r mut ImageReader,
    /// A constant texture's colour: nothing is read, every pixel is this one.
    constant: Option<&'r [f32]>,
    /// Pixels a row.
    width: usize,
}

impl ReadAhead<'_> {
    /// The pixels of each strip of `window`.
    fn read(&mut self, window: &[Strip]) -> Result<Vec<Pixels>> {
        let width = self.width;
        window
            .iter()
            .map(|s| match self.constant {
                Some(px) => Ok(Pixels {
                    width: width as u32,
                    height: s.height as u32,
                    channels: px.len(),
                    data: px.repeat(width * s.height),
                }),
                None => Ok(self
                    .reader
                    .read_scanlines(s.level, s.y as u32..(s.y + s.height) as u32)?),
            })
            .collect()
    }
}

/// What makes blocks, shared by the threads that make them.
struct Encoder<'a> {
    job: &'a Job<'a>,
    file: &'a SpectralFile,
    reading: &'a Reading<'a>,
    /// The blocks of the smaller levels, by the (level, y) of their strip.
    smaller: HashMap<(usize, usize), Vec<Block>>,
    /// Level 0 is resized from what the window's blocks make.
    resized: bool,
}

impl Encoder<'_> {
    /// A window's blocks, made from its strips' `rows` (one list a strip), and the blocks of
    /// the smaller levels' strips `lower`, made alongside.
    fn window_and_lower(
        &self,
        window: &[Strip],
        rows: &[Pixels],
        lower: &[mip::MadeStrip],
    ) -> Result<(Vec<Vec<Made>>, Vec<Made>)> {
        let (strips, lower) = rayon::join(|| self.window(window, rows), || self.lower(lower));
        Ok((strips?, lower?))
    }

    /// Colour-converts, uplifts and compresses every block of `window` from its strips' rows.
    fn window(&self, window: &[Strip], rows: &[Pixels]) -> Result<Vec<Vec<Made>>> {
        window
            .par_iter()
            .zip(rows.par_iter())
            .map(|(strip, px)| {
                strip
                    .blocks
                    .par_iter()
                    .map(|b| {
                        // Checked per block, not only per window: a window of fine-band
                        // blocks takes seconds.
                        check_cancel(self.job)?;
                        encode_block(self.file, self.job, self.reading, b, px, self.resized)
                    })
                    .collect::<Result<Vec<_>>>()
            })
            .collect()
    }

    /// The blocks of the smaller levels made from `strips` of the smaller levels.
    fn lower(&self, strips: &[mip::MadeStrip]) -> Result<Vec<Made>> {
        strips
            .par_iter()
            .flat_map(|strip| {
                self.smaller[&(strip.level, strip.y)]
                    .par_iter()
                    .map(move |b| encode_made_block(self.file, self.job, b, strip))
            })
            .collect()
    }
}

/// The writer's side: chunks handed to the sink in the order made, what their pixels had
/// counted, level 0's sums kept for the average.
struct Ordered<'a> {
    job: &'a Job<'a>,
    sums: &'a Mutex<Vec<f64>>,
    counts: Counts,
}

impl Ordered<'_> {
    /// Hands `made`'s chunks to `sink`, counting what their pixels had.
    fn write(&mut self, made: Vec<Made>, sink: &mut Sink) -> Result<()> {
        for made in made {
            if !made.sums.is_empty() {
                let mut sums = self.sums.lock().expect("no panic holds it");
                sums.iter_mut().zip(made.sums).for_each(|(s, b)| *s += b);
            }
            // A window of fine-band chunks is hundreds of megabytes.
            check_cancel(self.job)?;
            self.add(&made.counts);
            if let Some(chunk) = made.chunk {
                sink(made.index, chunk)?;
            }
        }
        Ok(())
    }

    fn add(&mut self, c: &Counts) {
        let counts = &mut self.counts;
        counts.non_finite += c.non_finite;
        counts.above_one += c.above_one;
        counts.saturated += c.saturated;
        counts.clamped += c.clamped;
        counts.tally += c.tally;
    }
}

/// The window loop. Window i's blocks are made while window i + 1 is read and window i − 1's
/// chunks are written, in file order: the writer never holds up the threads that compress.
struct Production<'a, 'r> {
    encoder: &'a Encoder<'a>,
    windows: &'a [Vec<Strip>],
    /// Pixels a row of the strips read.
    width: usize,
    input: ReadAhead<'r>,
    cascade: Option<mip::Cascade>,
    /// The pixels of the window to make next, read while the one before was made.
    next: Option<Vec<Pixels>>,
    /// The blocks of the window made last: written while the next one is made.
    made: Vec<Made>,
    /// Strips of smaller levels that the window made last completed: encoded with the next.
    completed: Vec<mip::MadeStrip>,
    /// Pixels read, and in all, for `progress`.
    done: u64,
    total: u64,
}

impl Production<'_, '_> {
    /// Makes every window and hands every chunk to `sink` through `ordered`; `progress` hears
    /// (pixels done, pixels in all) after every window.
    fn run(
        &mut self,
        ordered: &mut Ordered,
        sink: &mut Sink,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<()> {
        for i in 0..self.windows.len() {
            check_cancel(self.encoder.job)?;
            self.window(i, ordered, sink)?;
            progress(self.done, self.total);
        }
        ordered.write(std::mem::take(&mut self.made), sink)?;
        // The smaller levels' last strips: the 1×1 level at least.
        check_cancel(self.encoder.job)?;
        let last = self.encoder.lower(&self.completed)?;
        ordered.write(last, sink)
    }

    /// Makes window `i` while the window before is written and the one after is read.
    fn window(&mut self, i: usize, ordered: &mut Ordered, sink: &mut Sink) -> Result<()> {
        let window = &self.windows[i];
        let rows = self
            .next
            .take()
            .expect("each window is read before it is processed");
        let previous = std::mem::take(&mut self.made);
        let lower = std::mem::take(&mut self.completed);
        let (encoder, input, after) = (self.encoder, &mut self.input, self.windows.get(i + 1));
        let (made, (read_next, wrote)) = rayon::join(
            || encoder.window_and_lower(window, &rows, &lower),
            || {
                let wrote = ordered.write(previous, sink);
                (after.map(|w| input.read(w)).transpose(), wrote)
            },
        );
        wrote?;
        self.next = read_next?;
        let (strips, lower) = made?;
        self.filter(window, &strips);
        self.made = strips.into_iter().flatten().chain(lower).collect();
        self.done += window
            .iter()
            .map(|s| (self.width * s.height) as u64)
            .sum::<u64>();
        Ok(())
    }

    /// Feeds the spectra of `window`'s blocks to the cascade; the strips of smaller levels
    /// they complete wait for the next window.
    fn filter(&mut self, window: &[Strip], strips: &[Vec<Made>]) {
        let Some(cascade) = self.cascade.as_mut() else {
            return;
        };
        let values = self.encoder.file.values_per_pixel();
        for (strip, blocks) in window.iter().zip(strips) {
            let rows = strip_rows(self.width, strip, blocks, values);
            self.completed.extend(cascade.push(&rows, self.width));
        }
    }
}

/// Renames the finished temporary into place. Without overwrite, an output another writer
/// published while this one ran is refused, not replaced.
fn publish(job: &Job, pending: Pending) -> Result<()> {
    let output = job.output;
    pending
        .publish(Replace::when(job.overwrite))
        .map_err(|source| match source.kind() {
            std::io::ErrorKind::AlreadyExists => Error::Plan(PlanError::Exists {
                output: output.to_path_buf(),
                more: 0,
            }),
            _ => Error::Io {
                path: output.to_path_buf(),
                source,
            },
        })
}

/// The strips the input is read in when level 0 is resized from it: rows of blocks of the
/// file's block size, over the input's `size`. Their blocks are not the file's (no chunk).
fn input_strips(file: &SpectralFile, (width, height): (usize, usize)) -> Vec<Strip> {
    let (bw, bh) = match file.spec().blocks {
        Blocks::Tiles { width, height, .. } => (width, height),
        Blocks::Scanlines => (width, file.block_height()),
    };
    (0..height)
        .step_by(bh)
        .map(|y| {
            let h = bh.min(height - y);
            Strip {
                level: 0,
                y,
                height: h,
                blocks: (0..width)
                    .step_by(bw)
                    .map(|x| Block {
                        chunk: usize::MAX,
                        level: 0,
                        x,
                        y,
                        width: bw.min(width - x),
                        height: h,
                    })
                    .collect(),
            }
        })
        .collect()
}

/// A strip's values, `width` pixels a row across its blocks, from the blocks' own values.
fn strip_rows(width: usize, strip: &Strip, blocks: &[Made], values: usize) -> Vec<f32> {
    let mut rows = vec![0.0f32; width * strip.height * values];
    for (b, made) in strip.blocks.iter().zip(blocks) {
        let v = made
            .kept
            .as_deref()
            .expect("a MIP map keeps level 0's values");
        for y in 0..b.height {
            let from = &v[y * b.width * values..(y + 1) * b.width * values];
            let at = (y * width + b.x) * values;
            rows[at..at + from.len()].copy_from_slice(from);
        }
    }
    rows
}
