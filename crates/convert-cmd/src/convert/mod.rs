//! `specconv [convert] INPUT… OUTPUT`: the main job.

pub mod paths;
pub mod printing;

pub use paths::for_farm;
use printing::converted;

use crate::errors::{explain, print_error, usage};
use crate::progress::{Closing, Progress};
use crate::stdio::{BatchOutput, StdoutFailed};
use crate::{exit, records, signals};
use anyhow::Result;
use specconv_conversion::plan::Pair;
use specconv_conversion::{Advice, Batch, Converter, Event, Options};
use specconv_flags::defs;
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

specconv_flags::args! {
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
    #[derive(Debug)]
    pub struct Args {
        paths: Vec<PathBuf> = (defs::CONVERT_PATHS),
        output: Option<PathBuf> = (defs::CONVERT_OUTPUT),
        output_template: Option<String> = (defs::CONVERT_OUTPUT_TEMPLATE),
        /// The global --ocio (see `specconv --help`).
        pub ocio: Option<String> = skip,
        /// The options of the conversion, made from the library's definitions.
        pub conversion: specconv_flags::ConversionArgs = flatten,
        /// -u, --json, --progress, -q.
        pub batch: BatchArgs = flatten,
        shard: Option<specconv_farm::Shard> = (defs::CONVERT_SHARD),
        verbose: bool = (defs::CONVERT_VERBOSE),
    }
}

specconv_flags::args! {
    /// The flags every batch command (`convert`, `expand`, `asset`) takes, written once: what a
    /// batch skips and how it reports.
    #[derive(Debug, Clone)]
    pub struct BatchArgs {
        pub update: bool = (defs::BATCH_UPDATE),
        pub json: bool = (defs::BATCH_JSON),
        pub progress: crate::progress::When = (defs::BATCH_PROGRESS),
        pub quiet: bool = (defs::BATCH_QUIET),
    }
}

impl BatchArgs {
    /// How a batch run with these flags reports; `verbose`: the command's `-v`.
    pub fn reporting(&self, verbose: bool) -> Reporting {
        Reporting {
            json: self.json,
            update: self.update,
            progress: self.progress,
            quiet: self.quiet,
            verbose,
            annotate: None,
        }
    }
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
    let pairs = paths::this_run(&args).map_err(usage)?;
    run_pairs(&args.reporting(), args.options(), &pairs)
}

/// A farm task's batch (`specconv farm task`, in specconv-farm-cmd): `pairs` with `options`,
/// reported as `convert --json -u --progress never` reports; input k in colour space
/// `spaces[k]` where the manifest carries one (a stage's textures, as `asset` converts them).
pub fn run_task(options: Options, pairs: &[Pair], spaces: &[Option<&str>]) -> Result<i32> {
    let reporting = Reporting {
        json: true,
        update: true,
        progress: crate::progress::When::Never,
        quiet: false,
        verbose: false,
        annotate: None,
    };
    if spaces.iter().all(Option::is_none) {
        return run_pairs(&reporting, options, pairs);
    }
    let converters = specconv_asset::Converters::of_spaces(&options, spaces.iter().copied())
        .map_err(|e| usage(anyhow::anyhow!(explain(&e))))?;
    let each = converters.each();
    run_batch(&reporting, (converters.first(), Some(&each)), pairs)
}

/// How a batch is reported and what it skips: `convert`'s own flags, or a farm task's.
#[derive(Clone)]
pub struct Reporting {
    /// `--json`: a record per input on standard output.
    pub json: bool,
    /// `-u`: skip outputs that are up to date.
    pub update: bool,
    /// `--progress`.
    pub progress: crate::progress::When,
    /// `-q`: nothing but errors.
    pub quiet: bool,
    /// `-v`: the config and the model too.
    pub verbose: bool,
    /// More keys for an input's JSON record (`asset`'s: the prims and inputs that read it),
    /// told every record.
    pub annotate: Option<Annotate>,
}

/// What `asset` adds to a record: a JSON object's members (`"asset": {…}`), or none.
pub type Annotate =
    std::sync::Arc<dyn Fn(&specconv_conversion::record::Record) -> Option<String> + Send + Sync>;

/// Converts `pairs` with `options`, reported as `args` asks.
fn run_pairs(args: &Reporting, options: Options, pairs: &[Pair]) -> Result<i32> {
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
    run_batch(args, (&converter, None), pairs)
}

impl Args {
    /// How this run reports.
    fn reporting(&self) -> Reporting {
        self.batch.reporting(self.verbose)
    }

    /// The conversion these options describe.
    pub fn options(&self) -> Options {
        let mut o = self.conversion.options.clone();
        o.ocio = self.ocio.clone();
        o
    }
}

/// Converts every input in turn, printing as it goes; returns the exit status. SIGINT and
/// SIGTERM stop the input being converted (its temporary file removed) and the batch; so does
/// a failed write to standard output, after the record of an input that is done.
/// `each_input`, when given, converts input k with its converter k ([`Batch::each_input`]).
pub fn run_batch(
    args: &Reporting,
    (converter, each_input): (&Converter, Option<&[&Converter]>),
    pairs: &[Pair],
) -> Result<i32> {
    let cancel = Arc::new(AtomicBool::new(false));
    let inputs: Vec<PathBuf> = pairs.iter().map(|p| p.input.clone()).collect();
    let mut progress = Progress::new(args.progress, args.quiet, &inputs);
    let mut summary = Closing::default();
    let mut stdout = BatchOutput::new(&cancel);
    let batch_start = std::time::Instant::now();
    let mut batch = Batch::new(converter).update(args.update).cancel_on(&cancel);
    if let Some(each) = each_input {
        batch = batch.each_input(each);
    }
    let ended = signals::deferred(&cancel, || {
        batch.run(pairs, &mut |event| match event {
            Event::Started { index, input } => progress.start(index, input),
            Event::Progress { done, total } => progress.update(done, total),
            Event::Skipped { input, output } => {
                progress.skip();
                summary.skipped += 1;
                stdout.said(printing::skipped(args, input, output));
            }
            Event::Converted {
                input,
                output,
                report,
            } => {
                progress.finish();
                summary.converted += 1;
                stdout.said(converted(args, converter, (input, output), report));
            }
            Event::Data {
                input,
                output,
                report,
            } => {
                progress.finish();
                summary
                    .data
                    .push(crate::progress::DataTextureLine::of(input, report));
                stdout.said(printing::data(args, (input, output), report));
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
                stdout.said(printing::failed(args, (input, output), error, seconds));
            }
            _ => {}
        })
    });
    let seconds = batch_start.elapsed().as_secs_f64();
    ending(
        args,
        ended,
        summary,
        stdout.failed(),
        &cancel,
        (pairs.len(), seconds),
    )
}

/// How a batch ended, said as every batch command says it (the warnings, the summary line,
/// the interrupt, the failed output), and its exit status; `batch` is the inputs and the
/// seconds it took.
pub fn ending(
    args: &Reporting,
    ended: Result<specconv_conversion::Summary, specconv_conversion::Error>,
    mut summary: Closing,
    stdout: Option<StdoutFailed>,
    cancel: &AtomicBool,
    (inputs, seconds): (usize, f64),
) -> Result<i32> {
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
    if inputs > 1 && !args.quiet {
        summary.clipped = ended.clipped;
        summary.warnings = ended.warnings.iter().map(|w| w.inputs).collect();
        errln!("{}", summary.text(seconds));
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
    pub fn output_dir(&self) -> Option<&Path> {
        self.output.as_deref()
    }

    pub fn output_template(&self) -> Option<&str> {
        self.output_template.as_deref()
    }

    /// The inputs as given (`farm submit` looks for a stage among them).
    pub fn inputs(&self) -> &[PathBuf] {
        &self.paths
    }

    /// `-u`.
    pub fn updating(&self) -> bool {
        self.batch.update
    }

    pub fn sharded(&self) -> bool {
        self.shard.is_some()
    }

    pub fn json_wanted(&self) -> bool {
        self.batch.json
    }

    pub fn colorspace(&self) -> Option<&str> {
        self.conversion.options.colorspace.as_deref()
    }
}
