//! `compact_texels`: the compact texels of pixels a renderer's reader decoded, made in memory
//! by the library (Mitsuba's `specconv_rgb`), in parallel with the GIL released.

use crate::args::FsPath;
use crate::arrays::{array, copied, zeros};
use crate::errors::{conversion, Kind};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use specconv_conversion::{Converter, Decoded, InMemory, Layout, Samples, Texels};
use specconv_spectral::compact::{Compact, TEXEL};

/// The compact texels (h, w, 6 float32: X, Y, Z, u₀, u₁, u₂) of `pixels`, an image a reader
/// decoded from `path`, as a conversion with `options` (`convert`'s keywords; the layout is
/// compact) makes them: `(text, texels, colorspace)`, the decoding text (docs/compact.md),
/// the texels, and the colour space they were read in, chosen from the file's header by the
/// rule `convert` uses. `pixels`: (h, w) or (h, w, c) with c from 1 to 4 (grey, grey and
/// alpha, RGB, RGBA), the file's samples as stored: uint8 or uint16 (scaled to [0, 1]) or
/// floats. `straight_alpha`: the reader's alpha is straight (PNG), so colour is multiplied
/// by it once converted; `moved`: the reader converts an OpenEXR's chromaticities (Mitsuba's
/// `Bitmap` does), so such a file's own samples are read instead. With `palette`, where the
/// pixels repeat enough, the texels are a renderer's palette instead, `(numbers, spectra)` as
/// [`palette`] gives it, made from the distinct pixels the route finds.
#[pyfunction]
#[pyo3(signature = (pixels, path, *, straight_alpha=false, moved=false, palette=false, **options))]
pub fn compact_texels<'py>(
    py: Python<'py>,
    pixels: &Bound<'py, PyAny>,
    path: FsPath,
    straight_alpha: bool,
    moved: bool,
    palette: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(String, Bound<'py, PyAny>, String)> {
    let mut o = crate::convert::conversion_options(options)?;
    o.layout = Layout::Compact;
    let shape = pixels
        .cast::<numpy::PyUntypedArray>()
        .map_err(|_| Kind::Option.err("pixels must be a numpy array"))?
        .shape()
        .to_vec();
    let (h, w, c) = match shape[..] {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c),
        _ => {
            return Err(Kind::Option.err(format!(
                "pixels have shape {shape:?}: expected (height, width) or (height, width, channels)"
            )))
        }
    };
    let size = |n: usize| {
        u32::try_from(n).map_err(|_| Kind::Option.err(format!("an image {n} pixels wide or high")))
    };
    let decoded = Decoded {
        path: &path.0,
        size: (size(w)?, size(h)?),
    };
    let held = Held::of(pixels)?;
    let made = py
        .detach(|| {
            let converter = Converter::new(o)?;
            let image = InMemory {
                samples: held.samples(),
                channels: c,
                decoded,
                straight_alpha,
                moves_chromaticities: moved,
            };
            converter.compact_texels(&image, palette)
        })
        .map_err(conversion)?;
    drop(held);
    let texels = match made.texels {
        Texels::Every(texels) => array(py, &[h, w], TEXEL, texels)?.into_any(),
        Texels::Palette { numbers, spectra } => {
            let compact = Compact::from_text(&made.text).map_err(crate::errors::option)?;
            let numbers = array(py, &[h, w], 1, numbers)?;
            let spectra = spectra_array(py, &compact, spectra)?;
            (numbers, spectra).into_pyobject(py)?.into_any()
        }
    };
    Ok((made.text, texels, made.colorspace))
}

/// The palette of a compact texture's texels (h, w, 6 float32) for a renderer's lookup
/// (Mitsuba's `specconv_compact` and `specconv_rgb`), decoded with the text `text`:
/// `(numbers, spectra)`, each texel's number (h, w, 1 float32, whole numbers) and the distinct
/// texels' spectra at the bands (d, n float32), each decoded once by the rule; `None` where
/// those would take more memory than the texels (`specconv_conversion::palette`). The work
/// runs with the GIL released: `texels` must not be changed meanwhile.
#[pyfunction]
pub fn palette<'py>(
    py: Python<'py>,
    text: &str,
    texels: &Bound<'py, PyArrayDyn<f32>>,
) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
    let compact = Compact::from_text(text).map_err(crate::errors::option)?;
    let shape = texels.shape().to_vec();
    let Some((&TEXEL, lead)) = shape.split_last() else {
        return Err(Kind::Option.err(format!(
            "texels have shape {shape:?}: the last axis must hold six values"
        )));
    };
    let numbers = zeros::<f32>(py, lead, 1)?;
    let spectra = {
        let texels = texels.readonly();
        let texels = texels.as_slice()?;
        let mut numbers = numbers.readwrite();
        let numbers = numbers.as_slice_mut()?;
        py.detach(|| specconv_conversion::palette::palette(&compact, texels, numbers))
    };
    let Some(spectra) = spectra else {
        return Ok(None);
    };
    let spectra = spectra_array(py, &compact, spectra)?;
    Ok(Some((numbers.into_any(), spectra)))
}

/// A palette's spectra as an array (distinct texels, bands).
fn spectra_array<'py>(
    py: Python<'py>,
    compact: &Compact,
    spectra: Vec<f32>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = compact.grid().len();
    Ok(array(py, &[spectra.len() / n.max(1)], n, spectra)?.into_any())
}

/// The samples, copied in C order while the GIL is held (Python code may change the array
/// once it is released): integers as they are, other numbers as float32.
enum Held {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

impl Held {
    fn of(pixels: &Bound<'_, PyAny>) -> PyResult<Held> {
        if let Ok(a) = pixels.cast::<PyArrayDyn<u8>>() {
            return Ok(Held::U8(copied(a, "pixels")?));
        }
        if let Ok(a) = pixels.cast::<PyArrayDyn<u16>>() {
            return Ok(Held::U16(copied(a, "pixels")?));
        }
        if let Ok(a) = pixels.cast::<PyArrayDyn<f32>>() {
            return Ok(Held::F32(copied(a, "pixels")?));
        }
        let np = pixels.py().import("numpy")?;
        let kind: String = pixels.getattr("dtype")?.getattr("kind")?.extract()?;
        if kind != "f" {
            return Err(Kind::Option.err(format!(
                "pixels of dtype {}: expected uint8, uint16 or floats",
                pixels.getattr("dtype")?
            )));
        }
        let f = np.call_method1("asarray", (pixels, np.getattr("float32")?))?;
        Ok(Held::F32(copied(f.cast::<PyArrayDyn<f32>>()?, "pixels")?))
    }

    fn samples(&self) -> Samples<'_> {
        match self {
            Held::U8(v) => Samples::U8(v),
            Held::U16(v) => Samples::U16(v),
            Held::F32(v) => Samples::F32(v),
        }
    }
}
