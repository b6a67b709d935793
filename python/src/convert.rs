//! `specconv.convert`: the command line's conversion, by [`specconv_conversion::Batch`], with
//! Ctrl-C heard while the GIL is released and progress told to a Python callback.

use crate::args::{whole, FsPath};
use crate::errors::{conversion, Kind};
use crate::model::Model;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use specconv_conversion::plan::Pair;
use specconv_conversion::record::{without_input, Record};
use specconv_conversion::{Batch, Converter, Event, Key, Options, Value};
use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

/// What the batch's thread tells the caller's.
enum Said {
    Started(usize, PathBuf),
    Progress(u64, u64),
    /// A record (JSON), with its input and status.
    Record(String, PathBuf, &'static str),
    Failed(Kind, String),
}

/// What a front-end adds to each record (`convert_asset`'s `asset` member): given the input,
/// the status and the record, the record to return.
pub(crate) type Annotate<'a> = &'a mut dyn FnMut(&std::path::Path, &'static str, String) -> String;

/// Inputs or outputs: one path or a sequence of them.
pub enum Paths {
    One(PathBuf),
    Many(Vec<PathBuf>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Paths {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(one) = ob.extract::<FsPath>() {
            return Ok(Paths::One(one.0));
        }
        let not_paths = || Kind::Option.err("give a path or a sequence of paths");
        ob.try_iter()
            .map_err(|_| not_paths())?
            .map(|p| Ok(p?.extract::<FsPath>()?.0))
            .collect::<PyResult<Vec<_>>>()
            .map(Paths::Many)
    }
}

impl Paths {
    fn list(self) -> Vec<PathBuf> {
        match self {
            Paths::One(p) => vec![p],
            Paths::Many(v) => v,
        }
    }
}

/// The model option: a built-in name or file, or a `Model` that has one.
#[derive(FromPyObject)]
pub enum ModelArg<'py> {
    Object(Bound<'py, Model>),
    Path(FsPath),
}

/// The keyword `keyword`'s choice by the library's names ([`specconv_conversion::Named`]), with the library's
/// message, naming the keyword, when it is none.
pub(crate) fn pick<T: specconv_conversion::Named>(keyword: &str, text: &str) -> PyResult<T> {
    T::from_name(text).map_err(|e| Kind::Option.err(format!("{keyword}: {e}")))
}

/// The options of a conversion as the library defines them, one dict each: `name` (the keyword
/// of `convert`), `default` (its text, `None` when unset), `choices` and `aliases` (a choice's
/// names and other spellings, else `None`), `help`, and `changes_output`. `convert`'s keywords,
/// defaults and stubs are checked against it (python/tests/test_options.py).
#[pyfunction]
pub fn options(py: Python<'_>) -> PyResult<Vec<Bound<'_, pyo3::types::PyDict>>> {
    let defaults = Options::default();
    Key::ALL
        .into_iter()
        .map(|key| {
            let about = key.about();
            let d = pyo3::types::PyDict::new(py);
            d.set_item("name", about.name)?;
            d.set_item("default", defaults.text(key))?;
            d.set_item("choices", about.choices.as_ref().map(|c| c.0.clone()))?;
            d.set_item("aliases", about.choices.as_ref().map(|c| c.1.clone()))?;
            d.set_item("help", about.help)?;
            d.set_item("changes_output", about.changes_output)?;
            Ok(d)
        })
        .collect()
}

/// Converts `inputs` (a path or a list; a UDIM pattern such as `wood.<UDIM>.png` stands for
/// its tiles) to spectral OpenEXR files, as `specconv convert` does with the same options,
/// byte for byte. `outputs`: a file (one input), a list of files (one per input; a pattern's
/// names its tiles with the token too), or an existing directory (`DIR/STEM_spectral.exr`); or
/// instead `output_template` (`{dir}`, `{stem}`, `{name}`, `{ext}`, `{udim}`, `{tile}`, `{role}`). Returns one record per
/// input, as `convert --json` prints them (docs/json.md). `errors="raise"` stops at the first
/// failed input and raises its exception (earlier outputs stay); `"record"` carries on and
/// records it. `progress(index, input, pixels_done, pixels_total)` is called as it goes.
/// Ctrl-C stops it, leaving no partial output, and raises `KeyboardInterrupt`. The options of
/// the conversion are keywords, one per option of `specconv.options()` (the stub lists them
/// with their defaults); None leaves an option unset where it can be.
#[pyfunction]
#[pyo3(signature = (inputs, outputs=None, *, output_template=None, update=false, errors="raise",
                    progress=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn convert<'py>(
    py: Python<'py>,
    inputs: Paths,
    outputs: Option<Paths>,
    output_template: Option<&str>,
    update: bool,
    errors: &str,
    progress: Option<Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let raise = raises(errors)?;
    let o = conversion_options(options)?;
    let pairs = crate::paths::pairs(py, inputs.list(), outputs.map(Paths::list), output_template)?;
    let converter = py.detach(|| Converter::new(o)).map_err(conversion)?;
    run(
        py,
        (&converter, None),
        &pairs,
        (update, raise),
        progress,
        None,
    )
}

/// The options of a conversion from `convert`'s keywords, each read as the library defines it
/// ([`specconv_conversion::definition`]): an unknown keyword is a `TypeError`, as Python's own.
pub(crate) fn conversion_options(keywords: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
    let mut o = Options::default();
    for (keyword, value) in keywords.into_iter().flat_map(|d| d.iter()) {
        let name: String = keyword.extract()?;
        let key = Key::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = Key::ALL.iter().map(|k| k.about().name).collect();
            pyo3::exceptions::PyTypeError::new_err(format!(
                "convert() got an unexpected keyword argument '{name}' (its options: {})",
                names.join(", ")
            ))
        })?;
        let Some(text) = option_text(key, &value)? else {
            o.unset(key);
            continue;
        };
        o.set_os(key, &text)
            .map_err(|e| Kind::Option.err(e.to_string()))?;
    }
    Ok(o)
}

/// An option's value from Python as the library's text: a bool `true`/`false`, a number as
/// written, a pair of whole numbers `WxH`, a path as `os.fspath` gives it, a `Model` as its
/// file; `None` (unset) where the option can be unset.
fn option_text(key: Key, value: &Bound<'_, PyAny>) -> PyResult<Option<OsString>> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyString, PyTuple};
    let about = key.about();
    let name = about.name;
    if value.is_none() {
        return match Options::default().text(key) {
            None => Ok(None),
            Some(default) => {
                Err(Kind::Option.err(format!("{name} cannot be None (its default is {default})")))
            }
        };
    }
    let wrong = |takes: &str| {
        let type_name = value
            .get_type()
            .name()
            .map_or_else(|_| "?".into(), |n| n.to_string());
        Kind::Option.err(format!("{name} takes {takes}, not {type_name}"))
    };
    let is_bool = value.is_instance_of::<PyBool>();
    let text: OsString = match about.value {
        // mip=True/False: a bool is its text, as the choice's names accept it.
        Value::Switch | Value::Choice if is_bool => value.is_truthy()?.to_string().into(),
        Value::Switch => return Err(wrong("True or False")),
        Value::Number if !is_bool && (value.is_instance_of::<PyFloat>() || value.is_instance_of::<PyInt>()) => {
            value.extract::<f64>()?.to_string().into()
        }
        Value::Number => return Err(wrong("a number")),
        Value::Count if !is_bool && value.is_instance_of::<PyInt>() => {
            whole(name, value.extract::<i128>()?, u64::MAX)?.to_string().into()
        }
        Value::Count => return Err(wrong("a whole number")),
        Value::Size if value.is_instance_of::<PyTuple>() => {
            let (w, h): (i128, i128) = value.extract().map_err(|_| wrong("(width, height) or 'scanline'"))?;
            let (w, h) = (whole(name, w, usize::MAX)?, whole(name, h, usize::MAX)?);
            format!("{w}x{h}").into()
        }
        Value::Path if key == Key::Model => match value.extract::<ModelArg>()? {
            ModelArg::Path(p) => p.0.into_os_string(),
            ModelArg::Object(m) => m.get().origin().ok_or_else(|| {
                Kind::Option.err("this model was trained in Python and not saved: save it (model.save(path)) so that outputs can name it")
            })?.into_os_string(),
        },
        Value::Path => value.extract::<FsPath>()?.0.into_os_string(),
        Value::Text | Value::Choice | Value::Size if value.is_instance_of::<PyString>() => {
            value.extract::<String>()?.into()
        }
        Value::Text | Value::Choice | Value::Size => return Err(wrong("a str")),
    };
    Ok(Some(text))
}

/// The batch on a thread of its own while this one, holding the GIL between waits, hears
/// signals and calls `progress`. The batch waits at each event (a window of pixels done, an
/// input finished) until this thread has taken it: a Ctrl-C heard here, or a callback that
/// raises, is seen by the batch before its next window. (One heard after an input's last
/// window may find its output published: whole, never partial.)
/// `each_input`, when given, converts input k with its converter k; `annotate` rewrites each
/// record.
pub(crate) fn run<'py>(
    py: Python<'py>,
    (converter, each_input): (&Converter, Option<&[&Converter]>),
    pairs: &[Pair],
    (update, raise): (bool, bool),
    progress: Option<Bound<'py, PyAny>>,
    mut annotate: Option<Annotate<'_>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let cancel = AtomicBool::new(false);
    // A rendezvous: the batch waits at each event until this thread takes it, so it never runs
    // ahead of what Python has heard. With a queue, a main thread starved of the CPU heard the
    // first progress when the conversion was already published, and a Ctrl-C then came too
    // late to stop anything (the flaky Ctrl-C test of issue 31).
    let (tx, rx) = mpsc::sync_channel::<Said>(0);
    // Shared with the waits that release the GIL (which may run on any thread).
    let rx = std::sync::Mutex::new(rx);
    let mut records = Vec::new();
    let mut failure: Option<PyErr> = None;
    let mut index = (0, PathBuf::new());
    let json = py.import("json")?;
    let ended = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let mut batch = Batch::new(converter).update(update).cancel_on(&cancel);
            if let Some(each) = each_input {
                batch = batch.each_input(each);
            }
            let tell = |said| {
                let _ = tx.send(said);
            };
            let ended = batch.run(pairs, &mut |event| {
                for said in heard_of(&event, converter, raise) {
                    if matches!(said, Said::Failed(..)) {
                        cancel.store(true, Ordering::SeqCst);
                    }
                    tell(said);
                }
            });
            drop(tx);
            ended
        });
        loop {
            let said = py.detach(|| {
                rx.lock()
                    .map_err(|_| mpsc::RecvTimeoutError::Disconnected)?
                    .recv_timeout(Duration::from_millis(50))
            });
            let heard = match said {
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
                // Stopping: the batch's last events are drained, nothing more is called back
                // (a callback that raised, or one held when Ctrl-C came, is not called again).
                _ if failure.is_some() => continue,
                Ok(Said::Started(i, input)) => {
                    index = (i, input);
                    call(&progress, (index.0, index.1.clone(), 0u64, 0u64))
                }
                Ok(Said::Progress(done, total)) => {
                    call(&progress, (index.0, index.1.clone(), done, total))
                }
                Ok(Said::Record(r, input, status)) => {
                    let r = match annotate.as_mut() {
                        Some(a) => a(&input, status, r),
                        None => r,
                    };
                    json.call_method1("loads", (r,)).map(|r| records.push(r))
                }
                Ok(Said::Failed(kind, message)) => Err(kind.err(message)),
                Err(mpsc::RecvTimeoutError::Timeout) => Ok(()),
            }
            .and_then(|()| py.check_signals());
            if let Err(e) = heard {
                cancel.store(true, Ordering::SeqCst);
                failure.get_or_insert(e);
            }
        }
        worker.join()
    });
    if let Some(e) = failure {
        let stopped = !matches!(&ended, Ok(Ok(summary)) if !summary.cancelled);
        return Err(interrupted(py, e, stopped));
    }
    match ended {
        Ok(Ok(_summary)) => Ok(records),
        Ok(Err(e)) => Err(conversion(e)),
        Err(_) => Err(Kind::Input.err("the conversion stopped unexpectedly")),
    }
}

/// The error a batch ended with when Python raised `e` during it. Decided where each output
/// is published: a Ctrl-C that came after the last one (nothing `stopped`) says so.
fn interrupted(py: Python<'_>, e: PyErr, stopped: bool) -> PyErr {
    if !stopped && e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
        return pyo3::exceptions::PyKeyboardInterrupt::new_err(
            "interrupted after every output was completed; they were kept",
        );
    }
    e
}

/// What the caller hears of a batch's event: progress, a record of each input, and with
/// `raise` an input's failure as the exception to raise (the batch is then cancelled).
fn heard_of(event: &Event, converter: &Converter, raise: bool) -> Vec<Said> {
    match *event {
        Event::Started { index, input } => vec![Said::Started(index, input.into())],
        Event::Progress { done, total } => vec![Said::Progress(done, total)],
        Event::Skipped { input, output } => vec![said(Record::skipped(input, output))],
        Event::Converted {
            input,
            output,
            report,
        } => vec![said(Record::converted(converter, input, output, report))],
        Event::Data {
            input,
            output,
            report,
        } => vec![said(Record::data(input, output, report))],
        Event::Failed {
            input,
            output,
            error,
            seconds,
        } => {
            let message = without_input(&crate::errors::message(error), input);
            let record = said(Record::failed(input, output, message.clone(), seconds));
            let failed = Said::Failed(
                crate::errors::kind(error),
                format!("{}: {message}", input.display()),
            );
            match raise {
                true => vec![record, failed],
                false => vec![record],
            }
        }
        _ => Vec::new(),
    }
}

/// A record as the batch's thread tells it.
fn said(r: Record) -> Said {
    Said::Record(r.to_json(), r.input().to_path_buf(), r.status())
}

/// Calls the progress callback, if any.
fn call(progress: &Option<Bound<'_, PyAny>>, args: (usize, PathBuf, u64, u64)) -> PyResult<()> {
    if let Some(p) = progress {
        p.call1(args)?;
    }
    Ok(())
}

/// `errors=`: whether a failed input raises (`raise`) or is only recorded (`record`).
pub(crate) fn raises(errors: &str) -> PyResult<bool> {
    match errors {
        "raise" => Ok(true),
        "record" => Ok(false),
        _ => Err(Kind::Option.err(format!(
            "errors must be 'raise' or 'record', not '{errors}'"
        ))),
    }
}
