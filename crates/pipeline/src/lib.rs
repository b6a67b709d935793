//! The conversion job: file ──OIIO──▶ RGB strip ──OCIO──▶ XYZ ──uplift──▶ bands ──exr──▶ file.
//!
//! Work flows in strips: the blocks of the output that share a level and a row. A window of
//! strips is read from the input (one reader, in order, so scanline formats such as PNG decode
//! once) while the previous window's blocks are colour-converted, uplifted and compressed in
//! parallel; chunks are then written in file order. Memory is bounded by the window, whatever
//! the image height, and the output bytes do not depend on the number of threads. What a
//! window needs is estimated before the output exists, and a file that cannot fit is refused
//! with the figure ([`memory`]).
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
pub mod expand;
pub mod filter;
pub mod header;
pub mod in_memory;
pub mod input;
pub mod interop;
pub mod memory;
mod mip;
pub mod palette;
pub mod png;
pub mod survey;
pub mod texture;
pub mod transfer;
pub mod wrapped;
mod write;

// The description of a conversion, under its names in this crate.
use specconv_description::{
    choices, layout, metadata, options, report, DataPolicy, Filter, NonFinite, Options, Rounding,
};
pub use wrapped::{ColourError, ImageError};

use crate::choices::Mip;
use crate::report::{Report, Role};
pub use colour::{input_space, texture_space, DataTexture, InputSpace, Rule, ToXyz, Warning};
use filter::Kernel;
use specconv_atomic_file::Replace;
use specconv_exr::{Block, Blocks, Chunk, Kind, Sample, Spec, SpectralFile, Windows};
use specconv_ocio::Config;
use specconv_spectral::compact::{Compact, Precision};
use specconv_spectral::method::Tally;
use specconv_spectral::stack::Stack;
use specconv_spectral::Method;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use write::write_file;

/// Why a conversion failed, by cause. Messages name no command-line option: a front-end adds
/// its own hint (the CLI's flags, the Python package's keywords).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be read.
    #[error(transparent)]
    Input(#[from] crate::wrapped::ImageError),
    /// The input's colour could not be managed.
    #[error(transparent)]
    Color(#[from] crate::wrapped::ColourError),
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
    /// Pixels in memory that cannot be made texels as given ([`in_memory`]).
    #[error("{0}")]
    InMemory(String),
    /// NaN or infinite values in the channels read, refused.
    #[error(
        "{}: {pixels} pixel(s) of rows {}–{} have NaN or infinite values (the first at x {}, y {}); \
         every filter that reads them, MIP levels included, spreads them",
        input.display(), rows.0, rows.1 - 1, first.0, first.1
    )]
    NonFinite {
        /// The input.
        input: PathBuf,
        /// Such pixels found (the pass stops at the first rows that have any).
        pixels: u64,
        /// The first (x, y).
        first: (usize, usize),
        /// The rows read when they were found.
        rows: (usize, usize),
    },
    /// More non-finite pixels than box3 repairs.
    #[error(
        "{}: more than {limit} pixels have NaN or infinite values, more than a 3×3 repair keeps",
        input.display()
    )]
    TooManyNonFinite {
        /// The input.
        input: PathBuf,
        /// `survey::BOX3_LIMIT`.
        limit: u64,
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
    /// The input is a compact spectral texture (`input::open`): its texels are spectra, not
    /// colours to uplift again.
    #[error(
        "{}: a compact spectral texture (specconv's compact layout): its spectra are not \
         uplifted again from its colour",
        path.display()
    )]
    Compact {
        /// The input.
        path: PathBuf,
    },
    /// The input is a spectral image already (`input::open`): it is not uplifted again.
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
    /// The input holds data, not colour (`colour::texture_space`): it is never uplifted.
    #[error(transparent)]
    Data(Box<DataTexture>),
    /// A file to expand that is not a compact texture this version reads.
    #[error("{}: not a compact texture: {why}", path.display())]
    NotCompact {
        /// The file.
        path: PathBuf,
        /// What is missing or wrong.
        why: String,
    },
    /// The file would need more memory at once than this process may use ([`memory`]):
    /// refused before the output exists.
    #[error("{0}")]
    TooMuchMemory(memory::Shortfall),
    /// A warning, which the strict setting makes a failure: nothing was written.
    #[error(
        "{}: {warning}; in strict mode a warning fails the input, and nothing was written",
        input.display()
    )]
    Strict {
        /// The input.
        input: PathBuf,
        /// The warning ([`specconv_description::Notice`]'s words).
        warning: String,
    },
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_oiio::Error> for Error {
    fn from(e: specconv_oiio::Error) -> Error {
        Error::Input(e.into())
    }
}

// Inside this crate only: no front-end names an FFI type.
#[doc(hidden)]
impl From<specconv_ocio::Error> for Error {
    fn from(e: specconv_ocio::Error) -> Error {
        Error::Color(e.into())
    }
}

/// The pipeline's results.
pub type Result<T> = std::result::Result<T, Error>;

/// How the spectra are stored, as the options and the method stack decide it together
/// ([`Storage::of`]): everything a job needs beyond the options themselves.
#[derive(Debug, Clone)]
pub struct Storage {
    /// Reflectance (`T.` channels) or emission (`S0.` channels with their units).
    pub kind: Kind,
    /// Per band, the weights of X, Y and Z with which the spectra will be read back (the
    /// method's colorimetry): half samples are rounded to keep that colour
    /// ([`specconv_exr::quantize`]); `None` rounds to nearest.
    pub xyz_weights: Option<[Vec<f64>; 3]>,
    /// The range a filter with negative lobes ([`Filter::has_negative_lobes`]) keeps the
    /// bands it makes in: [0, 1] for bounded reflectance. Alpha is kept in [0, 1].
    pub band_range: (f32, f32),
    /// The compact layout's encoder: texels of [`COMPACT_CHANNELS`] instead of bands.
    pub compact: Option<Compact>,
    /// How a compact texel's colour and u are stored (`--data-type`: half as maketx stores
    /// colour, u as half where exact enough; float32 throughout).
    pub precision: Precision,
}

impl Storage {
    /// What `options` make of `stack`'s spectra, with the compact layout's encoder when it
    /// is the layout.
    pub fn of(options: &Options, stack: &Stack, compact: Option<Compact>) -> Storage {
        let precision = match options.sample {
            Sample::Half => Precision::Half,
            Sample::Float => Precision::Float,
        };
        if let Some(compact) = compact {
            // Colours and dual unknowns, rounded by `Compact::store`: no range but a number's.
            let float = |name: &str| precision == Precision::Float || name.starts_with("UF.");
            let channels = COMPACT_CHANNELS.map(|name| {
                let sample = if float(name) {
                    Sample::Float
                } else {
                    Sample::Half
                };
                (name.to_string(), sample)
            });
            return Storage {
                kind: specconv_exr::Kind::Named(channels.to_vec()),
                xyz_weights: None,
                band_range: (f32::NEG_INFINITY, f32::INFINITY),
                compact: Some(compact),
                precision,
            };
        }
        let by_colour = options.rounding_in_effect() == Rounding::Colour;
        Storage {
            kind: crate::layout::bands(options.emission),
            xyz_weights: by_colour.then(|| match stack.emission() {
                Some(e) => e.emission.weights.clone(),
                None => stack.colorimetry().weights.clone(),
            }),
            // What a filter's negative lobes may not push a band beyond: a bounded reflectance
            // stays in [0, 1]; nothing physical is negative.
            band_range: if options.bounded && options.emission.is_none() {
                (0.0, 1.0)
            } else {
                (0.0, f32::INFINITY)
            },
            compact: None,
            precision,
        }
    }

    /// Values a pixel holds beside alpha: the `bands` of the spectra, or a compact texel's.
    pub fn values(&self, bands: usize) -> usize {
        match self.compact {
            Some(_) => specconv_spectral::compact::STORED,
            None => bands,
        }
    }
}

/// A compact texel's channels as a file stores them, in the order of its values
/// ([`specconv_spectral::compact::Compact::store`]): the colour in the working space (so that
/// any viewer shows the texture), u as half, u as float32.
pub const COMPACT_CHANNELS: [&str; specconv_spectral::compact::STORED] =
    ["R", "G", "B", "U.0", "U.1", "U.2", "UF.0", "UF.1", "UF.2"];

/// The attribute that names a compact file's layout and version (`compact 2`).
pub const LAYOUT_ATTRIBUTE: &str = "specconvLayout";
/// The attribute that holds a compact file's model and decoding rule (docs/compact.md).
pub const COMPACT_ATTRIBUTE: &str = "specconvCompact";
/// The attribute that holds how `specconv expand` stores the spectra (`expand::settings`).
pub const EXPAND_ATTRIBUTE: &str = "specconvExpand";

/// Values above this count as above 1: 0.1 % of headroom, so that the rounding of colour
/// conversion does not make white count.
pub const ABOVE_ONE: f32 = 1.001;

/// What one block's pixels had; see [`Report`].
#[derive(Debug, Clone, Copy, Default)]
struct Counts {
    non_finite: u64,
    above_one: u64,
    saturated: u64,
    clamped: u64,
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
    pub stack: &'a Stack,
    /// What the conversion is asked to do.
    pub options: &'a Options,
    /// How the spectra are stored.
    pub storage: &'a Storage,
    /// Write over an existing output (the options', or a batch's update of its own output).
    pub overwrite: bool,
    /// Set from another thread (a signal handler) to stop the job.
    pub cancel: &'a AtomicBool,
}

impl Job<'_> {
    /// The method every pixel is uplifted with.
    fn method(&self) -> &dyn Method {
        self.stack.method()
    }

    /// Values a pixel of the output holds beside alpha: bands, or a compact texel's.
    fn values(&self) -> usize {
        self.storage.values(self.method().grid().len())
    }

    /// The tile size, or `None` for scanlines.
    fn tile(&self) -> Option<(usize, usize)> {
        match self.options.blocks {
            specconv_description::Blocks::Tiles(w, h) => Some((w, h)),
            specconv_description::Blocks::Scanlines => None,
        }
    }
}

/// One row of blocks: the unit read from the input.
struct Strip {
    level: usize,
    y: usize,
    height: usize,
    blocks: Vec<Block>,
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
    /// The wrap modes, and whether the input declared them.
    wrap: (texture::WrapModes, bool),
    survey: survey::Survey,
    /// The input's metadata the output carries and what it drops (none when stripped).
    metadata: metadata::Carry,
}

/// Opens `job`'s input: refuses to write over the input or an existing output (unless the
/// settings allow it), checks an OpenEXR input's header, chooses channels and colour space.
pub fn open<'a>(job: &'a Job<'a>) -> Result<Opened<'a>> {
    refuse_overwrites(job.input, job.output, job.overwrite)?;
    specconv_exr::check::check_input(job.input)?;
    png::check_whole(job.input)?;
    let (reader, selection) = input::open(job.input, &input::Request::of(job.options))?;
    let info = reader.info().clone();
    let space = match texture_space(
        job.config,
        &reader,
        &selection,
        job.options.colorspace.as_deref(),
    ) {
        // A data texture to be copied meets a conversion's rule on NaN and infinities: every
        // channel surveyed as a conversion's are, before anything is written.
        Err(Error::Data(data))
            if job.options.data == crate::DataPolicy::Copy
                && job.options.non_finite != crate::NonFinite::Keep =>
        {
            let mut reader = reader;
            let every: Vec<usize> = (0..reader.info().channels.len()).collect();
            survey::survey(job.into(), &mut reader, (&every, None))?;
            return Err(Error::Data(data));
        }
        other => other?,
    };
    if let (true, Some(w)) = (job.options.strict, space.warnings.first()) {
        return Err(Error::Strict {
            input: job.input.to_path_buf(),
            warning: w.to_string(),
        });
    }
    let premultiply = colour::premultiply(job.options.alpha, &reader, selection.channels.alpha);
    let declared = texture::declared(&reader);
    let metadata = match job.options.strip_metadata {
        true => metadata::Carry::default(),
        false => texture::metadata(&reader, job.input)?,
    };
    if job.options.strict && !metadata.dropped.is_empty() {
        return Err(Error::Strict {
            input: job.input.to_path_buf(),
            warning: metadata::describe(&metadata.dropped),
        });
    }
    let wrap = match (job.options.wrap, declared) {
        (Some(w), _) => (w, false),
        (None, Some(w)) => (w, true),
        (None, None) => (texture::DEFAULT_WRAP, false),
    };
    let mut reader = reader;
    let survey = survey::survey(
        job.into(),
        &mut reader,
        (&selection.channels.colour, selection.channels.alpha),
    )?;
    Ok(Opened {
        job,
        reader,
        info,
        selection,
        space,
        premultiply,
        wrap,
        survey,
        metadata,
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
            wrap,
            survey,
            metadata,
        } = self;
        // The caller's attributes first; the input's metadata where they name nothing.
        let mut attributes = attributes.to_vec();
        let metadata_dropped = metadata.dropped;
        for (name, value) in metadata.kept {
            if !attributes.iter().any(|(n, _)| *n == name) {
                attributes.push((name, value));
            }
        }
        let dropped = job.options.opaque_detect && survey.opaque;
        let alpha = selection.channels.alpha.filter(|_| !dropped);
        let constant = survey
            .constant
            .as_deref()
            .filter(|_| job.options.constant_detect && job.tile().is_some());
        let (file, source) = output_file(
            job,
            &info,
            (alpha.is_some(), constant.is_some()),
            &attributes,
            wrap.0,
            &survey,
        )?;
        let reading = Reading {
            to_xyz: &space.to_xyz,
            colour: &selection.channels.colour,
            alpha,
            premultiply: premultiply && alpha.is_some(),
            repair: &survey.repair,
        };
        let (total, counts) = write_file(
            job,
            (&file, source),
            &mut reader,
            &reading,
            constant,
            progress,
        )?;
        let levels = file.levels();
        let stack = job.stack;
        Ok(Report {
            role: if selection.channels.colour.len() == 1 {
                Role::Achromatic
            } else {
                Role::Colour
            },
            data: None,
            width: info.width() as usize,
            height: info.height() as usize,
            pixels: total,
            levels,
            wrap: job.tile().map(|_| wrap),
            non_finite_input: (survey.non_finite, survey.repaired),
            constant: constant.is_some(),
            opaque_dropped: dropped,
            source_hash: survey.hash.clone(),
            bands: stack.method().grid().len(),
            selection,
            colorspace: space.name,
            colorspace_rule: space.rule,
            warnings: space.warnings,
            metadata_dropped,
            premultiplied: premultiply && alpha.is_some(),
            non_finite: counts.non_finite,
            above_one: counts.above_one,
            saturated: counts.saturated,
            clamped: counts.clamped,
            filter: (levels > 1 || job.options.resize).then_some(job.options.filter),
            bounded: stack.counts_bounded().then_some(counts.tally.bounded),
            unmatched: stack.emissive().map(|_| counts.tally.unmatched),
            // The converter times the whole call.
            seconds: 0.0,
        })
    }
}

/// The output's description: its size and windows, bands, blocks and levels, with
/// `attributes`, the texture's and what the survey found; and the size of the spectra level 0
/// is made of (the input's, or a constant texture's tile). `(alpha, constant)`: whether alpha
/// is written, and whether the texture is written as one tile of its constant colour.
fn output_file(
    job: &Job,
    info: &specconv_oiio::ImageInfo,
    (alpha, constant): (bool, bool),
    attributes: &[(String, String)],
    wrap: texture::WrapModes,
    survey: &survey::Survey,
) -> Result<(SpectralFile, (usize, usize))> {
    // Every tiled output is a MIP map made from its own spectra (module `mip`); the input's
    // smaller levels, if any, are not read.
    let blocks = match job.tile() {
        None => Blocks::Scanlines,
        Some((width, height)) => Blocks::Tiles {
            width,
            height,
            mip_levels: job.options.mip == Mip::All,
        },
    };
    let top = info.levels[0];
    let (mut width, mut height) = (info.width() as usize, info.height() as usize);
    let mut windows = windows_of(&top);
    if let (true, Some((tw, th))) = (constant, job.tile()) {
        // One tile, as maketx --constant-color-detect: the display window is the data
        // window, so that lookups over [0, 1] read it all.
        (width, height) = (width.min(tw), height.min(th));
        windows.display = (top.x, top.y, width, height);
    }
    let source = (width, height);
    if job.options.resize {
        // maketx --resize: each size up to a power of two, and the texture spans it.
        (width, height) = (width.next_power_of_two(), height.next_power_of_two());
        windows.display = (windows.display.0, windows.display.1, width, height);
    }
    // A tiled output is a texture: its wrap modes and format, as maketx writes them.
    let (mut extra, fovcot) = match blocks {
        Blocks::Tiles { .. } => (
            texture::attributes(wrap),
            vec![(
                "fovcot".to_string(),
                texture::fovcot(windows.display.2, windows.display.3),
            )],
        ),
        Blocks::Scanlines => (Vec::new(), Vec::new()),
    };
    extra.push((survey::SOURCE_HASH.to_string(), survey.hash.clone()));
    if let Some(compact) = &job.storage.compact {
        extra.push((
            LAYOUT_ATTRIBUTE.into(),
            specconv_spectral::compact::VERSION.into(),
        ));
        extra.push((COMPACT_ATTRIBUTE.into(), compact.to_text()));
        extra.push((EXPAND_ATTRIBUTE.into(), expand::settings(job.options)));
    }
    let spec = Spec {
        width,
        height,
        windows: Some(windows),
        wavelengths: match &job.storage.compact {
            Some(_) => (1..=job.values()).map(|i| i as f64).collect(),
            None => job.method().grid().wavelengths(),
        },
        kind: job.storage.kind.clone(),
        alpha,
        sample: job.options.sample,
        compression: job.options.compression.exr(),
        zip_level: job
            .options
            .zip_level
            .unwrap_or(specconv_exr::zip::DEFAULT_LEVEL),
        blocks,
        attributes: attributes.iter().cloned().chain(extra).collect(),
        float_attributes: fovcot,
    };
    // The average of each channel, known once level 0 is made: its place kept here, its
    // value written then (`average_attributes`).
    let mut spec = spec;
    let placeholder = average_text(&vec![0.0; usize::from(alpha) + spec.wavelengths.len()]);
    spec.attributes.push((AVERAGE.into(), placeholder.clone()));
    if constant {
        spec.attributes.push((CONSTANT.into(), placeholder));
    }
    Ok((SpectralFile::new(spec)?, source))
}

/// What OpenImageIO's texture system reports as a texture's average colour.
const AVERAGE: &str = "oiio:AverageColor";
/// What it answers every lookup of a constant texture with.
const CONSTANT: &str = "oiio:ConstantColor";

/// Values as `oiio:AverageColor` lists them, each in 13 characters (`+1.234568e-01`), so that
/// the text's length does not depend on them.
fn average_text(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| {
            if !v.is_finite() {
                return format!("{v:>13}");
            }
            let text = format!("{v:+.6e}");
            let (mantissa, exponent) = text.split_once('e').expect("{:e} has an exponent");
            let exponent: i32 = exponent.parse().expect("{:e}'s exponent is an integer");
            format!(
                "{mantissa}e{}{:02}",
                if exponent < 0 { '-' } else { '+' },
                exponent.abs()
            )
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// The average (and, for a constant texture, the constant) colour attributes of `file`, from
/// the sums of level 0's values (bands, then alpha) over its `pixels`.
fn average_attributes(file: &SpectralFile, sums: &[f64], pixels: u64) -> Vec<(String, String)> {
    let mean: Vec<f64> = sums.iter().map(|s| s / pixels as f64).collect();
    let text = average_text(&file.in_channel_order(&mean));
    let constant = file
        .spec()
        .attributes
        .iter()
        .any(|(k, _)| k == CONSTANT)
        .then(|| (CONSTANT.to_string(), text.clone()));
    std::iter::once((AVERAGE.to_string(), text))
        .chain(constant)
        .collect()
}

/// One block made: its chunk (none for the input's spectra that a resized level 0 is made
/// of), what its pixels had, and (for a MIP map) its values — the spectra before rounding,
/// alpha after each spectrum when the file has it — for the smaller levels.
struct Made {
    index: usize,
    chunk: Option<Chunk>,
    counts: Counts,
    kept: Option<Vec<f32>>,
    /// Level 0: the sums of its values, bands then alpha (for the average); else empty.
    sums: Vec<f64>,
}

/// Encodes one block of a smaller level from its strip's values.
fn encode_made_block(
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
fn clamp_made(
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
fn level_sums(bands: &[f32], alpha: Option<&[f32]>, n: usize) -> Vec<f64> {
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

pub use input::colour_channels;

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
    to_xyz: &'a ToXyz,
    colour: &'a [usize],
    alpha: Option<usize>,
    /// The colour is straight: multiplied by alpha once converted, as OpenEXR stores colour
    /// premultiplied.
    premultiply: bool,
    repair: &'a survey::Repair,
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
fn encode_block(
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

/// Rounds a block's spectra as the file stores them (half: finite values kept finite, and
/// the colour kept when asked) and compresses it; returns the chunk and the spectra clamped.
fn finish_block(
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
fn finish(
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

/// The hash of `input`'s full-resolution pixels in the subimage `request` names, as
/// conversions record it ([`survey::Survey::hash`]).
pub fn source_hash(input: &Path, request: &input::Request) -> Result<String> {
    specconv_atomic_file::readable_file(input)?;
    let (mut reader, _) = input::open(input, request)?;
    survey::source_hash(&mut reader)
}

/// Refuses a special file as input (before anything probes it), writing over the input, and
/// over an existing output unless asked to: the rules every writer shares
/// (specconv_atomic_file::plan).
fn refuse_overwrites(input: &Path, output: &Path, overwrite: bool) -> Result<()> {
    specconv_atomic_file::readable_file(input)?;
    Ok(specconv_atomic_file::check_plan(
        &[input],
        &[output],
        Replace::when(overwrite),
    )?)
}

/// The data and display windows an output keeps of its input's level `top`.
pub(crate) fn windows_of(top: &specconv_oiio::Level) -> Windows {
    Windows {
        data_origin: (top.x, top.y),
        display: (
            top.display.x,
            top.display.y,
            top.display.width as usize,
            top.display.height as usize,
        ),
    }
}
