//! `specconv [convert] INPUT… OUTPUT`: the main job.

use crate::progress::{Progress, Summary};
use crate::{checks, exit, files, methods, one_line, print_error, records, usage};
use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use serde::Serialize;
use specconv_exr::{Compression, Kind, Sample};
use specconv_pipeline::{convert, Alpha, Job, Mip, Settings};
use specconv_spectral::bounded::Counts;
use specconv_spectral::emission::Emissive;
use specconv_spectral::method::MethodName;
use specconv_spectral::stack::Stack;
use specconv_spectral::{Method, Model};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv convert albedo.tx albedo_spectral.exr
  specconv convert --colorspace ACEScg -d float plate.exr plate_spectral.exr
  specconv convert textures/*.png -o spectral -u --json > convert.jsonl
  specconv convert sky.hdr sky_spectral.exr --emissive
  find textures -name '*.tx' | specconv convert - -o spectral --progress always 2> convert.log
";

/// `--alpha`, as typed (a value enum keeps [`Args`] small).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum AlphaArg {
    Auto,
    Straight,
    Premultiplied,
}

/// Convert textures to spectral OpenEXR images (the default command).
///
/// Reads each INPUT through OpenImageIO (any format it reads, every MIP level), converts it to
/// CIE XYZ (D65) through OpenColorIO, uplifts every pixel to a reflectance spectrum with the
/// model, and writes a spectral OpenEXR in the layout of Fichet et al. 2021 (`T.380,000000nm`
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
    /// standard input, one per line.
    #[arg(value_name = "INPUT… [OUTPUT]", required = true)]
    paths: Vec<PathBuf>,
    /// Write every output into this directory, as STEM_spectral.exr.
    #[arg(short, long, value_name = "DIR", conflicts_with = "output_template")]
    output: Option<PathBuf>,
    /// Output path for each input; {dir}, {stem} and {name} are the input's directory, name
    /// without extension and file name.
    #[arg(long, value_name = "TEMPLATE")]
    output_template: Option<String>,
    /// The global --ocio (see `specconv --help`).
    #[arg(skip)]
    pub(crate) ocio: Option<String>,
    /// The input's colour space, overriding what the file declares. Without it: the file's
    /// declaration (ICC profile, EXR chromaticities, PNG sRGB/cHRM/gAMA, a colour-space name),
    /// else the config's file rules, else linear Rec.709 for float and sRGB texture for
    /// integer pixels (docs/colour.md).
    #[arg(long, visible_alias = "iscolorspace", value_name = "NAME")]
    colorspace: Option<String>,
    #[command(flatten)]
    read: ReadArgs,
    /// Whether the input's colour is straight (unassociated) or premultiplied by alpha: `auto`
    /// as the file says (PNG straight, OpenEXR premultiplied), or force either for files that
    /// say it wrong (as oiiotool's --no-autopremult). Straight colour is converted, then
    /// premultiplied: OpenEXR stores premultiplied colour.
    #[arg(long, value_name = "HOW", value_enum, default_value_t = AlphaArg::Auto)]
    alpha: AlphaArg,
    /// Uplift method: otsu2018 (the clustered PCA of the model), pca (a one-cluster model),
    /// smits1999, meng2015, meng2015-bounded or jakob2019.
    #[arg(long, value_name = "NAME", default_value = "otsu2018")]
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
        default_value = "reference",
        requires = "emissive"
    )]
    emission_units: specconv_colour::EmissionUnits,
    /// Sample type of the output.
    #[arg(short = 'd', long = "data-type", value_name = "TYPE", default_value = "half", value_parser = ["half", "float"])]
    data_type: String,
    /// How half samples are rounded: `nearest` rounds each band on its own (the colour moves
    /// by up to ≈3e-4 relative, below what half can resolve per band); `colour` picks, band by
    /// band, the half below or above so that the spectrum's XYZ moves as little as possible
    /// (≈5× smaller colour error, ≈1.5× the conversion time of a 36-band ZIP file).
    /// Default: `nearest` for reflectances, `colour` for --emissive, whose dark pixels' S0
    /// values (∫ S0·x̄ dλ = XYZ: ≈1/107 of Y per band) fall where half has few digits.
    #[arg(long, value_name = "HOW", value_parser = ["nearest", "colour"])]
    half_rounding: Option<String>,
    /// Output compression. The lossless ones: none, rle, zips, zip, piz, pxr24 (for half;
    /// float loses 8 bits); b44, b44a, dwaa and dwab lose precision (docs/compression.md
    /// compares them all).
    #[arg(long, default_value = "zip", value_parser = ["none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"])]
    compression: String,
    /// Deflate level of zip and zips, 0 (stored) to 9 (smallest), as OpenEXR's
    /// zipCompressionLevel; the default is the measured best trade (docs/compression.md).
    #[arg(long, value_name = "LEVEL", value_parser = clap::value_parser!(u8).range(0..=9))]
    zip_level: Option<u8>,
    /// Tile width and height of the output.
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [64usize, 64])]
    tile: Vec<usize>,
    /// Write scanlines instead of tiles (no MIP levels).
    #[arg(long, conflicts_with = "tile")]
    scanline: bool,
    /// `all`: every MIP level the input has, each uplifted from its own level; `0`: the full
    /// resolution only.
    #[arg(long, default_value = "all", value_parser = ["all", "0"])]
    mip: String,
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
    /// subimage, channels, bounded, non_finite, above_one, saturated. See docs/json.md.
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

impl ReadArgs {
    pub fn request(&self) -> specconv_pipeline::input::Request {
        specconv_pipeline::input::Request {
            subimage: self.subimage.clone(),
            channels: self.channels.clone(),
        }
    }
}

/// One input's record (`--json`): every key on every record, null where it does not apply
/// (docs/json.md).
#[derive(Serialize)]
struct Record {
    input: PathBuf,
    output: PathBuf,
    /// `ok`, `skipped` or `failed`.
    status: &'static str,
    /// Why a skipped input was skipped.
    skip_reason: Option<&'static str>,
    /// Why a failed input failed, without its path (the record has it).
    error: Option<String>,
    seconds: f64,
    /// Pixels uplifted, over all levels.
    pixels: Option<u64>,
    width: Option<usize>,
    height: Option<usize>,
    levels: Option<usize>,
    bands: Option<usize>,
    /// The input colour space (the config's name) and the rule that chose it.
    colorspace: Option<String>,
    colorspace_rule: Option<&'static str>,
    /// The subimage read, and the colour (then alpha) channels.
    subimage: Option<u32>,
    channels: Option<Vec<String>>,
    /// Pixels (all levels) projected into [0, 1] and outside the object-colour solid; null
    /// with --unbounded or --emissive.
    bounded: Option<BoundedCounts>,
    non_finite: Option<u64>,
    above_one: Option<u64>,
    saturated: Option<u64>,
}

impl Record {
    /// A record of an input that was not converted.
    fn not_converted(input: &Path, output: &Path, status: &'static str, seconds: f64) -> Record {
        Record {
            input: input.to_path_buf(),
            output: output.to_path_buf(),
            status,
            skip_reason: None,
            error: None,
            seconds,
            pixels: None,
            width: None,
            height: None,
            levels: None,
            bands: None,
            colorspace: None,
            colorspace_rule: None,
            subimage: None,
            channels: None,
            bounded: None,
            non_finite: None,
            above_one: None,
            saturated: None,
        }
    }
}

#[derive(Serialize)]
struct BoundedCounts {
    projected: usize,
    outside_solid: usize,
}

/// Runs the conversion of every input; returns the exit status ([`exit`]: all done, any
/// failed, interrupted). Settings that cannot work for any input are usage errors, found
/// before the first input.
pub fn run(args: Args) -> Result<i32> {
    if args.zip_level.is_some() && !matches!(args.compression.as_str(), "zip" | "zips") {
        return Err(usage(anyhow::anyhow!(
            "--zip-level sets the deflate level of zip and zips; --compression {} has none (drop --zip-level or use --compression zip)",
            args.compression
        )));
    }
    // Wrong paths on the command line are usage errors.
    let (inputs, outputs) = plan(&args)
        .and_then(|(i, o)| match args.shard {
            Some(shard) => crate::shard::shard_of(shard, i, o),
            None => Ok((i, o)),
        })
        .map_err(usage)?;
    if args.tile.contains(&0) {
        return Err(usage(anyhow::anyhow!(
            "--tile {} {}: tiles must be at least 1×1",
            args.tile[0],
            args.tile[1]
        )));
    }
    if let Some(n) = args.threads {
        if n == 0 {
            return Err(usage(anyhow::anyhow!("-j/--threads must be at least 1")));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot start worker threads")?;
    }
    let config = checks::config(args.ocio.as_deref())?;
    checks::input_colorspace(&config, args.colorspace.as_deref())?;
    let model = files::load_model(args.stack.model.as_deref())?;
    let stack = methods::build(&args.description(), &model).map_err(usage)?;
    let described = files::describe_model(args.stack.model.as_deref(), &model);
    let tag = settings_tag(&args, &described, &stack, &config.source().to_string());
    let settings = settings(&args, &model, &described, &stack, &tag);
    if args.emissive
        && args.emission_units == specconv_colour::EmissionUnits::Photometric
        && args.data_type == "half"
        && !args.quiet
    {
        // Y = 683·∫ S0·ȳ dλ: S0 ≈ Y/73000 per band, below half's normal range (6.1e-5) for
        // scenes under ≈4 cd/m², and few digits left far above.
        eprintln!(
            "specconv: note: photometric S0 of scenes below a few cd/m² falls below what half \
             resolves; use -d float"
        );
    }
    if args.verbose && !args.quiet {
        eprintln!("config: {}", config.source());
        eprintln!("model:  {described}");
    }
    let batch = Batch {
        args: &args,
        config: &config,
        stack: &stack,
        settings: &settings,
        tag: &tag,
    };
    Ok(batch.run(&inputs, &outputs))
}

impl Args {
    /// The method stack these options describe.
    pub(crate) fn description(&self) -> specconv_spectral::stack::Description {
        specconv_spectral::stack::Description {
            emissive: self.emissive.then_some(self.emission_units),
            ..self.stack.describe(self.method)
        }
    }
}

/// `specconvSettings`: everything that makes an output what it is, for `--update`.
fn settings_tag(args: &Args, model: &str, stack: &Stack, config: &str) -> String {
    format!(
        "model={} method={} blend={} data-type={} compression={} tile={} mip={} colorspace={} alpha={} config={}{}",
        model,
        stack.method().name(),
        stack.blend(),
        args.data_type,
        match args.zip_level {
            Some(level) => format!("{} zip-level={level}", args.compression),
            None => args.compression.clone(),
        },
        if args.scanline {
            "scanline".to_string()
        } else {
            format!("{}x{}", args.tile[0], args.tile[1])
        },
        args.mip,
        args.colorspace.as_deref().unwrap_or("auto"),
        args.alpha.to_possible_value().expect("no value is skipped").get_name(),
        config,
        stack
            .emission()
            .map_or(String::new(), |e| format!(" emission-units={}", e.units))
    ) + &[("subimage", &args.read.subimage), ("channels", &args.read.channels)]
        .iter()
        .filter_map(|(k, v)| v.as_ref().map(|v| format!(" {k}={v}")))
        .collect::<String>()
}

/// The pipeline's settings of every output.
fn settings(args: &Args, model: &Model, described: &str, stack: &Stack, tag: &str) -> Settings {
    let rounding = args.half_rounding.as_deref();
    let by_colour =
        rounding.unwrap_or(if args.emissive { "colour" } else { "nearest" }) != "nearest";
    Settings {
        kind: if args.emissive {
            Kind::Emissive {
                units: EMISSIVE_UNITS.into(),
            }
        } else {
            Kind::Reflective
        },
        xyz_weights: by_colour.then(|| match stack.emission() {
            Some(e) => e.emission.weights.clone(),
            None => stack.colorimetry().weights.clone(),
        }),
        colorspace: args.colorspace.clone(),
        input: args.read.request(),
        alpha: match args.alpha {
            AlphaArg::Auto => Alpha::Auto,
            AlphaArg::Straight => Alpha::Straight,
            AlphaArg::Premultiplied => Alpha::Premultiplied,
        },
        sample: if args.data_type == "float" {
            Sample::Float
        } else {
            Sample::Half
        },
        compression: compression(&args.compression),
        zip_level: args.zip_level.unwrap_or(specconv_exr::zip::DEFAULT_LEVEL),
        tile: (!args.scanline).then(|| (args.tile[0], args.tile[1])),
        mip: if args.mip == "0" { Mip::Base } else { Mip::All },
        overwrite: args.force || args.update,
        attributes: [
            ("specconvModel", described.to_string()),
            ("specconvMethod", stack.method().name().into()),
            ("specconvBlend", stack.blend().to_string()),
            ("specconvObserver", model.observer.to_string()),
            ("specconvIlluminant", model.illuminant.to_string()),
            ("specconvSettings", tag.to_string()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .chain(
            stack
                .emission()
                .map(|e| (files::EMISSION_UNITS_ATTRIBUTE.into(), e.units.to_string())),
        )
        .chain([("specconvVersion".into(), env!("CARGO_PKG_VERSION").into())])
        .collect(),
    }
}

/// One run's inputs share these.
struct Batch<'a> {
    args: &'a Args,
    config: &'a specconv_ocio::Config,
    stack: &'a Stack,
    settings: &'a Settings,
    tag: &'a str,
}

impl Batch<'_> {
    /// Converts every input in turn; returns the exit status.
    fn run(&self, inputs: &[PathBuf], outputs: &[PathBuf]) -> i32 {
        let args = self.args;
        let cancel = Arc::new(AtomicBool::new(false));
        {
            let cancel = cancel.clone();
            // SIGINT and SIGTERM stop the job between windows; its temporary file is removed.
            let _ = ctrlc::set_handler(move || cancel.store(true, Ordering::SeqCst));
        }
        let mut progress = Progress::new(args.progress, args.quiet, inputs);
        let mut summary = Summary::default();
        let batch_start = Instant::now();
        for (i, (input, output)) in inputs.iter().zip(outputs).enumerate() {
            if cancel.load(Ordering::SeqCst) {
                break;
            }
            progress.start(i, input);
            if args.update && up_to_date(input, output, self.tag) {
                progress.skip();
                summary.skipped += 1;
                let record = Record {
                    skip_reason: Some("up to date"),
                    ..Record::not_converted(input, output, "skipped", 0.0)
                };
                emit(args, record, "");
                continue;
            }
            let start = Instant::now();
            let job = Job {
                input,
                output,
                config: self.config,
                method: self.stack.method(),
                settings: self.settings,
                cancel: &cancel,
            };
            let result = convert(&job, &mut |done, total| progress.update(done, total));
            progress.finish();
            let seconds = start.elapsed().as_secs_f64();
            // Taken after every input, so that a failed one's count is not the next one's.
            let counts = self.stack.take_counts();
            match result {
                Ok(r) => {
                    summary.converted += 1;
                    self.converted((input, output), &r, counts, seconds);
                }
                // Interrupted: not a failure of this input, which stays to be converted.
                Err(specconv_pipeline::Error::Cancelled) => break,
                Err(e) => {
                    let error = records::without_input(&one_line(&e.into()), input);
                    if !args.json {
                        print_error(&format!("{}: {error}", input.display()));
                    }
                    summary.failed.push((input.clone(), error.clone()));
                    let record = Record {
                        error: Some(error),
                        ..Record::not_converted(input, output, "failed", seconds)
                    };
                    emit(args, record, "");
                }
            }
        }
        if inputs.len() > 1 && !args.quiet {
            eprintln!("{}", summary.text(batch_start.elapsed().as_secs_f64()));
        }
        if cancel.load(Ordering::SeqCst) {
            print_error("interrupted; no partial output was left");
            return exit::INTERRUPTED;
        }
        if summary.failed.is_empty() {
            exit::OK
        } else {
            exit::FAILED
        }
    }

    /// Reports a converted input: its warnings, its record or line.
    fn converted(
        &self,
        (input, output): (&Path, &Path),
        r: &specconv_pipeline::Report,
        counts: Option<Counts>,
        seconds: f64,
    ) {
        let (args, method) = (self.args, self.stack.method());
        if !args.quiet {
            for w in &r.warnings {
                eprintln!("specconv: warning: {}: {w}", input.display());
            }
        }
        let bands = method.grid().len();
        let line = summary_line(r, bands, seconds)
            + &counts.map_or(String::new(), |c| {
                format!(
                    ", {} pixels projected into [0, 1], {} outside the object-colour solid \
                     (nearest colour in CIELAB)",
                    c.projected, c.outside
                )
            })
            + &range_notes(r, method, self.stack.emissive());
        let record = Record {
            pixels: Some(r.pixels),
            width: Some(r.width),
            height: Some(r.height),
            levels: Some(r.levels),
            bands: Some(bands),
            colorspace: Some(r.colorspace.clone()),
            colorspace_rule: Some(records::colorspace_rule(&r.colorspace_rule)),
            subimage: Some(r.selection.subimage),
            channels: Some(r.selection.channels.names.clone()),
            bounded: counts.map(|c| BoundedCounts {
                projected: c.projected,
                outside_solid: c.outside,
            }),
            non_finite: Some(r.non_finite),
            above_one: Some(r.above_one),
            saturated: Some(r.saturated),
            ..Record::not_converted(input, output, "ok", seconds)
        };
        emit(args, record, &line);
    }
}

/// `W×H, L levels, N bands, colour space …, …, S s` of a converted input.
fn summary_line(r: &specconv_pipeline::Report, bands: usize, seconds: f64) -> String {
    let plural = if r.levels == 1 { "" } else { "s" };
    let mut line = format!(
        "{}×{}, {} level{plural}, {bands} bands, colour space {} ({}), {}",
        r.width, r.height, r.levels, r.colorspace, r.colorspace_rule, r.selection,
    );
    if r.premultiplied {
        line += ", straight alpha premultiplied";
    }
    if r.non_finite > 0 {
        line += &format!(", {} pixels NaN or infinite (written as NaN)", r.non_finite);
    }
    line + &format!(", {seconds:.2} s")
}

/// Units of `S0.` channels: radiance, as the layout names it; the scale is the convention of
/// `specconvEmissionUnits`.
const EMISSIVE_UNITS: &str = "W.m^-2.sr^-1";

/// The summary's notes on values out of range: pixels above 1 in reflectance mode (and the
/// --emissive hint when they are at least 1 % of the image), emission colours no spectrum of
/// the method matched, values saturated at the half range.
fn range_notes(
    r: &specconv_pipeline::Report,
    method: &dyn Method,
    emissive: Option<&Emissive<Box<dyn Method>>>,
) -> String {
    let mut notes = String::new();
    match emissive {
        Some(e) => {
            let unmatched = e.take_unmatched();
            if unmatched > 0 {
                notes += &format!(
                    ", {unmatched} pixels no emission of {} matches (outside the spectral locus or \
                     negative luminance: written with the nearest colour it reached)",
                    e.inner().name()
                );
            }
        }
        None if r.above_one > 0 => {
            let what = if method.name().contains("bounded") {
                "moved to the closest colour a reflectance can have"
            } else {
                "spectra above 1, not physical reflectances"
            };
            notes += &format!(", {} pixels above 1 ({what})", r.above_one);
            if r.above_one * 100 >= r.pixels {
                notes += "; an emission or HDR texture? convert it with --emissive";
            }
        }
        None => {}
    }
    if r.saturated > 0 {
        notes += &format!(
            ", {} pixels beyond the half range (stored as ±65504; use -d float)",
            r.saturated
        );
    }
    notes
}

fn emit(args: &Args, record: Record, line: &str) {
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&record).expect("a record serialises")
        );
    } else if !args.quiet && record.status != "failed" {
        eprintln!(
            "{} → {}: {}{line}",
            record.input.display(),
            record.output.display(),
            record
                .skip_reason
                .map_or(String::new(), |r| format!("skipped, {r}"))
        );
    }
}

impl Args {
    /// `-o DIR`, for `farm submit`.
    pub(crate) fn output_dir(&self) -> Option<&Path> {
        self.output.as_deref()
    }

    pub(crate) fn has_output_template(&self) -> bool {
        self.output_template.is_some()
    }

    pub(crate) fn json_wanted(&self) -> bool {
        self.json
    }

    pub(crate) fn colorspace(&self) -> Option<&str> {
        self.colorspace.as_deref()
    }
}

/// Inputs and their outputs, from the positional paths, `-o DIR` or `--output-template`.
pub(crate) fn plan(args: &Args) -> Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    let mut paths = args.paths.clone();
    let single = args.output.is_none() && args.output_template.is_none();
    let explicit_output = if single {
        if paths.len() != 2 {
            bail!(
                "give INPUT OUTPUT, or several inputs with -o DIR or --output-template (got {} path{})",
                paths.len(),
                if paths.len() == 1 { "" } else { "s" }
            );
        }
        paths.pop()
    } else {
        None
    };
    let mut inputs = Vec::new();
    for p in paths {
        if p.as_os_str() == "-" {
            for line in std::io::stdin().lock().lines() {
                let line = line.context("cannot read input paths from standard input")?;
                if !line.trim().is_empty() {
                    inputs.push(PathBuf::from(line.trim_end()));
                }
            }
        } else {
            inputs.push(p);
        }
    }
    let outputs: Vec<PathBuf> = match (&explicit_output, &args.output, &args.output_template) {
        (Some(o), _, _) => vec![o.clone()],
        (None, Some(dir), _) => {
            checks::directory(dir)?;
            inputs
                .iter()
                .map(|i| dir.join(format!("{}_spectral.exr", stem(i))))
                .collect()
        }
        (None, None, Some(t)) => inputs
            .iter()
            .map(|i| {
                let dir = i
                    .parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .unwrap_or(Path::new("."));
                PathBuf::from(
                    t.replace("{dir}", &dir.display().to_string())
                        .replace("{stem}", &stem(i))
                        .replace(
                            "{name}",
                            &i.file_name()
                                .map(|n| n.to_string_lossy().into_owned())
                                .unwrap_or_default(),
                        ),
                )
            })
            .collect(),
        (None, None, None) => unreachable!("single conversions have an explicit output"),
    };
    let mut seen = std::collections::HashSet::new();
    for o in &outputs {
        files::check_output(o, &["exr"], "specconv writes spectral OpenEXR")?;
        if !seen.insert(o.clone()) {
            bail!("two inputs would both be written to {}; use a template with {{dir}} or rename them", o.display());
        }
        checks::output_dir(o)?;
    }
    Ok((inputs, outputs))
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "output".into(), |s| s.to_string_lossy().into_owned())
}

fn compression(name: &str) -> Compression {
    match name {
        "none" => Compression::Uncompressed,
        "rle" => Compression::RLE,
        "zips" => Compression::ZIP1,
        "piz" => Compression::PIZ,
        "pxr24" => Compression::PXR24,
        "b44" => Compression::B44,
        "b44a" => Compression::B44A,
        "dwaa" => Compression::DWAA(None),
        "dwab" => Compression::DWAB(None),
        _ => Compression::ZIP16,
    }
}

/// An output newer than its input, written with the same settings (as `maketx -u`).
fn up_to_date(input: &Path, output: &Path, settings: &str) -> bool {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    match (modified(input), modified(output)) {
        (Some(i), Some(o)) if o >= i => specconv_exr::read_attributes(output)
            .map(|attrs| {
                attrs
                    .iter()
                    .any(|(k, v)| k == "specconvSettings" && v == settings)
            })
            .unwrap_or(false),
        _ => false,
    }
}
