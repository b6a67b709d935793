//! The conversion job: file ──OIIO──▶ RGB strip ──OCIO──▶ XYZ ──uplift──▶ bands ──exr──▶ file.
//!
//! Work flows in strips: the blocks of the output that share a level and a row. A window of
//! strips is read from the input (one reader, in order, so scanline formats such as PNG decode
//! once) while the previous window's blocks are colour-converted, uplifted and compressed in
//! parallel; chunks are then written in file order. Memory is bounded by the window, whatever
//! the image height, and the output bytes do not depend on the number of threads.
//!
//! The output is written to a temporary file beside the target and renamed into place only
//! when complete: a failed or cancelled job leaves nothing behind. Before it is created, an
//! OpenEXR input's header is checked against the file's size ([`specconv_exr::check`]) and the
//! first window of pixels is read, so a damaged input fails at once.
//!
//! The output keeps the input's data and display windows (OpenEXR gives every MIP level the
//! data window's origin). [`input`] chooses the subimage and the channels read.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod colour;
pub mod data;
pub mod input;
mod png;

pub use colour::{
    input_space, texture_space, Alpha, DataTexture, InputSpace, Rule, ToXyz, Warning,
};
use rayon::prelude::*;
use specconv_atomic_file::{PlanError, Replace};
use specconv_exr::{Block, Blocks, Chunk, Compression, Kind, Sample, Spec, SpectralFile, Windows};
use specconv_ocio::Config;
use specconv_spectral::method::Tally;
use specconv_spectral::Method;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Why a conversion failed, by cause. Messages name no command-line option: a front-end adds
/// its own hint (the CLI's flags, the Python package's keywords).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The input could not be read.
    #[error(transparent)]
    Input(#[from] specconv_oiio::Error),
    /// The input's colour could not be managed.
    #[error(transparent)]
    Color(#[from] specconv_ocio::Error),
    /// The output could not be written.
    #[error(transparent)]
    Output(#[from] specconv_exr::Error),
    /// An OpenEXR input whose header does not match its size.
    #[error(transparent)]
    Damaged(#[from] specconv_exr::check::Problem),
    /// The channels asked for, or those found, cannot carry a colour.
    #[error("{}: {what}; its channels are {channels}", path.display())]
    Channels {
        /// The input.
        path: PathBuf,
        /// What is wrong with them.
        what: String,
        /// The channels the input has, and its layers.
        channels: String,
        /// What naming would settle it, where naming would.
        choose: Option<input::Choose>,
    },
    /// The format's default colour space cannot be reached in the config.
    #[error("{0}")]
    DefaultColourSpace(String),
    /// Scanline files hold one level and the input has several.
    #[error("{} has {levels} MIP levels, which scanline files cannot hold", input.display())]
    ScanlineMip {
        /// The input.
        input: PathBuf,
        /// Its levels.
        levels: usize,
    },
    /// The input's levels are not an OpenEXR MIP map's.
    #[error(
        "{}: its {levels} MIP levels are not the {needed} levels of halving sizes an OpenEXR MIP map has \
         (level {level}: {have:?} where {want:?} is needed)",
        input.display()
    )]
    NotAMipMap {
        /// The input.
        input: PathBuf,
        /// Its levels.
        levels: usize,
        /// The levels an OpenEXR MIP map of its size has.
        needed: usize,
        /// The first level that differs.
        level: usize,
        /// That level's size in the input.
        have: Option<(usize, usize)>,
        /// The size it needs.
        want: (usize, usize),
    },
    /// The weights half rounding keeps the colour under are not on the method's grid.
    #[error("the XYZ weights have {have} bands where the method makes {want}")]
    Weights {
        /// Bands of the weights.
        have: usize,
        /// Bands of the method.
        want: usize,
    },
    /// The input is not a file (a directory, a device, a FIFO), or is missing.
    #[error(transparent)]
    NotAFile(#[from] specconv_atomic_file::ReadError),
    /// The output may not be written: it is the input, exists and may not be replaced, or has
    /// no directory.
    #[error(transparent)]
    Plan(#[from] specconv_atomic_file::PlanError),
    /// Writing the output failed.
    #[error("cannot write {}", path.display())]
    Io {
        /// The output.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Stopped through the job's cancel flag.
    #[error("cancelled")]
    Cancelled,
    /// The input is a spectral image already ([`input::open`]): it is not uplifted again.
    #[error(
        "{}: already a spectral image ({} bands of {}, {}–{} nm, the Fichet 2021 layout): \
         its spectra are not uplifted again from a colour",
        path.display(), bands, if *emissive { "emission" } else { "reflectance" }, range_nm.0, range_nm.1
    )]
    Spectral {
        /// The input.
        path: PathBuf,
        /// `S0.` channels (emission) rather than `T.` (reflectance).
        emissive: bool,
        /// Its bands.
        bands: usize,
        /// Its first and last wavelengths.
        range_nm: (f64, f64),
    },
    /// The input holds data, not colour ([`colour::texture_space`]): it is never uplifted.
    #[error(transparent)]
    Data(Box<DataTexture>),
}

/// The pipeline's results.
pub type Result<T> = std::result::Result<T, Error>;

/// Which MIP levels to convert.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mip {
    /// Every level the input has, each uplifted from its own input level.
    All,
    /// The full-resolution level only.
    Base,
}

/// How the output is stored.
#[derive(Debug, Clone)]
pub struct Settings {
    /// Reflectance (`T.` channels) or emission (`S0.` channels with their units); the method
    /// makes the matching spectra.
    pub kind: Kind,
    /// Per band, the weights of X, Y and Z with which the spectra will be read back (the
    /// method's colorimetry): half samples are rounded to keep that colour
    /// ([`specconv_exr::quantize`]); `None` rounds to nearest.
    pub xyz_weights: Option<[Vec<f64>; 3]>,
    /// `--colorspace`: the input's colour space, overriding what the file declares.
    pub colorspace: Option<String>,
    /// `--subimage` and `--channels`: what of the input is read.
    pub input: input::Request,
    /// `--alpha`: whether the input's colour is straight or premultiplied.
    pub alpha: Alpha,
    /// Half or float samples.
    pub sample: Sample,
    /// OpenEXR compression of every block.
    pub compression: Compression,
    /// Deflate level of ZIP and ZIPS blocks, 0–9 ([`specconv_exr::zip::DEFAULT_LEVEL`]).
    pub zip_level: u8,
    /// `None` for scanlines, else the tile size.
    pub tile: Option<(usize, usize)>,
    /// Which MIP levels to convert.
    pub mip: Mip,
    /// Write over an existing output.
    pub overwrite: bool,
    /// Attributes recorded in the output (model, method, observer, illuminant…).
    pub attributes: Vec<(String, String)>,
}

impl Default for Settings {
    /// `convert`'s defaults: reflectance, half rounded to nearest, ZIP at the default level,
    /// 64×64 tiles, every MIP level, the file's own colour space and channels; an existing
    /// output is kept.
    fn default() -> Settings {
        Settings {
            kind: Kind::Reflective,
            xyz_weights: None,
            colorspace: None,
            input: Default::default(),
            alpha: Alpha::Auto,
            sample: Sample::Half,
            compression: Compression::ZIP16,
            zip_level: specconv_exr::zip::DEFAULT_LEVEL,
            tile: Some((64, 64)),
            mip: Mip::All,
            overwrite: false,
            attributes: Vec::new(),
        }
    }
}

/// What a finished conversion did.
#[derive(Debug, Clone)]
pub struct Report {
    /// Width of the full-resolution level.
    pub width: usize,
    /// Height of the full-resolution level.
    pub height: usize,
    /// Pixels uplifted, over all levels.
    pub pixels: u64,
    /// MIP levels written.
    pub levels: usize,
    /// The subimage and channels read.
    pub selection: input::Selection,
    /// The input colour space ([`colour`]'s rule).
    pub colorspace: String,
    /// The rule that chose it.
    pub colorspace_rule: Rule,
    /// Declarations of the file that were ignored or disagree.
    pub warnings: Vec<Warning>,
    /// Straight colour was multiplied by alpha after conversion.
    pub premultiplied: bool,
    /// Pixels whose colour had a NaN or infinite component (their spectra are NaN).
    pub non_finite: u64,
    /// Pixels above 1: an input channel or Y above [`ABOVE_ONE`]. No reflectance has Y > 1.
    pub above_one: u64,
    /// Pixels with a finite band beyond the half range, stored as ±65504 instead of ±∞.
    pub saturated: u64,
    /// What the method's adapters counted over this job's pixels (bounded outcomes, unmatched
    /// emission): this job's alone.
    pub tally: Tally,
}

/// Values above this count as above 1: 0.1 % of headroom, so that the rounding of colour
/// conversion does not make white count.
pub const ABOVE_ONE: f32 = 1.001;

/// What one block's pixels had; see [`Report`].
#[derive(Debug, Clone, Copy, Default)]
struct Counts {
    non_finite: u64,
    above_one: u64,
    saturated: u64,
    tally: Tally,
}

/// A conversion: one input, one output.
pub struct Job<'a> {
    /// The image to read.
    pub input: &'a Path,
    /// The spectral OpenEXR to write.
    pub output: &'a Path,
    /// The OCIO config the input's colour is managed with.
    pub config: &'a Config,
    /// The method stack that uplifts every pixel.
    pub method: &'a dyn Method,
    /// How the output is stored.
    pub settings: &'a Settings,
    /// Set from another thread (a signal handler) to stop the job.
    pub cancel: &'a AtomicBool,
}

/// One row of blocks: the unit read from the input.
struct Strip {
    level: usize,
    y: usize,
    height: usize,
    blocks: Vec<Block>,
}

/// Runs a job: [`open`], then [`Opened::write`] with the settings' attributes. `progress`
/// hears (pixels done, pixels in all) after every window.
pub fn convert(job: &Job, progress: &mut dyn FnMut(u64, u64)) -> Result<Report> {
    open(job)?.write(&job.settings.attributes, progress)
}

/// An input opened for a job: the output may be written, the input's header is sound, its
/// channels and colour space are chosen. Nothing is written yet.
pub struct Opened<'a> {
    job: &'a Job<'a>,
    reader: specconv_oiio::ImageReader,
    info: specconv_oiio::ImageInfo,
    selection: input::Selection,
    space: InputSpace,
    premultiply: bool,
}

/// Opens `job`'s input: refuses to write over the input or an existing output (unless the
/// settings allow it), checks an OpenEXR input's header, chooses channels and colour space.
pub fn open<'a>(job: &'a Job<'a>) -> Result<Opened<'a>> {
    refuse_overwrites(job.input, job.output, job.settings.overwrite)?;
    specconv_exr::check::check_input(job.input)?;
    let (reader, selection) = input::open(job.input, &job.settings.input)?;
    let info = reader.info().clone();
    let space = texture_space(
        job.config,
        &reader,
        &selection,
        job.settings.colorspace.as_deref(),
    )?;
    let premultiply = job
        .settings
        .alpha
        .premultiply(&reader, selection.channels.alpha);
    Ok(Opened {
        job,
        reader,
        info,
        selection,
        space,
        premultiply,
    })
}

impl Opened<'_> {
    /// The colour space the input is read in (the config's name, or a description).
    pub fn colorspace(&self) -> &str {
        &self.space.name
    }

    /// Uplifts every pixel and writes the output with `attributes` in its header (the caller's
    /// provenance). `progress` hears (pixels done, pixels in all) after every window.
    pub fn write(
        self,
        attributes: &[(String, String)],
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Report> {
        let Opened {
            job,
            mut reader,
            info,
            selection,
            space,
            premultiply,
        } = self;
        let file = output_file(job, &info, &selection, attributes)?;
        write_file(
            job,
            &file,
            &mut reader,
            &selection,
            (&space, premultiply),
            progress,
        )
        .map(|(total, counts)| Report {
            width: info.width() as usize,
            height: info.height() as usize,
            pixels: total,
            levels: file.levels(),
            selection,
            colorspace: space.name,
            colorspace_rule: space.rule,
            warnings: space.warnings,
            premultiplied: premultiply,
            non_finite: counts.non_finite,
            above_one: counts.above_one,
            saturated: counts.saturated,
            tally: counts.tally,
        })
    }
}

/// The output's description: its size and windows, bands, blocks and levels (checked against
/// the input's), with `attributes`.
fn output_file(
    job: &Job,
    info: &specconv_oiio::ImageInfo,
    selection: &input::Selection,
    attributes: &[(String, String)],
) -> Result<SpectralFile> {
    let mip = job.settings.mip == Mip::All && info.levels.len() > 1;
    let blocks = match job.settings.tile {
        None if mip => {
            return Err(Error::ScanlineMip {
                input: job.input.to_path_buf(),
                levels: info.levels.len(),
            })
        }
        None => Blocks::Scanlines,
        Some((width, height)) => Blocks::Tiles {
            width,
            height,
            mip_levels: mip,
        },
    };
    let top = info.levels[0];
    let file = SpectralFile::new(Spec {
        width: info.width() as usize,
        height: info.height() as usize,
        windows: Some(Windows {
            data_origin: (top.x, top.y),
            display: (
                top.display.x,
                top.display.y,
                top.display.width as usize,
                top.display.height as usize,
            ),
        }),
        wavelengths: job.method.grid().wavelengths(),
        kind: job.settings.kind.clone(),
        alpha: selection.channels.alpha.is_some(),
        sample: job.settings.sample,
        compression: job.settings.compression,
        zip_level: job.settings.zip_level,
        blocks,
        attributes: attributes.to_vec(),
    })?;
    // Every output level comes from the input level of the same size.
    for level in 0..file.levels() {
        let want = file.level_size(level);
        let have = info
            .levels
            .get(level)
            .map(|l| (l.width as usize, l.height as usize));
        if have != Some(want) || (mip && info.levels.len() != file.levels()) {
            return Err(Error::NotAMipMap {
                input: job.input.to_path_buf(),
                levels: info.levels.len(),
                needed: file.levels(),
                level,
                have,
                want,
            });
        }
    }
    Ok(file)
}

/// Reads, converts, uplifts and writes every window of `file`; returns the pixels uplifted and
/// what they had.
fn write_file(
    job: &Job,
    file: &SpectralFile,
    reader: &mut specconv_oiio::ImageReader,
    selection: &input::Selection,
    (space, premultiply): (&InputSpace, bool),
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(u64, Counts)> {
    let output = job.output;
    if let Some(w) = &job.settings.xyz_weights {
        if w.iter().any(|row| row.len() != job.method.grid().len()) {
            return Err(Error::Weights {
                have: w[0].len(),
                want: job.method.grid().len(),
            });
        }
    }
    let strips = strips(file);
    let total: u64 = strips
        .iter()
        .map(|s| (file.level_size(s.level).0 * s.height) as u64)
        .sum();
    // Enough strips per window to keep every thread busy, at least one.
    let budget = (rayon::current_num_threads() * 8 * 64 * 64) as u64;
    let mut windows = Vec::new();
    let mut current: Vec<Strip> = Vec::new();
    let mut pixels = 0u64;
    for s in strips {
        pixels += (file.level_size(s.level).0 * s.height) as u64;
        current.push(s);
        if pixels >= budget {
            windows.push(std::mem::take(&mut current));
            pixels = 0;
        }
    }
    if !current.is_empty() {
        windows.push(current);
    }

    let read = |reader: &mut specconv_oiio::ImageReader,
                window: &[Strip]|
     -> Result<Vec<specconv_oiio::Pixels>> {
        window
            .iter()
            .map(|s| Ok(reader.read_scanlines(s.level, s.y as u32..(s.y + s.height) as u32)?))
            .collect()
    };
    // The first window is read before the output exists: a file whose pixels cannot be read
    // fails here, leaving nothing behind.
    let mut next = windows.first().map(|w| read(reader, w)).transpose()?;

    let pending = specconv_atomic_file::Pending::beside(output).map_err(|source| Error::Io {
        path: output.to_path_buf(),
        source,
    })?;
    let colour = &selection.channels.colour;
    let alpha = selection.channels.alpha;
    let mut done = 0u64;
    let mut counts = Counts::default();
    // The writer speaks specconv_exr's errors; ours wait here and win over its abort.
    let mut failure: Option<Error> = None;
    let mut fail = |e: Error| {
        failure = Some(e);
        specconv_exr::Error::Invalid("aborted".into())
    };
    let written = file.write(BufWriter::with_capacity(1 << 20, pending.file()), |sink| {
        // Window i's blocks are made while window i + 1 is read and window i − 1's chunks are
        // written, in file order: the writer never holds up the threads that compress.
        let mut made: Vec<(usize, Chunk, Counts)> = Vec::new();
        let mut write = |made: Vec<(usize, Chunk, Counts)>| -> specconv_exr::Result<()> {
            for (chunk_index, chunk, c) in made {
                // A window of fine-band chunks is hundreds of megabytes.
                if job.cancel.load(Ordering::Relaxed) {
                    return Err(specconv_exr::Error::Invalid("cancelled".into()));
                }
                counts.non_finite += c.non_finite;
                counts.above_one += c.above_one;
                counts.saturated += c.saturated;
                counts.tally += c.tally;
                sink(chunk_index, chunk)?;
            }
            Ok(())
        };
        for (i, window) in windows.iter().enumerate() {
            if job.cancel.load(Ordering::Relaxed) {
                return Err(fail(Error::Cancelled));
            }
            let rows = next
                .take()
                .expect("each window is read before it is processed");
            let previous = std::mem::take(&mut made);
            let (chunks, (read_next, wrote)) = rayon::join(
                || -> Result<Vec<(usize, Chunk, Counts)>> {
                    let strips: Vec<Vec<_>> = window
                        .par_iter()
                        .zip(rows.par_iter())
                        .map(|(strip, px)| {
                            strip
                                .blocks
                                .par_iter()
                                .map(|b| {
                                    // Checked per block, not only per window: a window of
                                    // fine-band blocks takes seconds.
                                    if job.cancel.load(Ordering::Relaxed) {
                                        return Err(Error::Cancelled);
                                    }
                                    encode_block(
                                        file,
                                        &space.to_xyz,
                                        job,
                                        b,
                                        px,
                                        colour,
                                        (alpha, premultiply),
                                    )
                                })
                                .collect::<Result<_>>()
                        })
                        .collect::<Result<_>>()?;
                    Ok(strips.into_iter().flatten().collect())
                },
                || {
                    let wrote = write(previous);
                    let read = windows.get(i + 1).map(|w| read(reader, w)).transpose();
                    (read, wrote)
                },
            );
            wrote?;
            next = read_next.map_err(&mut fail)?;
            made = chunks.map_err(&mut fail)?;
            done += window
                .iter()
                .map(|s| (file.level_size(s.level).0 * s.height) as u64)
                .sum::<u64>();
            progress(done, total);
        }
        write(made)
    });
    if let Some(e) = failure {
        return Err(e);
    }
    // Wherever the flag was seen (and whatever error the writer made of it), nothing is
    // published once it is set.
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    written?;
    // Without overwrite, an output another writer published while this one ran is refused,
    // not replaced.
    pending
        .publish(replace_of(job.settings.overwrite))
        .map_err(|source| match source.kind() {
            std::io::ErrorKind::AlreadyExists => Error::Plan(PlanError::Exists {
                output: output.to_path_buf(),
                more: 0,
            }),
            _ => Error::Io {
                path: output.to_path_buf(),
                source,
            },
        })?;
    Ok((total, counts))
}

pub use input::colour_channels;

/// A pixel's RGB from its colour channels ([`input::Channels::colour`]): a single grey channel is repeated; `None` when
/// the image has no colour channel.
#[inline]
pub fn colour_of(px: &[f32], colour: &[usize]) -> Option<[f32; 3]> {
    match colour {
        [r, g, b] => Some([px[*r], px[*g], px[*b]]),
        [grey, ..] => Some([px[*grey]; 3]),
        [] => None,
    }
}

/// Colour-converts, uplifts and compresses one block from its strip's pixels. With
/// `premultiply` the colour is straight: multiplied by alpha once converted, as OpenEXR stores
/// colour premultiplied.
fn encode_block(
    file: &SpectralFile,
    to_xyz: &ToXyz,
    job: &Job,
    b: &Block,
    strip: &specconv_oiio::Pixels,
    colour: &[usize],
    (alpha, premultiply): (Option<usize>, bool),
) -> Result<(usize, Chunk, Counts)> {
    let count = b.width * b.height;
    let mut rgb = Vec::with_capacity(count * 3);
    let mut a = alpha.map(|_| Vec::with_capacity(count));
    let mut counts = Counts::default();
    for y in 0..b.height {
        for x in b.x..b.x + b.width {
            let px = strip.pixel(x as u32, y as u32);
            rgb.extend_from_slice(&colour_of(px, colour).unwrap_or([0.0; 3]));
            if let (Some(a), Some(c)) = (a.as_mut(), alpha) {
                a.push(px[c]);
            }
        }
    }
    // Above 1: by an input channel, or by Y after the conversion.
    let channel_above: Vec<bool> = rgb
        .chunks_exact(3)
        .map(|c| c.iter().any(|&v| v > ABOVE_ONE))
        .collect();
    to_xyz.apply_rgb(&mut rgb)?;
    if let (true, Some(a)) = (premultiply, &a) {
        for (c, alpha) in rgb.chunks_exact_mut(3).zip(a) {
            c.iter_mut().for_each(|v| *v *= alpha);
        }
    }
    for (c, above) in rgb.chunks_exact(3).zip(&channel_above) {
        counts.non_finite += u64::from(!c.iter().all(|v| v.is_finite()));
        counts.above_one += u64::from(*above || c[1] > ABOVE_ONE);
    }
    let n = job.method.grid().len();
    let mut bands = vec![0.0f32; count * n];
    job.method
        .uplift_f32_tallied(&rgb, &mut bands, &mut counts.tally);
    // Compressing a fine-band block takes as long as uplifting it.
    if job.cancel.load(Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    if file.spec().sample == Sample::Half {
        counts.saturated = saturate_half(&mut bands, n);
        if let Some(w) = &job.settings.xyz_weights {
            specconv_exr::quantize::round_to_half_keeping_colour(w, &mut bands, n);
        }
    }
    let chunk = file.encode(b, &bands, a.as_deref())?;
    Ok((b.chunk, chunk, counts))
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

/// Groups the file's blocks into rows (they come level by level, row by row).
fn strips(file: &SpectralFile) -> Vec<Strip> {
    let mut out: Vec<Strip> = Vec::new();
    for b in file.blocks() {
        match out.last_mut() {
            Some(s) if s.level == b.level && s.y == b.y => s.blocks.push(b),
            _ => out.push(Strip {
                level: b.level,
                y: b.y,
                height: b.height,
                blocks: vec![b],
            }),
        }
    }
    out
}

/// Refuses a special file as input (before anything probes it), writing over the input, and
/// over an existing output unless asked to: the rules every writer shares
/// (specconv_atomic_file::plan).
fn refuse_overwrites(input: &Path, output: &Path, overwrite: bool) -> Result<()> {
    specconv_atomic_file::readable_file(input)?;
    Ok(specconv_atomic_file::check_plan(
        &[input],
        &[output],
        replace_of(overwrite),
    )?)
}

fn replace_of(overwrite: bool) -> Replace {
    if overwrite {
        Replace::Allowed
    } else {
        Replace::Never
    }
}
