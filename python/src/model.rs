//! `specconv.Model`: a clustered-PCA model, built in, loaded from a file or trained on numpy
//! spectra, and the method stacks built from it (cached: building one resamples the model).

use crate::args::{whole, FsPath};
use crate::errors::Kind;
use pyo3::prelude::*;
use specconv_spectral::otsu2018::model::BUILTIN;
use specconv_spectral::stack::Stack;
use specconv_spectral::TrainOptions;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A clustered-PCA model (Otsu et al. 2018): `Model.builtin()`, `Model.load(path)` or
/// `Model.train(spectra, wavelengths)`.
#[pyclass(module = "specconv", frozen)]
pub struct Model {
    pub inner: Arc<specconv_spectral::Model>,
    /// What `convert`'s `model` option names it by: a built-in name or a file; `None` for a
    /// model trained here and not saved.
    pub origin: Mutex<Option<PathBuf>>,
    /// Stacks built for `uplift`, by their description.
    stacks: Mutex<HashMap<String, Arc<Stack>>>,
}

impl Model {
    fn new(inner: specconv_spectral::Model, origin: Option<PathBuf>) -> Model {
        Model {
            inner: Arc::new(inner),
            origin: Mutex::new(origin),
            stacks: Mutex::new(HashMap::new()),
        }
    }

    /// Where `convert` finds it.
    pub fn origin(&self) -> Option<PathBuf> {
        self.origin.lock().map_or(None, |o| o.clone())
    }

    /// The stack `options` describe on this model, built once.
    pub fn stack(&self, options: &specconv_conversion::Options) -> PyResult<Arc<Stack>> {
        self.stack_of(&options.stack_spec())
    }

    /// The stack `description` describes on this model, built once.
    pub fn stack_of(
        &self,
        description: &specconv_spectral::stack::StackSpec,
    ) -> PyResult<Arc<Stack>> {
        let key = format!("{description:?}");
        if let Some(s) = self.stacks.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return Ok(s);
        }
        let tables = specconv_conversion::tables::in_dir(None, |_| {});
        let stack = Stack::build(description, &self.inner, &tables)
            .map(Arc::new)
            .map_err(crate::errors::option)?;
        if let Ok(mut m) = self.stacks.lock() {
            m.insert(key, stack.clone());
        }
        Ok(stack)
    }

    /// The model in force when none is named: the site's default (`$SPECCONV_MODEL`) or the
    /// built-in default, the library's rule ([`specconv_conversion::models::in_force`]); one
    /// per model named, for the process (so its stacks are built once).
    pub fn default_model() -> PyResult<&'static Model> {
        type Cache = Vec<(Option<PathBuf>, &'static Model)>;
        static CACHE: Mutex<Cache> = Mutex::new(Vec::new());
        let (path, _) = specconv_conversion::models::in_force(None);
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, m)) = cache.iter().find(|(p, _)| *p == path) {
            return Ok(m);
        }
        let inner = specconv_conversion::models::load(None)
            .map_err(|e| crate::errors::conversion(e.into()))?;
        let origin = path.clone().or_else(|| Some(BUILTIN[0].name.into()));
        // A handful at most (one per value of the variable): kept for the process.
        let m: &'static Model = Box::leak(Box::new(Model::new(inner, origin)));
        cache.push((path, m));
        Ok(m)
    }
}

/// The numpy spectra (one per row, at `wavelengths` nm) as a table named `source`, and their
/// weights (none: unweighted).
pub(crate) fn table_of(
    spectra: &Bound<'_, PyAny>,
    wavelengths: &Bound<'_, PyAny>,
    weights: Option<&Bound<'_, PyAny>>,
    source: &str,
) -> PyResult<(specconv_colour::SpectralTable, Vec<f64>)> {
    use crate::arrays::{values, Values};
    let flat = |v: Values| match v {
        Values::F32(lead, v) => (lead, v.into_iter().map(f64::from).collect::<Vec<_>>()),
        Values::F64(lead, v) => (lead, v),
    };
    let (_, wavelengths) = flat(values(wavelengths, None, "wavelengths")?);
    let n = wavelengths.len();
    let (lead, spectra) = flat(values(spectra, Some(n), "spectra")?);
    if lead.len() != 1 {
        return Err(Kind::Option.err(format!(
            "spectra must be 2-D (one spectrum of {n} values per row), not {} axes",
            lead.len() + 1
        )));
    }
    let weights = match weights {
        None => Vec::new(),
        Some(w) => flat(values(w, Some(lead[0]), "weights")?).1,
    };
    let table = specconv_colour::SpectralTable {
        source: source.to_string(),
        wavelengths,
        names: (0..lead[0]).map(|k| format!("spectrum {k}")).collect(),
        columns: spectra.chunks_exact(n).map(<[f64]>::to_vec).collect(),
    };
    Ok((table, weights))
}

/// The terms the trainer states (`licence`, `commercial`), else unknown ones.
fn terms_of(
    licence: Option<String>,
    commercial: Option<&str>,
) -> PyResult<specconv_spectral::otsu2018::terms::Terms> {
    use specconv_spectral::otsu2018::terms::{Commercial, Terms};
    // Arrays are no file: their terms are known only as stated, never by a source's name.
    let mut terms = match &licence {
        Some(l) => Terms::stated(l, Commercial::Unstated)
            .map_err(|e| Kind::Option.err(format!("licence: {e}")))?,
        None => Terms::of_content(None),
    };
    if let Some(c) = commercial {
        terms.commercial = c
            .parse()
            .map_err(|e: String| Kind::Option.err(format!("commercial: {e}")))?;
    }
    Ok(terms)
}

/// The model a Python training builds on (`with_model`), with its sets read again.
struct Base {
    model: specconv_spectral::Model,
    parts: Vec<specconv_spectral::Part>,
}

impl Base {
    fn read(
        py: Python<'_>,
        model: &std::path::Path,
        dir: &std::path::Path,
        unweighted: bool,
    ) -> PyResult<Base> {
        if !unweighted {
            return Err(Kind::Option.err(
                "with with_model, give your spectra one weight (weight=…), not weights per spectrum",
            ));
        }
        py.detach(|| {
            let named = model;
            let model = specconv_conversion::models::load(Some(named))?;
            let recorded = specconv_conversion::models::recorded_parts(named, &model, dir)?;
            Ok(Base {
                model,
                parts: recorded.parts,
            })
        })
        .map_err(|e: specconv_conversion::models::ModelError| crate::errors::conversion(e.into()))
    }
}

fn describe(origin: Option<PathBuf>, m: &specconv_spectral::Model) -> String {
    match origin {
        Some(p) => specconv_conversion::models::describe(Some(&p), m),
        None => specconv_conversion::models::describe(Some("(trained in Python)".as_ref()), m),
    }
}

#[pymethods]
impl Model {
    /// A built-in model by name (`None`: the built-in default, the first of `builtin_names()`);
    /// `specconv models` lists them.
    #[staticmethod]
    #[pyo3(signature = (name=None))]
    fn builtin(name: Option<&str>) -> PyResult<Model> {
        let name = name.unwrap_or(BUILTIN[0].name);
        let m = specconv_spectral::Model::builtin_named(name).ok_or_else(|| {
            let names: Vec<&str> = BUILTIN.iter().map(|b| b.name).collect();
            Kind::Option.err(format!(
                "no built-in model is called '{name}'; the built-in models are {}",
                names.join(", ")
            ))
        })?;
        Ok(Model::new(m.clone(), Some(name.into())))
    }

    /// The built-in models' names, the default first.
    #[staticmethod]
    fn builtin_names() -> Vec<&'static str> {
        BUILTIN.iter().map(|b| b.name).collect()
    }

    /// A model file written by `specconv train` or `Model.save`.
    #[staticmethod]
    fn load(py: Python<'_>, path: FsPath) -> PyResult<Model> {
        let path = path.0;
        let m = py
            .detach(|| specconv_conversion::models::load(Some(&path)))
            .map_err(|e| crate::errors::conversion(e.into()))?;
        Ok(Model::new(m, Some(path)))
    }

    /// Trains a model on measured reflectances `spectra` (one per row, values at `wavelengths`
    /// nm), as `specconv train` does: `clusters` leaves of at least `min_cluster_size` spectra,
    /// each with a condition number of M below `max_condition`, on the grid `bands`
    /// ("START:END:STEP" nm) under `observer` and `illuminant`. `weights`: one per spectrum.
    /// `source`, `licence` and `commercial` ("yes", "no", "unstated") are recorded in the
    /// model (and in every file it makes). Arrays have no file whose content could be
    /// checked: their terms are the ones stated, else unknown, whatever `source` says (a
    /// set's known terms come only with its file, `specconv train --spectra`).
    ///
    /// `with_model` (a built-in name or a model file) trains on top of that model's own data,
    /// as `specconv train --with`: its recorded sets, read from the folder `with_data`, join
    /// these spectra (which weigh `weight` each) with their recorded weights and terms, in the
    /// model's grid, observer and illuminant, its options the defaults of `clusters`,
    /// `min_cluster_size` and `max_condition`.
    #[staticmethod]
    #[pyo3(signature = (spectra, wavelengths, *, clusters=None, min_cluster_size=None,
                        max_condition=None, weights=None, bands="380:730:10",
                        observer="cie1931", illuminant="D65", source="numpy", licence=None,
                        commercial=None, with_model=None, with_data=None, weight=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn train(
        py: Python<'_>,
        spectra: &Bound<'_, PyAny>,
        wavelengths: &Bound<'_, PyAny>,
        clusters: Option<i128>,
        min_cluster_size: Option<i128>,
        max_condition: Option<f64>,
        weights: Option<&Bound<'_, PyAny>>,
        bands: &str,
        observer: &str,
        illuminant: &str,
        source: &str,
        licence: Option<String>,
        commercial: Option<&str>,
        with_model: Option<FsPath>,
        with_data: Option<FsPath>,
        weight: f64,
    ) -> PyResult<Model> {
        let (table, weights) = table_of(spectra, wavelengths, weights, source)?;
        let terms = terms_of(licence, commercial)?;
        let base = match (with_model, with_data) {
            (Some(m), Some(dir)) => Some(Base::read(py, &m.0, &dir.0, weights.is_empty())?),
            (None, None) => None,
            _ => return Err(Kind::Option.err(
                "with_model and with_data go together: the model, and the folder holding its sets",
            )),
        };
        let setting = match &base {
            Some(b) => (b.model.grid, b.model.observer, b.model.illuminant),
            None => (
                bands.parse().map_err(crate::errors::option)?,
                observer.parse().map_err(crate::errors::option)?,
                illuminant.parse().map_err(crate::errors::option)?,
            ),
        };
        let defaults = base.as_ref().map_or_else(TrainOptions::default, |b| {
            specconv_conversion::models::recorded_options(&b.model)
        });
        let opts = specconv_spectral::TrainOptions {
            clusters: whole(
                "clusters",
                clusters.unwrap_or(defaults.clusters as i128),
                usize::MAX,
            )?,
            min_cluster_size: whole(
                "min_cluster_size",
                min_cluster_size.unwrap_or(defaults.min_cluster_size as i128),
                usize::MAX,
            )?,
            max_condition: max_condition.unwrap_or(defaults.max_condition),
        };
        let model = py.detach(|| -> Result<_, specconv_spectral::Error> {
            let (grid, observer, illuminant) = setting;
            let mut own = specconv_spectral::TrainingSet::from_table(&table, &grid)?;
            let set = match base {
                Some(b) => {
                    let own = specconv_spectral::Part {
                        set: own,
                        weight,
                        terms,
                    };
                    specconv_spectral::TrainingSet::on_top(b.parts, vec![own], 0.0)?
                }
                None => {
                    own.sets.iter_mut().for_each(|s| {
                        s.licence = terms.licence.clone();
                        s.commercial = terms.commercial;
                        s.attribution = terms.attribution.clone();
                    });
                    own.weights = weights;
                    own
                }
            };
            let a = specconv_colour::Colorimetry::new(grid, observer, illuminant)?;
            specconv_spectral::train(&set, &a, &opts)
        });
        Ok(Model::new(model.map_err(crate::errors::option)?, None))
    }

    /// Writes the model as JSON (what `specconv train` writes and `Model.load` reads) to
    /// `path`, which must end in `.json`; an existing file only with `overwrite=True`, as
    /// `specconv train --force` (the library's rules for a model file: models::save).
    #[pyo3(signature = (path, *, overwrite=false))]
    fn save(&self, py: Python<'_>, path: FsPath, overwrite: bool) -> PyResult<()> {
        let path = path.0;
        let replace = specconv_atomic_file::Replace::when(overwrite);
        py.detach(|| specconv_conversion::models::save(&self.inner, &path, &[], replace))
            .map_err(|e| crate::errors::conversion(e.into()))?;
        if let Ok(mut o) = self.origin.lock() {
            *o = Some(path);
        }
        Ok(())
    }

    /// The wavelengths (nm) of the spectra it makes.
    #[getter]
    fn wavelengths<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArrayDyn<f64>> {
        crate::arrays::vector(py, &self.inner.grid.wavelengths())
    }

    /// Number of clusters.
    #[getter]
    fn clusters(&self) -> usize {
        self.inner.leaves.len()
    }

    /// The observer it was trained with (`cie1931`, …).
    #[getter]
    fn observer(&self) -> String {
        self.inner.observer.to_string()
    }

    /// The illuminant it was trained under.
    #[getter]
    fn illuminant(&self) -> String {
        self.inner.illuminant.to_string()
    }

    /// The data it was trained on, with their weights and terms of use.
    #[getter]
    fn sources(&self) -> String {
        specconv_conversion::models::sources(&self.inner)
    }

    /// Whether the model may be used commercially: "yes" only when every set it was trained
    /// on may, "no" when one may not, else "unstated".
    #[getter]
    fn commercial(&self) -> String {
        self.inner.training.commercial().to_string()
    }

    /// What a user of its training data must credit (`specconvModelAttribution`), or `None`.
    #[getter]
    fn attribution(&self) -> Option<String> {
        specconv_conversion::models::attribution(&self.inner)
    }

    /// The one-line description outputs record (`specconvModel`).
    #[getter]
    fn description(&self) -> String {
        describe(self.origin(), &self.inner)
    }

    /// The built-in name or file it came from; `None` when trained here and not saved.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.origin()
    }

    fn __repr__(&self) -> String {
        format!("<specconv.Model {}>", self.description())
    }
}
