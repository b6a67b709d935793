//! [`Batch`]: many inputs through one [`Converter`], in order, with the up-to-date check,
//! cancellation and progress events that every front-end needs.

use crate::plan::check_plan;
use crate::report::{tally, NoticeCount};
use crate::{Converter, Error, Report};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// What a batch says as it goes. Every input gets `Started` and then exactly one of
/// `Skipped`, `Converted`, `Data` or `Failed`, unless the batch is cancelled during it.
#[derive(Debug)]
#[non_exhaustive]
pub enum Event<'a> {
    /// Input `index` is next.
    Started {
        /// Its position in the batch.
        index: usize,
        /// The input.
        input: &'a Path,
    },
    /// Pixels done and pixels in all of the current input.
    Progress {
        /// Pixels uplifted so far.
        done: u64,
        /// Pixels in all.
        total: u64,
    },
    /// The output is up to date.
    Skipped {
        /// The input.
        input: &'a Path,
        /// Its output.
        output: &'a Path,
    },
    /// Converted.
    Converted {
        /// The input.
        input: &'a Path,
        /// Its output.
        output: &'a Path,
        /// What the conversion did.
        report: &'a Report,
    },
    /// A data texture (a roughness or normal map): never uplifted, skipped or written through
    /// by the converter's data policy (`report.data` says which). Not a failure.
    Data {
        /// The input.
        input: &'a Path,
        /// Its output.
        output: &'a Path,
        /// What was done.
        report: &'a Report,
    },
    /// Failed; the batch goes on with the next input.
    Failed {
        /// The input.
        input: &'a Path,
        /// Its output.
        output: &'a Path,
        /// Why.
        error: &'a Error,
        /// Seconds spent on it.
        seconds: f64,
    },
}

/// How a batch ended.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Summary {
    /// Inputs converted.
    pub converted: usize,
    /// Inputs skipped, up to date.
    pub skipped: usize,
    /// Inputs that failed.
    pub failed: usize,
    /// Data textures, skipped or written through.
    pub data: usize,
    /// Of those converted, inputs with pixels clipped ([`Report::clipped`]).
    pub clipped: usize,
    /// Each kind of warning once, with the inputs that had it ([`Report::notices`]).
    pub warnings: Vec<NoticeCount>,
    /// The batch was cancelled before its end; the input it was on was left as it was. The
    /// decision is taken where each output is published: a cancel that comes after the last
    /// one was published stopped nothing, and is not reported here.
    pub cancelled: bool,
}

/// Inputs and their outputs through one converter.
///
/// ```no_run
/// use specconv_conversion::{Batch, Converter, Event, Options};
/// let converter = Converter::new(Options::default())?;
/// let pairs = vec![("a.png".into(), "a_spectral.exr".into())];
/// let summary = Batch::new(&converter).update(true).run(&pairs, &mut |event| {
///     if let Event::Failed { input, error, .. } = event {
///         eprintln!("{}: {error}", input.display());
///     }
/// })?;
/// assert!(!summary.cancelled);
/// # Ok::<(), specconv_conversion::Error>(())
/// ```
pub struct Batch<'c> {
    converter: &'c Converter,
    update: bool,
    cancel: Option<&'c AtomicBool>,
}

impl<'c> Batch<'c> {
    /// A batch that converts every input, refusing existing outputs unless the converter's
    /// options allow replacing them.
    pub fn new(converter: &'c Converter) -> Batch<'c> {
        Batch {
            converter,
            update: false,
            cancel: None,
        }
    }

    /// Skips inputs whose output is up to date ([`Converter::is_up_to_date`]) and replaces
    /// outputs that specconv made and are out of date; any other existing file at an output's
    /// path still needs the converter's `overwrite`.
    pub fn update(mut self, update: bool) -> Batch<'c> {
        self.update = update;
        self
    }

    /// Stops when `cancel` is set: between inputs, or inside one between windows (its output
    /// is not written).
    pub fn cancel_on(mut self, cancel: &'c AtomicBool) -> Batch<'c> {
        self.cancel = Some(cancel);
        self
    }

    /// Checks the whole plan before anything is written ([`check_plan`] with the converter's
    /// `overwrite` and this batch's update).
    pub fn check(&self, pairs: &[(PathBuf, PathBuf)]) -> Result<(), Error> {
        Ok(check_plan(
            pairs,
            self.converter.options().overwrite,
            self.update,
        )?)
    }

    /// Converts each (input, output) in turn, telling `on` what happens, once the plan is
    /// checked ([`Batch::check`]; its error is returned and nothing is written).
    pub fn run(
        &self,
        pairs: &[(PathBuf, PathBuf)],
        on: &mut (dyn FnMut(Event) + Send),
    ) -> Result<Summary, Error> {
        self.check(pairs)?;
        let never = AtomicBool::new(false);
        let cancel = self.cancel.unwrap_or(&never);
        let overwrite = self.converter.options().overwrite || self.update;
        let mut summary = Summary::default();
        for (index, (input, output)) in pairs.iter().enumerate() {
            if cancel.load(Ordering::SeqCst) {
                summary.cancelled = true;
                break;
            }
            on(Event::Started { index, input });
            if self.update && self.converter.is_up_to_date(input, output) {
                summary.skipped += 1;
                on(Event::Skipped { input, output });
                continue;
            }
            let start = std::time::Instant::now();
            let result =
                self.converter
                    .run(input, output, overwrite, cancel, &mut |done, total| {
                        on(Event::Progress { done, total })
                    });
            if let Ok(report) = &result {
                tally(&mut summary.warnings, input, report);
            }
            match result {
                Ok(report) if report.data.is_some() => {
                    summary.data += 1;
                    on(Event::Data {
                        input,
                        output,
                        report: &report,
                    });
                }
                Ok(report) => {
                    summary.converted += 1;
                    summary.clipped += usize::from(report.clipped() > 0);
                    on(Event::Converted {
                        input,
                        output,
                        report: &report,
                    });
                }
                // Interrupted: not a failure of this input, which stays to be converted.
                Err(e) if e.is_cancelled() => {
                    summary.cancelled = true;
                    break;
                }
                Err(error) => {
                    summary.failed += 1;
                    on(Event::Failed {
                        input,
                        output,
                        error: &error,
                        seconds: start.elapsed().as_secs_f64(),
                    });
                }
            }
        }
        Ok(summary)
    }
}
