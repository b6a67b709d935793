//! `specconv.evaluate`: how well a model reproduces measured spectra from their own colours,
//! as `specconv eval --json` reports it (the study crate's one evaluation).

use crate::model::Model;
use pyo3::prelude::*;
use specconv_colour::Illuminant;
use specconv_evaluation::eval;

/// The spectral error Δe and the colour shift under other lights of the uplift of each row of
/// `spectra` (sampled at `wavelengths` nm, resampled onto the model's grid) from its own colour;
/// a dict as `specconv eval --json` prints it, with `per_spectrum` (`delta_e`, and a list per
/// illuminant under `colour_shift`).
#[pyfunction]
#[pyo3(signature = (spectra, wavelengths, model=None, *, under=None, bounded=true,
                    blend=specconv_spectral::otsu2018::blend::DEFAULT_WIDTH))]
pub fn evaluate<'py>(
    py: Python<'py>,
    spectra: &Bound<'py, PyAny>,
    wavelengths: &Bound<'py, PyAny>,
    model: Option<&Bound<'py, Model>>,
    under: Option<Vec<String>>,
    bounded: bool,
    blend: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let model = match model {
        Some(m) => m.get(),
        None => Model::default_model()?,
    };
    // As `eval` measures: exact under the model's own band sums (the round trip of Eq. 9).
    let description = specconv_spectral::stack::StackSpec::measured(
        specconv_spectral::method::MethodName::Otsu2018,
        blend,
        Default::default(),
        specconv_spectral::baselines::jakob::DEFAULT_RESOLUTION,
        bounded,
    );
    let stack = model.stack_of(&description)?;
    let a = stack.colorimetry();
    let lights: Vec<Illuminant> = match under {
        None => eval::SHIFT_ILLUMINANTS.to_vec(),
        Some(names) => names
            .iter()
            .map(|n| n.parse())
            .collect::<Result<_, _>>()
            .map_err(crate::errors::option)?,
    };
    let viewing = eval::Viewing::new(a, &lights).map_err(crate::errors::option)?;
    let (table, _) = crate::model::table_of(spectra, wavelengths, None, "spectra")?;
    let spectra = table.resampled(&a.grid).map_err(crate::errors::option)?;
    let (summary, outcomes) = py.detach(|| {
        let outcomes = eval::evaluate(a, stack.method(), &spectra, &viewing);
        (eval::summarise(&outcomes), outcomes)
    });
    let mut v = serde_json::to_value(&summary).map_err(crate::errors::option)?;
    v["method"] = stack.method().name().into();
    v["model"] =
        specconv_conversion::models::describe(model.origin().as_deref(), &model.inner).into();
    let shift: serde_json::Map<String, serde_json::Value> = lights
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let values: Vec<f64> = outcomes
                .iter()
                .map(|o| o.colour_shift[k].ciede2000)
                .collect();
            (l.to_string(), values.into())
        })
        .collect();
    v["per_spectrum"] = serde_json::json!({
        "delta_e": outcomes.iter().map(|o| o.delta_e).collect::<Vec<_>>(),
        "colour_shift": shift,
    });
    let text = serde_json::to_string(&v).map_err(crate::errors::option)?;
    py.import("json")?.call_method1("loads", (text,))
}
