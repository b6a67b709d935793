//! [`Batch`]: many inputs through one [`Converter`], in order, with the up-to-date check,
//! cancellation and progress events that every front-end needs.

use crate::plan::{check_plan, Pair};
use crate::report::{tally, NoticeCount};
use crate::{Converter, Error, Expanded, NonFinite, Report};
use specconv_atomic_file::outputs::Holds;
use std::path::Path;
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
        /// Its output that is up to date (its data copy's, for a data texture).
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
        /// Its data copy's output ([`Pair::output`] for [`Holds::Data`]), written or not.
        output: &'a Path,
        /// What was done.
        report: &'a Report,
    },
    /// A compact texture expanded ([`Expansions`]).
    Expanded {
        /// The input.
        input: &'a Path,
        /// Its output.
        output: &'a Path,
        /// What was written.
        expanded: &'a Expanded,
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
/// use specconv_conversion::plan::Pair;
/// let pairs = vec![Pair::new("a.png", "a_spectral.exr")];
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
    each_input: Option<&'c [&'c Converter]>,
    update: bool,
    cancel: Option<&'c AtomicBool>,
}

impl<'c> Batch<'c> {
    /// A batch that converts every input, refusing existing outputs unless the converter's
    /// options allow replacing them.
    pub fn new(converter: &'c Converter) -> Batch<'c> {
        Batch {
            converter,
            each_input: None,
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

    /// Input `k` is converted by `converters[k]` (an asset's textures, each in the colour
    /// space its material gives: converters that differ only there); the plan checks and the
    /// replacing of outputs follow the batch's converter.
    pub fn each_input(mut self, converters: &'c [&'c Converter]) -> Batch<'c> {
        self.each_input = Some(converters);
        self
    }

    fn converter_of(&self, index: usize) -> &'c Converter {
        self.each_input
            .and_then(|c| c.get(index).copied())
            .unwrap_or(self.converter)
    }

    /// Checks the whole plan before anything is written ([`check_plan`] with the converter's
    /// `overwrite` and this batch's update).
    pub fn check(&self, pairs: &[Pair]) -> Result<(), Error> {
        Ok(check_plan(
            pairs,
            &self.converter.files_read(),
            self.converter.options().overwrite,
            self.update,
        )?)
    }

    /// Converts each input in turn, telling `on` what happens, once the plan is checked
    /// ([`Batch::check`]; its error is returned and nothing is written). A data texture
    /// written through goes to its pair's data name ([`Pair::output`]).
    pub fn run(
        &self,
        pairs: &[Pair],
        on: &mut (dyn FnMut(Event) + Send),
    ) -> Result<Summary, Error> {
        self.check(pairs)?;
        let never = AtomicBool::new(false);
        let cancel = self.cancel.unwrap_or(&never);
        let overwrite = self.converter.options().overwrite || self.update;
        // Either name may hold the up-to-date output: which one the input makes is known once
        // it is read, and the recorded settings tell a stale one.
        let up_to_date = |k: usize, pair: &'_ Pair| -> Option<Holds> {
            if !self.update {
                return None;
            }
            Holds::ALL
                .into_iter()
                .filter(|h| *h == Holds::Spectral || pair.data.is_some())
                .find(|h| {
                    self.converter_of(k)
                        .is_up_to_date(&pair.input, pair.output(*h))
                })
        };
        let run = |k: usize, pair: &Pair, on: &mut (dyn FnMut(Event) + Send)| {
            self.converter_of(k)
                .run(pair, overwrite, cancel, &mut |done, total| {
                    on(Event::Progress { done, total })
                })
        };
        let done = |pair: &Pair,
                    report: Report,
                    on: &mut (dyn FnMut(Event) + Send),
                    summary: &mut Summary| {
            let input = pair.input.as_path();
            tally(&mut summary.warnings, input, &report);
            if report.data.is_some() {
                summary.data += 1;
                on(Event::Data {
                    input,
                    output: pair.output(Holds::Data),
                    report: &report,
                });
            } else {
                summary.converted += 1;
                summary.clipped += usize::from(report.clipped() > 0);
                on(Event::Converted {
                    input,
                    output: &pair.output,
                    report: &report,
                });
            }
        };
        Ok(each(pairs, cancel, up_to_date, run, done, on))
    }
}

/// The loop of every batch: each input in turn, `Started`, then skipped when `up_to_date` names
/// the output that is, else `run` and handed to `done` (which tells `on`), or `Failed`; a cancel
/// stops it between inputs, or inside one (`run` returns the cancelled error: not a failure of
/// that input).
fn each<T>(
    pairs: &[Pair],
    cancel: &AtomicBool,
    up_to_date: impl Fn(usize, &Pair) -> Option<Holds>,
    mut run: impl FnMut(usize, &Pair, &mut (dyn FnMut(Event) + Send)) -> Result<T, Error>,
    mut done: impl FnMut(&Pair, T, &mut (dyn FnMut(Event) + Send), &mut Summary),
    on: &mut (dyn FnMut(Event) + Send),
) -> Summary {
    let mut summary = Summary::default();
    for (index, pair) in pairs.iter().enumerate() {
        let input = pair.input.as_path();
        if cancel.load(Ordering::SeqCst) {
            summary.cancelled = true;
            break;
        }
        on(Event::Started { index, input });
        if let Some(holds) = up_to_date(index, pair) {
            summary.skipped += 1;
            on(Event::Skipped {
                input,
                output: pair.output(holds),
            });
            continue;
        }
        let start = std::time::Instant::now();
        match run(index, pair, on) {
            Ok(t) => done(pair, t, on, &mut summary),
            Err(e) if e.is_cancelled() => {
                summary.cancelled = true;
                break;
            }
            Err(error) => {
                summary.failed += 1;
                on(Event::Failed {
                    input,
                    output: &pair.output,
                    error: &error,
                    seconds: start.elapsed().as_secs_f64(),
                });
            }
        }
    }
    summary
}

/// Compact textures (`--layout compact`) written out in the spectral layout, many in turn, with
/// the plan checks, up-to-date check, cancellation and events of a conversion's [`Batch`]:
/// each input gives `Started`, then `Skipped`, `Expanded` or `Failed`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Expansions<'c> {
    overwrite: bool,
    fixnan: Option<NonFinite>,
    update: bool,
    threads: Option<usize>,
    cancel: Option<&'c AtomicBool>,
}

impl<'c> Expansions<'c> {
    /// Expansions that refuse existing outputs unless `overwrite`.
    pub fn new(overwrite: bool) -> Expansions<'c> {
        Expansions {
            overwrite,
            ..Expansions::default()
        }
    }

    /// Treats NaN and infinite texels by `fixnan`, else by the rule each file's conversion
    /// recorded ([`crate::expand`]).
    pub fn fixnan(self, fixnan: Option<NonFinite>) -> Expansions<'c> {
        Expansions { fixnan, ..self }
    }

    /// Skips inputs whose output is up to date ([`expansion_is_up_to_date`]) and replaces
    /// outputs that specconv made.
    pub fn update(self, update: bool) -> Expansions<'c> {
        Expansions { update, ..self }
    }

    /// Worker threads (default: one per core).
    pub fn threads(self, threads: Option<usize>) -> Expansions<'c> {
        Expansions { threads, ..self }
    }

    /// Stops when `cancel` is set: between inputs, or inside one (its output is not written).
    pub fn cancel_on(self, cancel: &'c AtomicBool) -> Expansions<'c> {
        Expansions {
            cancel: Some(cancel),
            ..self
        }
    }

    /// Expands each input into its output in turn, telling `on` what happens, once the whole plan is
    /// checked ([`check_plan`]; its error is returned and nothing is written).
    pub fn run(
        &self,
        pairs: &[Pair],
        on: &mut (dyn FnMut(Event) + Send),
    ) -> Result<Summary, Error> {
        // An expansion writes its output alone, never a data copy: the data names are no part
        // of its plan.
        let pairs: Vec<Pair> = pairs
            .iter()
            .map(|p| Pair::new(&p.input, &p.output))
            .collect();
        let pairs = &pairs[..];
        check_plan(pairs, &[], self.overwrite, self.update)?;
        if self.threads == Some(0) {
            return Err(Error::NoThreads);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads.unwrap_or(0))
            .build()
            .map_err(|e| Error::Threads(e.to_string()))?;
        let never = AtomicBool::new(false);
        let cancel = self.cancel.unwrap_or(&never);
        let overwrite = self.overwrite || self.update;
        // An expansion writes its output alone: a pair's data name is never its.
        let up_to_date = |_, p: &Pair| {
            (self.update && expansion_is_up_to_date(&p.input, &p.output)).then_some(Holds::Spectral)
        };
        let run = |_, p: &Pair, _: &mut (dyn FnMut(Event) + Send)| {
            pool.install(|| {
                crate::compact::expand(&p.input, &p.output, overwrite, self.fixnan, cancel)
            })
        };
        let done = |p: &Pair,
                    expanded: Expanded,
                    on: &mut (dyn FnMut(Event) + Send),
                    summary: &mut Summary| {
            summary.converted += 1;
            on(Event::Expanded {
                input: &p.input,
                output: &p.output,
                expanded: &expanded,
            });
        };
        Ok(each(pairs, cancel, up_to_date, run, done, on))
    }
}

/// Whether `output` is the expansion of the compact texture `input` as it is now: complete,
/// not older than it, and recording the same source and settings (`layout=spectral` for its
/// `layout=compact`), as an expansion records them.
pub fn expansion_is_up_to_date(input: &Path, output: &Path) -> bool {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    if !matches!((modified(input), modified(output)), (Some(i), Some(o)) if o >= i) {
        return false;
    }
    let (Some(made), Some(from)) = (
        crate::provenance::recorded(output),
        crate::provenance::recorded(input),
    ) else {
        return false;
    };
    specconv_exr::check::check_complete(output).is_ok()
        && made.source == from.source
        && made.settings
            == from
                .settings
                .as_deref()
                .map(specconv_description::as_spectral)
}
