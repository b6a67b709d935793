//! `specconv.convert_asset`: `specconv asset`'s conversion of a USD stage (docs/assets.md), by
//! the same library steps (`specconv_asset`): read and plan, one converter per colour space,
//! the batch of `convert`, the layer. usd-core is read in this interpreter: the reader
//! (`specconv._asset_reader`) is imported and asked in the protocol the command line's child
//! speaks, its answers read by the same parser (no second interpreter, no time limit: a run
//! of the caller's own).

use crate::convert::{conversion_options, run};
use crate::errors::{conversion, Kind};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use specconv_asset::{
    finish, make_folders, member, prepare, unknown_line, unknown_record, with_member, Call,
    Converters, Job, Outcomes, Prepared, Reader,
};
use specconv_conversion::record::Record;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Converts the textures a USD stage's bound materials read, each as its material says
/// (colour in the space it names, data skipped or copied as `data` says, a conflict or a
/// missing file a failure), into `output`, and writes `output/STEM_spectral.usda`, a layer over
/// the stage pointing each colour texture at its spectral file (a MaterialX document, `.mtlx`:
/// its copy `output/STEM_spectral.mtlx`). Returns `convert`'s records, each with an `asset`
/// member (the rule, why, the prims and inputs that read it); with `dry_run`, the `asset`
/// members alone and nothing written. usd-core and MaterialX (`pip install usd-core MaterialX`)
/// are read in this interpreter. `errors`, `update`, `progress` and the options' keywords are
/// `convert`'s (`colorspace` is refused: the material names it).
#[pyfunction]
#[pyo3(signature = (stage, output, *, update=false, errors="raise", dry_run=false,
                    progress=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn convert_asset<'py>(
    py: Python<'py>,
    stage: PathBuf,
    output: PathBuf,
    update: bool,
    errors: &str,
    dry_run: bool,
    progress: Option<Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let raise = crate::convert::raises(errors)?;
    let o = conversion_options(options)?;
    if o.colorspace.is_some() {
        return Err(Kind::Option.err(
            "convert_asset takes no colorspace: the material names each texture's (docs/assets.md)",
        ));
    }
    let reader = in_process(py)?;
    let Prepared { asset, jobs } = py
        .detach(|| prepare(&reader, (&stage, &output), &o, (dry_run, update)))
        .map_err(asset_error)?;
    let json = py.import("json")?;
    let loads = |text: String| json.call_method1("loads", (text,));
    if dry_run {
        return (0..asset.textures.len())
            .map(|k| loads(member(&asset, k).to_string()))
            .collect();
    }
    let mut records = Vec::new();
    // A shader it does not know reading a file: a record of its own; with `strict` (a warning
    // fails) an InputError where errors raise (issue 56, item 2).
    for u in &asset.unknown {
        if raise && o.strict {
            return Err(Kind::Input.err(unknown_line(u)));
        }
        records.push(loads(unknown_record(&asset, u).to_string())?);
    }
    for (k, t) in asset.textures.iter().enumerate() {
        let Some(why) = &t.error else { continue };
        if raise {
            return Err(Kind::Input.err(format!("{}: {why}", t.texture.file.display())));
        }
        let record = Record::failed(&t.texture.file, Path::new(""), why.clone(), 0.0);
        records.push(loads(with_member(&record.to_json(), &asset, k))?);
    }
    let converters = py
        .detach(|| Converters::new(&o, &jobs))
        .map_err(conversion)?;
    make_folders(&asset.dir, &jobs).map_err(asset_error)?;
    let each = converters.each();
    let pairs: Vec<_> = jobs.iter().map(Job::pair).collect();
    let mut outcomes = Outcomes::new(&asset, &jobs);
    let mut annotate =
        |input: &Path, status: &'static str, record: String| match outcomes.heard(input, status) {
            Some(k) => with_member(&record, &asset, k),
            None => record,
        };
    let converted = run(
        py,
        (converters.first(), Some(&each)),
        &pairs,
        (update, raise),
        progress,
        Some(&mut annotate),
    )?;
    records.extend(converted);
    py.detach(|| finish(&reader, &asset, &outcomes))
        .map_err(asset_error)?;
    Ok(records)
}

/// The reader in this interpreter: `specconv._asset_reader.answer`, called with the lock on
/// the interpreter taken again (the library runs the reader from `py.detach`).
fn in_process(py: Python<'_>) -> PyResult<Reader> {
    let python: PathBuf = py.import("sys")?.getattr("executable")?.extract()?;
    let module = py.import("specconv._asset_reader")?.unbind();
    let call: Call = Arc::new(move |request: &str| {
        Python::attach(|py| {
            let answer = module.bind(py).call_method1("answer", (request,))?;
            answer.extract::<(i32, String)>()
        })
        .map_err(|e| e.to_string())
    });
    Ok(Reader::in_process(python.into_os_string(), call))
}

/// An asset's error as this package's exception: the caller's (a setting) or the stage's.
fn asset_error(e: specconv_asset::Error) -> PyErr {
    use specconv_asset::Error as E;
    let kind = match &e {
        // As convert says an existing output and an output that is the input.
        E::NotWrittenByAsset { .. } | E::ChangedSinceWritten { .. } => Kind::Exists,
        E::WritesItsInput { .. } => Kind::File,
        e if e.is_usage() => Kind::Option,
        E::Io(..) => Kind::File,
        _ => Kind::Input,
    };
    kind.err(e.to_string())
}
