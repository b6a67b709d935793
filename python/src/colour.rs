//! Colours and spectra as numpy arrays: `uplift` (the stack `convert` builds), `spectra_to_xyz`
//! (the readers' integration) and `rgb_to_xyz` (through OpenColorIO).

use crate::arrays::{array, values, zeros, Values};
use crate::errors::option;
use crate::model::Model;
use numpy::{PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;
use specconv_colour::{EmissionUnits, Integration};
use specconv_spectral::stack::Stack;

/// Colours per parallel piece: large enough that a piece outweighs its scheduling.
const PIECE: usize = 4096;

/// Spectra of CIE XYZ colours (D65 white, Y = 1 for a perfect white): what `convert` writes
/// for pixels of that colour, before samples are rounded to half. `xyz`: any shape ending in
/// 3; the result ends in the model's band count (`model.wavelengths`, or `bands`). float32
/// runs the float32 kernel `convert` runs (its spectra exactly); anything else float64.
#[pyfunction]
#[pyo3(signature = (xyz, model=None, *, bounded=true, blend=specconv_spectral::otsu2018::blend::DEFAULT_WIDTH,
                    method="otsu2018", bands=None, emission=None))]
#[allow(clippy::too_many_arguments)]
pub fn uplift<'py>(
    py: Python<'py>,
    xyz: &Bound<'py, PyAny>,
    model: Option<&Bound<'py, Model>>,
    bounded: bool,
    blend: f64,
    method: &str,
    bands: Option<&str>,
    emission: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut options = stack_options(bounded, blend, method, bands)?;
    options.emission = emission
        .map(str::parse::<EmissionUnits>)
        .transpose()
        .map_err(option)?;
    let model = match model {
        Some(m) => m.get(),
        None => Model::default_model()?,
    };
    let stack = model.stack(&options)?;
    let n = stack.method().grid().len();
    Ok(match values(xyz, Some(3), "xyz")? {
        Values::F32(lead, v) => {
            let out = zeros::<f32>(py, &lead, n)?;
            let mut spectra = out.readwrite();
            let spectra = spectra.as_slice_mut()?;
            py.detach(|| kernel(&stack, &v, spectra));
            out.into_any()
        }
        Values::F64(lead, v) => {
            let out = zeros::<f64>(py, &lead, n)?;
            let mut spectra = out.readwrite();
            let spectra = spectra.as_slice_mut()?;
            py.detach(|| {
                spectra
                    .par_chunks_mut(PIECE * n)
                    .zip(v.par_chunks(PIECE * 3))
                    .for_each(|(o, c)| stack.method().uplift_f64(c, o));
            });
            out.into_any()
        }
    })
}

/// Compact texels (X, Y, Z, u₀, u₁, u₂) of float32 colours `xyz` (..., 3), and the text that
/// decodes them (docs/compact.md): what `convert --layout compact` stores, for
/// `specconv.decode`.
#[pyfunction]
#[pyo3(signature = (xyz, model=None, *, bounded=true, blend=specconv_spectral::otsu2018::blend::DEFAULT_WIDTH,
                    method="otsu2018", bands=None))]
pub fn encode<'py>(
    py: Python<'py>,
    xyz: &Bound<'py, PyAny>,
    model: Option<&Bound<'py, Model>>,
    bounded: bool,
    blend: f64,
    method: &str,
    bands: Option<&str>,
) -> PyResult<(String, Bound<'py, PyAny>)> {
    let options = stack_options(bounded, blend, method, bands)?;
    let model = match model {
        Some(m) => m.get(),
        None => Model::default_model()?,
    };
    let name = specconv_conversion::models::describe(model.origin().as_deref(), &model.inner);
    let compact =
        specconv_spectral::compact::Compact::new(&model.inner, &name, &options.stack_spec())
            .map_err(option)?;
    let Values::F32(lead, v) = values(xyz, Some(3), "xyz")? else {
        return Err(
            crate::errors::Kind::Option.err("encode takes float32 colours, as textures hold them")
        );
    };
    let m = specconv_spectral::compact::TEXEL;
    let out = zeros::<f32>(py, &lead, m)?;
    {
        let mut texels = out.readwrite();
        let texels = texels.as_slice_mut()?;
        py.detach(|| {
            texels
                .par_chunks_mut(PIECE * m)
                .zip(v.par_chunks(PIECE * 3))
                .for_each(|(t, c)| {
                    compact.encode_f32(c, t);
                })
        });
    }
    Ok((compact.to_text(), out.into_any()))
}

/// The float32 kernel: the pipeline's call (`uplift_f32_tallied`), in parallel pieces.
fn kernel(stack: &Stack, xyz: &[f32], out: &mut [f32]) {
    let n = stack.method().grid().len();
    out.par_chunks_mut(PIECE * n)
        .zip(xyz.par_chunks(PIECE * 3))
        .for_each(|(o, c)| {
            let mut tally = Default::default();
            stack.method().uplift_f32_tallied(c, o, &mut tally);
        });
}

/// Seconds the float32 kernel takes on `xyz` (an (n, 3) float32 array) with the default model,
/// its input and output in Rust's memory, the output written once before (no page faults):
/// the reference of the package's benchmark (python/bench/uplift.py), the kernel's throughput
/// alone, measured in the same process as `uplift`.
#[pyfunction]
pub fn _kernel_seconds(py: Python<'_>, xyz: &Bound<'_, PyAny>) -> PyResult<f64> {
    let Values::F32(_, v) = values(xyz, Some(3), "xyz")? else {
        return Err(crate::errors::Kind::Option.err("the kernel takes float32"));
    };
    let stack = Model::default_model()?.stack(&specconv_conversion::Options::default())?;
    let n = stack.method().grid().len();
    Ok(py.detach(|| {
        let mut out = vec![1f32; v.len() / 3 * n];
        let start = std::time::Instant::now();
        kernel(&stack, &v, &mut out);
        let seconds = start.elapsed().as_secs_f64();
        std::hint::black_box(out);
        seconds
    }))
}

/// CIE XYZ of `spectra` sampled at `wavelengths` (nm), integrated as the spectral layout's
/// reference reader does (values interpolated linearly onto 1 nm, summed with the CIE tables):
/// reflectance under `illuminant` (a perfect white has Y = 1), or with `emission` the emission
/// in those units (`reference`: ∫ S·x̄ dλ; `normalised`; `photometric`). float64 out.
#[pyfunction]
#[pyo3(signature = (spectra, wavelengths, *, illuminant="D65", observer="cie1931", emission=None))]
pub fn spectra_to_xyz<'py>(
    py: Python<'py>,
    spectra: &Bound<'py, PyAny>,
    wavelengths: &Bound<'py, PyAny>,
    illuminant: &str,
    observer: &str,
    emission: Option<&str>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let wavelengths = match values(wavelengths, None, "wavelengths")? {
        Values::F32(_, v) => v.into_iter().map(f64::from).collect(),
        Values::F64(_, v) => v,
    };
    let n = wavelengths.len();
    let observer = observer.parse().map_err(option)?;
    let integration = match emission {
        Some(units) => units
            .parse::<EmissionUnits>()
            .and_then(|u| u.integration(&wavelengths, observer)),
        None => illuminant
            .parse()
            .and_then(|i| Integration::reflectance(&wavelengths, observer, i)),
    }
    .map_err(option)?;
    let xyz = |s: &[f64]| integration.xyz(s);
    let (lead, out) = match values(spectra, Some(n), "spectra")? {
        Values::F32(lead, v) => (
            lead,
            py.detach(|| {
                v.par_chunks(n)
                    .flat_map_iter(|s| {
                        let s: Vec<f64> = s.iter().map(|&x| f64::from(x)).collect();
                        xyz(&s)
                    })
                    .collect()
            }),
        ),
        Values::F64(lead, v) => (
            lead,
            py.detach(|| v.par_chunks(n).flat_map_iter(xyz).collect()),
        ),
    };
    array(py, &lead, 3, out)
}

/// CIE XYZ (D65) of colours in `colorspace` of the OpenColorIO `config` (a file, `aces`, an
/// `ocio://` name; `None`: `$OCIO`, else `aces`), as `convert` converts pixels: the config's
/// `cie_xyz_d65_interchange` (or `aces_interchange`) role. OpenColorIO computes in float32;
/// the result has the input's dtype (float32, else float64).
#[pyfunction]
#[pyo3(signature = (rgb, colorspace, config=Some("aces")))]
pub fn rgb_to_xyz<'py>(
    py: Python<'py>,
    rgb: &Bound<'py, PyAny>,
    colorspace: &str,
    config: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let colour = crate::errors::conversion;
    let processor = py.detach(|| {
        let config = specconv_conversion::ColourConfig::resolve(config)?;
        config.to_xyz(colorspace)
    });
    let processor = processor.map_err(colour)?;
    let apply = |mut v: Vec<f32>| -> PyResult<Vec<f32>> {
        py.detach(|| processor.apply_rgb(&mut v)).map_err(colour)?;
        Ok(v)
    };
    Ok(match values(rgb, Some(3), "rgb")? {
        Values::F32(lead, v) => array(py, &lead, 3, apply(v)?)?.into_any(),
        Values::F64(lead, v) => {
            let out = apply(v.into_iter().map(|x| x as f32).collect())?;
            let out = out.into_iter().map(f64::from).collect();
            array(py, &lead, 3, out)?.into_any()
        }
    })
}

/// The conversion options `uplift` and `encode` share: the method stack's.
fn stack_options(
    bounded: bool,
    blend: f64,
    method: &str,
    bands: Option<&str>,
) -> PyResult<specconv_conversion::Options> {
    let mut options = specconv_conversion::Options::default();
    options.bounded = bounded;
    options.blend = blend;
    options.method = method.parse().map_err(option)?;
    options.bands = bands.map(str::parse).transpose().map_err(option)?;
    Ok(options)
}
