//! Spectral OpenEXR files in the layout of Fichet et al. 2021, read into and written from numpy
//! arrays by the project's reader and writer (what `convert` writes and `to-rgb` reads).

use crate::args::{whole, FsPath};
use crate::arrays::Values;
use crate::errors::Kind;
use numpy::ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use specconv_exr::{Blocks, Kind as Bands, Spec, SpectralFile};

/// One MIP level of a spectral file.
#[pyclass(module = "specconv", frozen)]
pub struct SpectralImage {
    /// Band wavelengths, nm, increasing.
    #[pyo3(get)]
    wavelengths: Py<PyAny>,
    /// float32, shape (height, width, bands), rows from the top as the file stores them.
    #[pyo3(get)]
    values: Py<PyAny>,
    /// float32, shape (height, width), or `None` when the file has no `A` channel.
    #[pyo3(get)]
    alpha: Py<PyAny>,
    /// `"reflectance"` (`T.` channels) or `"emission"` (`S0.` channels).
    #[pyo3(get)]
    kind: &'static str,
    /// The `emissiveUnits` of an emission file (`None` for reflectance).
    #[pyo3(get)]
    units: Option<String>,
    /// Number of MIP levels in the file.
    #[pyo3(get)]
    levels: usize,
    /// The level read (0 is the largest).
    #[pyo3(get)]
    level: usize,
    /// The header's text attributes.
    #[pyo3(get)]
    attributes: Py<PyAny>,
}

#[pymethods]
impl SpectralImage {
    fn __repr__(&self, py: Python<'_>) -> String {
        let shape = shape(py, &self.values);
        format!(
            "<specconv.SpectralImage {} {shape}, level {} of {}>",
            self.kind, self.level, self.levels
        )
    }
}

/// Reads MIP level `level` (0: the largest) of a spectral EXR: its `T.` bands (reflectance),
/// else its `S0.` bands (emission), any wavelengths the layout allows, and `A`.
/// A FIFO, a device or a directory is refused by kind before anything opens it (as the
/// command line refuses them): opening a FIFO would wait for a writer for ever.
#[pyfunction]
#[pyo3(signature = (path, *, level=0))]
pub fn read_spectral(py: Python<'_>, path: FsPath, level: i128) -> PyResult<SpectralImage> {
    let (path, level) = (path.0, whole("level", level, usize::MAX)?);
    let image = py
        .detach(|| -> Result<_, specconv_conversion::Error> {
            specconv_atomic_file::readable_file(&path)?;
            // A compact texture is named as one (read it with read_compact).
            specconv_exr::read_level(&path, level)
                .map_err(|source| specconv_conversion::spectral_read_error(&path, source))
        })
        .map_err(crate::errors::conversion)?;
    let (w, h, n) = (image.width, image.height, image.wavelengths.len());
    let mut interleaved = vec![0f32; w * h * n];
    for (b, plane) in image.bands.iter().enumerate() {
        for (p, &v) in plane.iter().enumerate() {
            interleaved[p * n + b] = v;
        }
    }
    let shaped = Array3::from_shape_vec((h, w, n), interleaved)
        .map_err(|e| Kind::Input.err(e.to_string()))?;
    let alpha = alpha_array(py, (h, w), image.alpha)?;
    let attributes = PyDict::new(py);
    for (k, v) in &image.attributes {
        attributes.set_item(k, v)?;
    }
    let (kind, units) = match image.kind {
        Bands::Reflective => ("reflectance", None),
        Bands::Emissive { units } => ("emission", Some(units)),
        // Never read: the reader gives bands only.
        Bands::Named(_) => ("values", None),
    };
    Ok(SpectralImage {
        wavelengths: crate::arrays::vector(py, &image.wavelengths)
            .into_any()
            .unbind(),
        values: shaped.into_pyarray(py).into_any().unbind(),
        alpha,
        kind,
        units,
        levels: image.levels,
        level,
        attributes: attributes.into_any().unbind(),
    })
}

/// One MIP level of a compact texture (`convert(layout="compact")`, docs/compact.md).
#[pyclass(module = "specconv", frozen)]
pub struct CompactImage {
    /// The decoding text (`specconvCompact`): what `specconv.decode` takes.
    #[pyo3(get)]
    text: String,
    /// float32, shape (height, width, 6): X Y Z u0 u1 u2 (the colour the file stores, as XYZ, and
    /// u = U + UF), rows from the top.
    #[pyo3(get)]
    texels: Py<PyAny>,
    /// float32, shape (height, width), or `None` when the file has no `A` channel.
    #[pyo3(get)]
    alpha: Py<PyAny>,
    /// Number of MIP levels in the file.
    #[pyo3(get)]
    levels: usize,
    /// The level read (0 is the largest).
    #[pyo3(get)]
    level: usize,
}

#[pymethods]
impl CompactImage {
    fn __repr__(&self, py: Python<'_>) -> String {
        let shape = shape(py, &self.texels);
        format!(
            "<specconv.CompactImage {shape}, level {} of {}>",
            self.level, self.levels
        )
    }
}

/// Reads MIP level `level` (0: the largest) of a compact texture: its texels and decoding
/// text; a spectral or RGB file is refused with what it is. A FIFO, a device or a directory is
/// refused by kind before anything opens it.
#[pyfunction]
#[pyo3(signature = (path, *, level=0))]
pub fn read_compact(py: Python<'_>, path: FsPath, level: i128) -> PyResult<CompactImage> {
    let (path, level) = (path.0, whole("level", level, usize::MAX)?);
    let image = py
        .detach(|| specconv_conversion::read_compact(&path, level))
        .map_err(crate::errors::conversion)?;
    let (w, h) = (image.width, image.height);
    let texels = Array3::from_shape_vec((h, w, specconv_spectral::compact::TEXEL), image.texels)
        .map_err(|e| Kind::Input.err(e.to_string()))?;
    let alpha = alpha_array(py, (h, w), image.alpha)?;
    Ok(CompactImage {
        text: image.text,
        texels: texels.into_pyarray(py).into_any().unbind(),
        alpha,
        levels: image.levels,
        level,
    })
}

/// A numpy array's shape as Python prints it (empty if it has none).
fn shape(py: Python<'_>, array: &Py<PyAny>) -> String {
    array
        .bind(py)
        .getattr("shape")
        .map_or(String::new(), |s| s.to_string())
}

/// Alpha as a (height, width) float32 array, or `None`.
fn alpha_array(
    py: Python<'_>,
    (h, w): (usize, usize),
    alpha: Option<Vec<f32>>,
) -> PyResult<Py<PyAny>> {
    Ok(match alpha {
        Some(a) => Array2::from_shape_vec((h, w), a)
            .map_err(|e| Kind::Input.err(e.to_string()))?
            .into_pyarray(py)
            .into_any()
            .unbind(),
        None => py.None(),
    })
}

/// Refuses a path that is missing or not a regular file (a FIFO, a device, a directory), by
/// kind, before anything opens it, as every reader of the library does: for readers outside
/// it (Mitsuba's), which would wait on a FIFO for ever.
#[pyfunction]
pub fn check_readable(path: FsPath) -> PyResult<()> {
    specconv_atomic_file::readable_file(&path.0).map_err(|e| {
        crate::errors::conversion(specconv_conversion::ConversionError::from(e).into())
    })
}

/// The compact grammar's limits (docs/compact.md), the library's own, for the numpy decoder
/// (specconv.compact) to read texts as the library does: `max_depth`, `max_bands`, `dark`,
/// `max_width`.
#[pyfunction]
pub fn compact_limits(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    use specconv_spectral::compact;
    let d = PyDict::new(py);
    d.set_item("max_depth", compact::MAX_DEPTH)?;
    d.set_item("max_bands", compact::MAX_BANDS)?;
    d.set_item("dark", compact::DARK)?;
    d.set_item("max_width", compact::MAX_WIDTH)?;
    Ok(d)
}

/// Whether the file `path`, read by another reader (Mitsuba's), is a compact texture, from its
/// header: `attributes` its text attributes by name (the library picks the ones it needs) and
/// `channels` its channel names. Returns the text as the library writes it and the columns of
/// R … UF.2 among `channels`; otherwise raises `InputError` saying what is missing or wrong.
#[pyfunction]
pub fn check_compact_header(
    path: FsPath,
    attributes: std::collections::HashMap<String, String>,
    channels: Vec<String>,
) -> PyResult<(String, [usize; specconv_spectral::compact::STORED])> {
    let names: Vec<&str> = channels.iter().map(String::as_str).collect();
    let attribute = |name: &str| attributes.get(name).cloned();
    specconv_conversion::check_compact_header(&path.0, &attribute, &names)
        .map_err(crate::errors::conversion)
}

/// Writes `values` (shape (height, width, bands), rows from the top) at `wavelengths` (nm,
/// finite, positive and increasing) as a spectral EXR with one level: reflectance (`T.`
/// channels), or with `emission` (`"reference"`, `"normalised"` or `"photometric"`, the
/// keyword of `convert`) emission (`S0.` channels, the layout's `emissiveUnits` and the
/// convention recorded as `convert` records it); `alpha` (height, width) as `A`. `path` must
/// end in `.exr`; written beside it and renamed into place; an existing `path` only with
/// `overwrite`, and never a FIFO, device or directory. `emission_units`, its old name, still
/// works with a `DeprecationWarning`.
#[pyfunction]
#[pyo3(signature = (path, wavelengths, values, *, alpha=None, emission=None,
                    sample="half", compression="zip", tile=Some((64, 64)), attributes=None,
                    overwrite=false, emission_units=None))]
#[allow(clippy::too_many_arguments)]
pub fn write_spectral(
    py: Python<'_>,
    path: FsPath,
    wavelengths: &Bound<'_, PyAny>,
    values: &Bound<'_, PyAny>,
    alpha: Option<&Bound<'_, PyAny>>,
    emission: Option<&str>,
    sample: &str,
    compression: &str,
    tile: Option<(i128, i128)>,
    attributes: Option<std::collections::BTreeMap<String, String>>,
    overwrite: bool,
    emission_units: Option<&str>,
) -> PyResult<()> {
    let emission = renamed(py, emission, emission_units)?;
    let path = path.0;
    specconv_atomic_file::check_extension(
        &path,
        specconv_exr::EXTENSIONS,
        "write_spectral writes spectral OpenEXR",
    )
    .map_err(|e| crate::errors::conversion(e.into()))?;
    let wavelengths: Vec<f64> = match crate::arrays::values(wavelengths, None, "wavelengths")? {
        Values::F32(_, v) => v.into_iter().map(f64::from).collect(),
        Values::F64(_, v) => v,
    };
    specconv_exr::check_wavelengths(&wavelengths)
        .map_err(|e| Kind::Option.err(format!("wavelengths: {e}")))?;
    let emission: Option<specconv_colour::EmissionUnits> = emission
        .map(|u| crate::convert::pick("emission", u))
        .transpose()?;
    let tile = match tile {
        Some((w, h)) => Some((whole("tile", w, usize::MAX)?, whole("tile", h, usize::MAX)?)),
        None => None,
    };
    let n = wavelengths.len();
    let (lead, bands) = as_f32(values_of(values, n)?);
    let [height, width] = lead[..] else {
        return Err(Kind::Option.err(format!(
            "values must have shape (height, width, {n}), not {} axes",
            lead.len() + 1
        )));
    };
    let alpha = alpha.map(|a| alpha_of(a, (height, width))).transpose()?;
    let sample: specconv_exr::Sample = crate::convert::pick("sample", sample)?;
    let compression: specconv_conversion::Compression =
        crate::convert::pick("compression", compression)?;
    let spec = Spec {
        width,
        height,
        windows: None,
        wavelengths,
        kind: specconv_conversion::layout::bands(emission),
        alpha: alpha.is_some(),
        sample,
        compression: compression.exr(),
        zip_level: specconv_exr::zip::DEFAULT_LEVEL,
        blocks: match tile {
            Some((w, h)) => Blocks::Tiles {
                width: w,
                height: h,
                mip_levels: false,
            },
            None => Blocks::Scanlines,
        },
        attributes: recorded(emission)
            .into_iter()
            .chain(attributes.unwrap_or_default())
            .collect(),
        float_attributes: Vec::new(),
    };
    py.detach(|| -> PyResult<()> {
        let file = SpectralFile::new(spec).map_err(|e| Kind::Option.err(e.to_string()))?;
        let bytes = encoded(&file, &bands, alpha.as_deref())?;
        publish(&path, &bytes, overwrite)
    })
}

/// `emission`, or `emission_units` (its name before it took `convert`'s) with a
/// `DeprecationWarning`; both given is an `OptionError`.
fn renamed<'a>(
    py: Python<'_>,
    emission: Option<&'a str>,
    emission_units: Option<&'a str>,
) -> PyResult<Option<&'a str>> {
    match (emission, emission_units) {
        (Some(_), Some(_)) => Err(Kind::Option.err(
            "emission and emission_units are one keyword: give emission (emission_units is its old name)",
        )),
        (None, Some(old)) => {
            let warning = py.get_type::<pyo3::exceptions::PyDeprecationWarning>();
            PyErr::warn(
                py,
                &warning,
                c"write_spectral's emission_units is now emission, as convert's keyword",
                1,
            )?;
            Ok(Some(old))
        }
        (given, None) => Ok(given),
    }
}

/// The attributes that record what a file's values mean, as a conversion records them: the
/// emission convention ([`specconv_conversion::Provenance`]).
fn recorded(emission: Option<specconv_colour::EmissionUnits>) -> Vec<(String, String)> {
    let mut p = specconv_conversion::Provenance::default();
    p.emission_units = emission;
    p.to_attributes()
}

/// Values as float32, and the shape before their last axis.
fn as_f32(v: Values) -> (Vec<usize>, Vec<f32>) {
    match v {
        Values::F32(lead, v) => (lead, v),
        Values::F64(lead, v) => (lead, v.into_iter().map(|x| x as f32).collect()),
    }
}

/// An alpha array of shape (height, width), as float32.
fn alpha_of(alpha: &Bound<'_, PyAny>, (height, width): (usize, usize)) -> PyResult<Vec<f32>> {
    let (shape, a) = as_f32(crate::arrays::values(alpha, Some(width), "alpha")?);
    if shape != [height] {
        return Err(Kind::Option.err(format!(
            "alpha must have shape ({height}, {width}), like values"
        )));
    }
    Ok(a)
}

/// The bytes of `file` made of `bands` (bands a pixel, rows of the file's width) and `alpha`.
fn encoded(file: &SpectralFile, bands: &[f32], alpha: Option<&[f32]>) -> PyResult<Vec<u8>> {
    let (width, n) = (file.spec().width, file.spec().wavelengths.len());
    let mut bytes = std::io::Cursor::new(Vec::new());
    file.write(&mut bytes, |sink| {
        for b in file.blocks() {
            let mut block = Vec::with_capacity(b.width * b.height * n);
            let mut a = alpha.map(|_| Vec::new());
            for y in b.y..b.y + b.height {
                let row = (y * width + b.x)..(y * width + b.x + b.width);
                block.extend_from_slice(&bands[row.start * n..row.end * n]);
                if let (Some(a), Some(all)) = (a.as_mut(), alpha) {
                    a.extend_from_slice(&all[row]);
                }
            }
            sink(b.chunk, file.encode(&b, &block, a.as_deref())?)?;
        }
        Ok(())
    })
    .map_err(|e| Kind::Input.err(e.to_string()))?;
    Ok(bytes.into_inner())
}

/// Writes `bytes` beside `path` and renames them into place; an existing `path` only with
/// `overwrite`.
fn publish(path: &std::path::Path, bytes: &[u8], overwrite: bool) -> PyResult<()> {
    let replace = specconv_atomic_file::Replace::when(overwrite);
    specconv_atomic_file::write_checked(path, bytes, &[], replace).map_err(|e| {
        use specconv_atomic_file::{PlanError, WriteError};
        let kind = match e {
            WriteError::Plan(PlanError::Exists { .. }) => Kind::Exists,
            _ => Kind::File,
        };
        kind.err(specconv_conversion::message(&e))
    })
}

/// The values of a (height, width, bands) array.
fn values_of(values: &Bound<'_, PyAny>, n: usize) -> PyResult<Values> {
    crate::arrays::values(values, Some(n), "values")
}
