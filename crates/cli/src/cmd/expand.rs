//! `specconv expand`: compact textures written out in the spectral layout, a batch as
//! `convert` runs one (the library's plan and [`specconv_conversion::Expansions`]).

use anyhow::Result;
use specconv_conversion::{Event, Expansions, Key};
use specconv_convert_cmd::convert::{ending, paths, printing, BatchArgs};
use specconv_convert_cmd::errors::{explain, print_error, usage};
use specconv_convert_cmd::progress::{Closing, Progress};
use specconv_convert_cmd::stdio::BatchOutput;
use specconv_convert_cmd::{records, signals};
use specconv_flags::defs;
use specconv_flags::{OptionArgs, Taken};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Shown after `--help` and as the man page's EXAMPLES.
pub const EXAMPLES: &str = "\
Examples:
  specconv convert --layout compact albedo.tx albedo_compact.exr
  specconv expand albedo_compact.exr albedo_spectral.exr
  specconv expand compact/*.exr -o spectral -u --json > expand.jsonl
";

specconv_flags::args! {
    /// Write compact textures (`convert --layout compact`) out in the spectral layout.
    ///
    /// Each texel of a compact file holds its colour and the three dual unknowns of the bounded
    /// projection; the header holds the model's maps on the output grid and the decoding rule
    /// (docs/compact.md). Level 0 is decoded by that rule and the smaller levels are filtered from
    /// its spectra, as `convert` filters its own; samples are rounded, compressed and tiled as
    /// `convert` with the compact file's settings would have, and the header keeps its provenance.
    /// The values are `convert`'s, within one half step (the dual unknowns are stored as float32).
    /// Several inputs are expanded in turn, as `convert` converts them: the whole plan is checked
    /// before the first write, and a failed input does not stop the others.
    #[derive(Debug)]
    pub struct Args {
        paths: Vec<PathBuf> = (defs::EXPAND_PATHS),
        output: Option<PathBuf> = (defs::EXPAND_OUTPUT),
        output_template: Option<String> = (defs::EXPAND_OUTPUT_TEMPLATE),
        /// -u, --json, --progress, -q, as `convert` takes them.
        batch: BatchArgs = flatten,
        /// -j, --force, --fixnan, as the library defines them.
        options: OptionArgs<Expanding> = flatten,
    }
}

/// The options of a conversion that `expand` takes: threads, replacing outputs, and NaN
/// texels (by default the rule the compact file's conversion recorded, not `convert`'s).
#[derive(Debug, Clone)]
struct Expanding;

impl Taken for Expanding {
    fn keys() -> Vec<Key> {
        vec![Key::Threads, Key::Overwrite, Key::NonFinite]
    }
    fn own_help(key: Key) -> Option<&'static str> {
        (key == Key::NonFinite).then_some(
            "NaN and infinite texels: refuse, black, box3 or keep, as `convert --fixnan` treats \
             its input's pixels; by default the rule the compact file's conversion recorded",
        )
    }
}

/// Expands every input; returns the exit status, as `convert`'s.
pub fn run(args: Args) -> Result<i32> {
    let whole = paths::of_paths(
        &args.paths,
        args.output.as_deref(),
        args.output_template.as_deref(),
    )
    .map_err(usage)?;
    whole
        .check_existing(args.options.options.overwrite, args.batch.update)
        .map_err(|e| usage(paths::planned(e)))?;
    let pairs = whole.into_pairs();
    let reporting = args.batch.reporting(false);
    let cancel = Arc::new(AtomicBool::new(false));
    let inputs: Vec<PathBuf> = pairs.iter().map(|p| p.input.clone()).collect();
    let mut progress = Progress::new(args.batch.progress, args.batch.quiet, &inputs);
    let mut summary = Closing {
        done: Some("expanded"),
        ..Closing::default()
    };
    let mut stdout = BatchOutput::new(&cancel);
    let batch_start = std::time::Instant::now();
    let mut started = batch_start;
    let options = &args.options;
    let fixnan = options
        .was_given(Key::NonFinite)
        .then_some(options.options.non_finite);
    let expansions = Expansions::new(options.options.overwrite)
        .fixnan(fixnan)
        .update(args.batch.update)
        .threads(options.options.threads)
        .cancel_on(&cancel);
    let ended = signals::deferred(&cancel, || {
        expansions.run(&pairs, &mut |event| match event {
            Event::Started { index, input } => {
                started = std::time::Instant::now();
                progress.start(index, input)
            }
            Event::Skipped { input, output } => {
                progress.skip();
                summary.skipped += 1;
                stdout.said(printing::skipped(&reporting, input, output));
            }
            Event::Expanded {
                input,
                output,
                expanded,
            } => {
                progress.finish();
                summary.converted += 1;
                let seconds = started.elapsed().as_secs_f64();
                stdout.said(printing::expanded(
                    &reporting,
                    (input, output),
                    expanded,
                    seconds,
                ));
            }
            Event::Failed {
                input,
                output,
                error,
                seconds,
            } => {
                progress.finish();
                let error = records::without_input(&explain(error), input);
                if !args.batch.json {
                    print_error(&format!("{}: {error}", input.display()));
                }
                summary.failed.push((input.to_path_buf(), error.clone()));
                stdout.said(printing::failed(
                    &reporting,
                    (input, output),
                    error,
                    seconds,
                ));
            }
            _ => {}
        })
    });
    let seconds = batch_start.elapsed().as_secs_f64();
    ending(
        &reporting,
        ended,
        summary,
        stdout.failed(),
        &cancel,
        (pairs.len(), seconds),
    )
}
