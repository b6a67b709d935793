//! `specconv [convert] INPUT… OUTPUT`: the main job.

mod plan;
mod printing;

pub(crate) use plan::for_farm;
use printing::converted;

use crate::options::{default_of, named, parsed};
use crate::progress::{Progress, Summary};
use crate::stdio::StdoutFailed;
use crate::{exit, explain, methods, print_error, records, signals, usage};
use anyhow::Result;
use specconv_conversion::{
    Advice, Alpha, Batch, Blocks, Compression, Converter, DataPolicy, Event, Filter, Key, Layout,
    Mip, NonFinite, Options, Rounding, Sample, WrapModes,
};
use specconv_spectral::method::MethodName;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv convert albedo.tx albedo_spectral.exr
  specconv convert --colorspace ACEScg -d float plate.exr plate_spectral.exr
  specconv convert textures/*.png -o spectral -u --json > convert.jsonl
  specconv convert 'wood.<UDIM>.png' --output-template '{dir}/{stem}_spectral.{udim}.exr'
  specconv convert sky.hdr sky_spectral.exr --emissive
  find textures -name '*.tx' | specconv convert - -o spectral --progress always 2> convert.log
";

/// Convert textures to spectral OpenEXR images (the default command).
///
/// Reads each INPUT through OpenImageIO (any format it reads; of a MIP-mapped input only the
/// full-resolution level 0, as maketx does), converts it to CIE XYZ (D65) through OpenColorIO,
/// uplifts every pixel to a reflectance spectrum with the model, makes the smaller MIP levels
/// by filtering its spectra, and writes a spectral OpenEXR in the layout of Fichet et al. 2021 (`T.380,000000nm`
/// … channels, alpha as `A`). Outputs are written to a temporary file and renamed into place,
/// so a failed or interrupted run leaves no partial file; inputs are never overwritten.
///
/// Reflectances stop at 1: a colour with Y > 1 is brighter than white, which no reflectance
/// is. Bounded methods move it to the closest colour a reflectance can have (brightness clipped
/// at white); unbounded ones give it a spectrum above 1. The summary counts pixels above 1 and
/// suggests --emissive when they look like an emission or HDR texture.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input textures, then the output file when converting one; `-` reads input paths from
    /// standard input, one per line. A UDIM pattern (`wood.<UDIM>.png`, `<udim>` or
    /// `%(UDIM)d` in the file name) stands for the tiles that exist, in tile order; converting
    /// one pattern, name the output with the token too (`wood_spectral.<UDIM>.exr`).
    #[arg(value_name = "INPUT… [OUTPUT]", required = true)]
    paths: Vec<PathBuf>,
    /// Write every output into this directory, as STEM_spectral.exr.
    #[arg(short, long, value_name = "DIR", conflicts_with = "output_template")]
    output: Option<PathBuf>,
    /// Output path for each input; {dir}, {stem}, {name} and {ext} are the input's directory,
    /// name without extension, file name and extension, {udim} its UDIM tile number (1001…)
    /// and {tile} the same tile as u1_v1 ('{dir}/{stem}_{ext}_spectral.exr' keeps brick.png
    /// and brick.tx apart). With {udim} or {tile}, {stem} leaves the tile number out:
    /// '{dir}/{stem}_spectral.{udim}.exr' makes wood_spectral.1001.exr of wood.1001.png. Any
    /// other {field} is refused before anything is written.
    #[arg(long, value_name = "TEMPLATE")]
    output_template: Option<String>,
    /// The global --ocio (see `specconv --help`).
    #[arg(skip)]
    pub(crate) ocio: Option<String>,
    /// The input's colour space, overriding all other evidence. Without it, the first of: the
    /// config's explicit file rules; strong declarations in the file (ICC profile, EXR
    /// chromaticities, a colour-space name); weak ones (PNG sRGB/cHRM/gAMA); the Default rule
    /// of a config given by --ocio or $OCIO; linear Rec.709 for float and sRGB texture for
    /// integer pixels (docs/colour.md).
    #[arg(long, visible_alias = "iscolorspace", value_name = "NAME")]
    colorspace: Option<String>,
    #[command(flatten)]
    read: ReadArgs,
    /// Whether the input's colour is straight (unassociated) or premultiplied by alpha: `auto`
    /// as the file says (PNG straight, OpenEXR premultiplied), or force either for files that
    /// say it wrong (as oiiotool's --no-autopremult). Straight colour is converted, then
    /// premultiplied: OpenEXR stores premultiplied colour.
    #[arg(long, value_name = "HOW", default_value = default_of(Key::Alpha), value_parser = named::<Alpha>())]
    alpha: Alpha,
    /// What to do with a data texture (roughness, normal map, mask), which is never uplifted:
    /// one whose colour space is data (OCIO isdata, such as Raw: by --colorspace, the file, or
    /// the config's file rules, ahead of PNG chunks), or one channel that neither
    /// --colorspace, a file rule nor a strong declaration in the file calls colour. `skip` writes nothing (status `data`, not a failure); `copy` writes it through
    /// as a tiled, MIP-mapped data texture, values and metadata kept (OpenImageIO's
    /// make_texture, as maketx); `fail` counts it as a failure.
    #[arg(long, value_name = "HOW", default_value = default_of(Key::Data), value_parser = named::<DataPolicy>())]
    data: DataPolicy,
    /// Uplift method: otsu2018 (the clustered PCA of the model), pca (a one-cluster model),
    /// smits1999, meng2015, meng2015-bounded or jakob2019.
    #[arg(long, value_name = "NAME", default_value = default_of(Key::Method), value_parser = named::<MethodName>())]
    method: MethodName,
    #[command(flatten)]
    pub(crate) stack: methods::StackArgs,
    /// Write emission (`S0.` channels, `emissiveUnits` W.m^-2.sr^-1) instead of reflectance:
    /// the colour is that of emitted radiance, of any brightness, and each spectrum L has it
    /// under the observer alone, in the convention of --emission-units. Each colour is scaled
    /// into half the range of reflectances, uplifted by the method and scaled back, so the
    /// shape does not depend on brightness; with a bounded method L ≥ 0. `to-rgb` turns it
    /// back into the input colours.
    #[arg(long)]
    emissive: bool,
    /// What S0 values mean (recorded as specconvEmissionUnits): `reference`, the layout's
    /// reference implementation, ∫ S0·x̄ dλ (1 nm steps) = the input's XYZ; `normalised`,
    /// ∫ S0·ȳ dλ / ∫ ȳ dλ = Y, a flat S0 = 1 has Y = 1 (pbrt-v4, Mitsuba 3), ≈106.8× the
    /// reference's values; `photometric`, the input's Y is luminance in cd/m² and S0 is
    /// radiance in W·m⁻²·sr⁻¹·nm⁻¹, Y = 683·∫ S0·ȳ dλ, 1/683 of the reference's values.
    #[arg(
        long,
        value_name = "UNITS",
        default_value = Options::default().emission.unwrap_or_default().to_string(),
        value_parser = named::<specconv_colour::EmissionUnits>(),
        requires = "emissive"
    )]
    emission_units: specconv_colour::EmissionUnits,
    /// How the spectra are stored: `spectral`, a band a channel in the layout of Fichet et al.
    /// 2021; `compact`, six float32 values a texel (its colour `C.X C.Y C.Z` and the bounded
    /// projection's dual unknowns `U.0 U.1 U.2`) with the model's maps and the decoding rule in
    /// the header: the same spectra at the size of RGB, for renderers that decode per lookup
    /// (docs/compact.md); `specconv expand` writes the spectral layout from it. The clustered
    /// methods' reflectance only; its smaller MIP levels hold the filtered colour, their dual
    /// unknowns solved again.
    #[arg(long, value_name = "LAYOUT", default_value = default_of(Key::Layout), value_parser = named::<Layout>())]
    layout: Layout,
    /// Sample type of the output.
    #[arg(short = 'd', long = "data-type", value_name = "TYPE", default_value = default_of(Key::Sample), value_parser = named::<Sample>())]
    data_type: Sample,
    /// How half samples are rounded: `nearest` rounds each band on its own (the colour moves
    /// by up to ≈3e-4 relative, below what half can resolve per band); `colour` picks, band by
    /// band, the half below or above so that the spectrum's XYZ moves as little as possible
    /// (≈5× smaller colour error, ≈1.5× the conversion time of a 36-band ZIP file).
    /// Default: `nearest` for reflectances, `colour` for --emissive, whose dark pixels' S0
    /// values (∫ S0·x̄ dλ = XYZ: ≈1/107 of Y per band) fall where half has few digits.
    #[arg(long, value_name = "HOW", value_parser = named::<Rounding>())]
    half_rounding: Option<Rounding>,
    /// Output compression. The lossless ones: none, rle, zips, zip, piz, pxr24 (for half;
    /// float loses 8 bits); b44, b44a, dwaa and dwab lose precision (docs/compression.md
    /// compares them all).
    #[arg(long, default_value = default_of(Key::Compression), value_parser = named::<Compression>())]
    compression: Compression,
    /// Deflate level of zip and zips, 0 (stored) to 9 (smallest), as OpenEXR's
    /// zipCompressionLevel; the default is the measured best trade (docs/compression.md).
    #[arg(long, value_name = "LEVEL", value_parser = clap::value_parser!(u8).range(0..=9))]
    zip_level: Option<u8>,
    /// Tile width and height of the output.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = crate::options::default_tile())]
    tile: Vec<usize>,
    /// Write scanlines instead of tiles (no MIP levels).
    #[arg(long, conflicts_with = "tile")]
    scanline: bool,
    /// `all`: a MIP map (tiled outputs), each level filtered from the spectra of the level
    /// above as maketx filters (the input's own smaller levels are not read); `0`: the full
    /// resolution only.
    #[arg(long, default_value = default_of(Key::Mip), value_parser = named::<Mip>())]
    mip: Mip,
    /// The filter each MIP level is made with from the spectra of the level above, as maketx's
    /// `--filter`: `box` (its default: the 2×2 average, bilinear at odd sizes) or one of
    /// OpenImageIO's. Filters with negative lobes (lanczos3, catmull-rom, mitchell, sinc, the
    /// cubics) clamp what they push out of range: bands into [0, 1] (bounded reflectance) or
    /// above 0, alpha into [0, 1].
    #[arg(long, value_name = "NAME", default_value = default_of(Key::Filter), value_parser = named::<Filter>())]
    filter: Filter,
    /// Resize level 0 up to the next power of two in each direction, as maketx's `--resize`:
    /// the input is uplifted at its own size and its spectra resampled with --filter (box and
    /// triangle: bilinearly, as maketx).
    #[arg(long)]
    resize: bool,
    /// Wrap modes the texture records, `MODE` or `S,T` (black, clamp, periodic, mirror);
    /// default: the input's (a maketx texture's), else black, as maketx.
    #[arg(long, value_name = "MODE[,MODE]", value_parser = parsed(Key::Wrap, |o| o.wrap))]
    wrap: Option<WrapModes>,
    /// Repair NaN and infinite input values: `box3` (the average of the finite 3×3
    /// neighbours), `black` (0), or `none` to write them as they are. Without it such an input
    /// is refused (as maketx --checknan).
    #[arg(long, value_name = "HOW", conflicts_with = "checknan", value_parser = named::<NonFinite>())]
    fixnan: Option<NonFinite>,
    /// Refuse inputs with NaN or infinite values (the default; for maketx habits).
    #[arg(long)]
    checknan: bool,
    /// Write a texture whose pixels are all the same as one tile, recording
    /// oiio:ConstantColor (default true, as maketx --constant-color-detect).
    #[arg(long, value_name = "BOOL", num_args = 0..=1, require_equals = true,
          default_value_t = Options::default().constant_detect, default_missing_value = "true", action = clap::ArgAction::Set)]
    constant_color_detect: bool,
    /// Leave out an alpha that is 1 everywhere (default true, as maketx --opaque-detect).
    #[arg(long, value_name = "BOOL", num_args = 0..=1, require_equals = true,
          default_value_t = Options::default().opaque_detect, default_missing_value = "true", action = clap::ArgAction::Set)]
    opaque_detect: bool,
    /// Leave out the input's texture metadata. Without it the output carries, as maketx does,
    /// the input's Copyright, DocumentName, ImageDescription, Artist and custom string
    /// attributes (such as studio:assetId), and `to-rgb` carries them back.
    #[arg(long)]
    strip_metadata: bool,
    /// Fail an input on any warning (a declaration of the file not followed, pixels above 1
    /// clipped in a reflectance conversion, 1 % of the image or more): nothing is written for
    /// it and the exit status is 1, for farms that gate on warnings.
    #[arg(long)]
    strict: bool,
    /// Worker threads (default: one per core).
    #[arg(short = 'j', long, value_name = "N")]
    threads: Option<usize>,
    /// Replace existing outputs.
    #[arg(long)]
    force: bool,
    /// Skip inputs whose output is newer than the input and was made with the same settings.
    #[arg(short, long)]
    update: bool,
    /// Print one JSON object per input on standard output, every key on every record (null
    /// where it does not apply): input, output, status (ok, skipped, failed), skip_reason,
    /// error, seconds, pixels, width, height, levels, bands, colorspace, colorspace_rule,
    /// subimage, channels, role, bounded, non_finite, above_one, saturated, warnings; status
    /// `clipped` is a conversion with pixels above 1 in reflectance. See docs/json.md.
    #[arg(long)]
    json: bool,
    /// Progress on standard error: `auto` shows a live line on a terminal (file i of n, the
    /// batch's ETA) and a plain line every few seconds when standard error is a file; `always`
    /// also into a pipe; `never` shows none.
    #[arg(long, value_name = "WHEN", default_value = "auto")]
    progress: crate::progress::When,
    /// Print nothing but errors (no progress, no summary).
    #[arg(short, long)]
    quiet: bool,
    /// Convert only shard I of N (`I/N`, I from 0), or `auto/N` with I from
    /// $SLURM_ARRAY_TASK_ID: inputs split by pixel count, the same plan on every run and as
    /// `farm submit`, so N runs given the same inputs convert each exactly once.
    #[arg(long, value_name = "I/N")]
    shard: Option<specconv_farm::Shard>,
    /// Say more: the colour space chosen and why, the config, the model.
    #[arg(short, long)]
    verbose: bool,
}

/// `--subimage` and `--channels`, shared with `info`.
#[derive(Debug, Clone, clap::Args)]
pub struct ReadArgs {
    /// The subimage (OpenEXR part) to read: its index or name. Default: the first; the report
    /// names the one read when the file has several.
    #[arg(long, value_name = "N|NAME")]
    pub subimage: Option<String>,
    /// The channels that carry the colour: names R,G,B or R,G,B,A (Y or Y,A for grey), or a
    /// layer such as `diffuse` (diffuse.R, .G, .B and .A if present). Default: the channels named
    /// R, G, B (and A); else, without layers, the channels in order; else the only layer with
    /// R, G and B. Other layered files are refused with the list of their layers.
    #[arg(long, value_name = "LIST|LAYER")]
    pub channels: Option<String>,
}

/// Runs the conversion of every input; returns the exit status ([`exit`]: all done, any
/// failed, interrupted). Settings that cannot work for any input are usage errors, found
/// before the first input.
pub fn run(args: Args) -> Result<i32> {
    // Wrong paths on the command line are usage errors; a shard that cannot be is one
    // whatever the plan.
    if let Some(shard) = args.shard {
        crate::shard::index(shard).map_err(usage)?;
    }
    let pairs = plan::this_run(&args).map_err(usage)?;
    run_pairs(&args, args.options(), &pairs)
}

/// A farm task's batch ([`crate::cmd::farm`]): `pairs` with `options`, reported as `convert
/// --json -u --progress never` reports.
pub(crate) fn run_task(options: Options, pairs: &[(PathBuf, PathBuf)]) -> Result<i32> {
    use clap::FromArgMatches;
    let words = ["task", "--json", "-u", "--progress", "never", "-"];
    let matches = <Args as clap::Args>::augment_args(clap::Command::new("task"))
        .try_get_matches_from(words)?;
    let args = Args::from_arg_matches(&matches)?;
    run_pairs(&args, options, pairs)
}

/// Converts `pairs` with `options`, as `args` asks them reported.
fn run_pairs(args: &Args, options: Options, pairs: &[(PathBuf, PathBuf)]) -> Result<i32> {
    let converter = Converter::new(options).map_err(|e| usage(anyhow::anyhow!(explain(&e))))?;
    if !args.quiet {
        for note in converter.config_notes() {
            errln!(
                "specconv: note: the OCIO config {}: {note}",
                converter.config_source()
            );
        }
        for advice in converter.advice() {
            let fix = match advice {
                Advice::PhotometricHalf => "; use -d float",
                _ => "",
            };
            errln!("specconv: note: {advice}{fix}");
        }
    }
    if args.verbose && !args.quiet {
        errln!("config: {}", converter.config_source());
        errln!("model:  {}", converter.model_description());
    }
    run_batch(args, &converter, pairs)
}

impl Args {
    /// The conversion these options describe.
    pub(crate) fn options(&self) -> Options {
        let mut o = Options::default();
        o.ocio = self.ocio.clone();
        o.colorspace = self.colorspace.clone();
        o.alpha = self.alpha;
        o.subimage = self.read.subimage.clone();
        o.channels = self.read.channels.clone();
        o.method = self.method;
        o.model = self.stack.model.clone();
        o.blend = self.stack.blend.width;
        o.bounded = !self.stack.unbounded;
        o.bands = self.stack.bands;
        o.emission = self.emissive.then_some(self.emission_units);
        o.layout = self.layout;
        o.sample = self.data_type;
        o.rounding = self.half_rounding;
        o.compression = self.compression;
        o.zip_level = self.zip_level;
        o.blocks = if self.scanline {
            Blocks::Scanlines
        } else {
            Blocks::Tiles(self.tile[0], self.tile[1])
        };
        o.mip = self.mip;
        o.filter = self.filter;
        o.resize = self.resize;
        o.wrap = self.wrap;
        if let Some(fix) = self.fixnan {
            o.non_finite = fix;
        }
        o.constant_detect = self.constant_color_detect;
        o.opaque_detect = self.opaque_detect;
        o.threads = self.threads;
        o.overwrite = self.force;
        o.data = self.data;
        o.strip_metadata = self.strip_metadata;
        o.strict = self.strict;
        o
    }
}

/// Converts every input in turn, printing as it goes; returns the exit status. SIGINT and
/// SIGTERM stop the input being converted (its temporary file removed) and the batch; so does
/// a failed write to standard output, after the record of an input that is done.
fn run_batch(args: &Args, converter: &Converter, pairs: &[(PathBuf, PathBuf)]) -> Result<i32> {
    let cancel = Arc::new(AtomicBool::new(false));
    let inputs: Vec<PathBuf> = pairs.iter().map(|(i, _)| i.clone()).collect();
    let mut progress = Progress::new(args.progress, args.quiet, &inputs);
    let mut summary = Summary::default();
    let mut stdout: Option<StdoutFailed> = None;
    // The first failed write stops the batch; later records are not attempted.
    let mut said = |written: Result<(), StdoutFailed>| {
        if let Err(e) = written {
            cancel.store(true, Ordering::SeqCst);
            stdout.get_or_insert(e);
        }
    };
    let batch_start = std::time::Instant::now();
    let batch = Batch::new(converter).update(args.update).cancel_on(&cancel);
    let ended = signals::deferred(&cancel, || {
        batch.run(pairs, &mut |event| match event {
            Event::Started { index, input } => progress.start(index, input),
            Event::Progress { done, total } => progress.update(done, total),
            Event::Skipped { input, output } => {
                progress.skip();
                summary.skipped += 1;
                said(printing::skipped(args, input, output));
            }
            Event::Converted {
                input,
                output,
                report,
            } => {
                progress.finish();
                summary.converted += 1;
                said(converted(args, converter, (input, output), report));
            }
            Event::Data {
                input,
                output,
                report,
            } => {
                progress.finish();
                summary.data.push(report.data);
                said(printing::data(args, (input, output), report));
            }
            Event::Failed {
                input,
                output,
                error,
                seconds,
            } => {
                progress.finish();
                let error = records::without_input(&explain(error), input);
                if !args.json {
                    print_error(&format!("{}: {error}", input.display()));
                }
                summary.failed.push((input.to_path_buf(), error.clone()));
                said(printing::failed(args, (input, output), error, seconds));
            }
            _ => {}
        })
    });
    let ended = match ended {
        Ok(ended) => ended,
        // The plan changed since it was checked (a file appeared): nothing was written.
        Err(e) => {
            print_error(&explain(&e));
            return Ok(exit::USAGE);
        }
    };
    if !args.quiet {
        printing::warnings(&ended.warnings);
    }
    if pairs.len() > 1 && !args.quiet {
        summary.clipped = ended.clipped;
        summary.warnings = ended.warnings.iter().map(|w| w.inputs).collect();
        errln!("{}", summary.text(batch_start.elapsed().as_secs_f64()));
    }
    if let Some(e) = stdout {
        return Err(e.into());
    }
    if ended.cancelled {
        print_error(signals::LINE);
        return Ok(exit::INTERRUPTED);
    }
    // The signal came after the last output was published: it stopped nothing.
    if cancel.load(Ordering::SeqCst) {
        errln!("specconv: the signal came after the last output was completed; it was kept");
    }
    Ok(if summary.failed.is_empty() {
        exit::OK
    } else {
        exit::FAILED
    })
}

impl Args {
    /// `-o DIR`, for `farm submit`.
    pub(crate) fn output_dir(&self) -> Option<&Path> {
        self.output.as_deref()
    }

    pub(crate) fn output_template(&self) -> Option<&str> {
        self.output_template.as_deref()
    }

    pub(crate) fn sharded(&self) -> bool {
        self.shard.is_some()
    }

    pub(crate) fn json_wanted(&self) -> bool {
        self.json
    }

    pub(crate) fn colorspace(&self) -> Option<&str> {
        self.colorspace.as_deref()
    }
}
