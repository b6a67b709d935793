//! numpy arrays in and out: any leading shape, float32 kept float32, anything else as float64.

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;

/// Values of an array whose last axis has `last` entries (`None`: any), flattened in C order,
/// with the leading shape.
pub enum Values {
    F32(Vec<usize>, Vec<f32>),
    F64(Vec<usize>, Vec<f64>),
}

/// `array` as [`Values`]: float32 as it is, any other numbers as float64.
pub fn values(array: &Bound<'_, PyAny>, last: Option<usize>, what: &str) -> PyResult<Values> {
    let py = array.py();
    let as_f64 = || -> PyResult<Bound<'_, PyArrayDyn<f64>>> {
        let np = py.import("numpy")?;
        // numpy would drop an imaginary part with a warning: a value that is not real is an
        // error, whatever its imaginary part.
        let is_complex = np
            .call_method1("iscomplexobj", (array,))
            .and_then(|c| c.is_truthy())
            .unwrap_or(false);
        if is_complex {
            return Err(crate::errors::Kind::Option.err(format!(
                "{what} are complex numbers; specconv takes real values (pass .real if the \
                 imaginary parts are meant to be dropped)"
            )));
        }
        let converted = np
            .call_method1("asarray", (array, np.getattr("float64")?))
            .map_err(|e| match e.is_instance_of::<PyMemoryError>(py) {
                true => e,
                false => crate::errors::Kind::Option.err(format!("{what}: {e}")),
            })?;
        Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
    };
    let shape_of = |shape: &[usize]| -> PyResult<Vec<usize>> {
        let ok = match last {
            Some(n) => shape.last() == Some(&n),
            None => !shape.is_empty(),
        };
        if !ok {
            let want = last.map_or("at least one axis".to_string(), |n| {
                format!("a last axis of {n}")
            });
            return Err(crate::errors::Kind::Option
                .err(format!("{what} has shape {shape:?}; it needs {want}")));
        }
        Ok(shape[..shape.len() - 1].to_vec())
    };
    if let Ok(a) = array.cast::<PyArrayDyn<f32>>() {
        let lead = shape_of(a.shape())?;
        return Ok(Values::F32(lead, copied(a, what)?));
    }
    let a = as_f64()?;
    let lead = shape_of(a.shape())?;
    Ok(Values::F64(lead, copied(&a, what)?))
}

/// The values in C order, owned: the work runs without the GIL, when Python code could change
/// the array. One copy of memory when the array is C-contiguous (`as_slice` also takes Fortran
/// order, whose memory is not in C order).
/// A copy that memory cannot hold (a broadcast view of 10¹² colours costs numpy nothing) is a
/// `MemoryError`, not an aborted process.
pub(crate) fn copied<T: numpy::Element + Copy>(
    a: &Bound<'_, PyArrayDyn<T>>,
    what: &str,
) -> PyResult<Vec<T>> {
    let c_order = a.is_c_contiguous();
    let a = a.readonly();
    let mut v = Vec::new();
    v.try_reserve_exact(a.len()).map_err(|_| {
        PyMemoryError::new_err(format!("{what}: {} values do not fit in memory", a.len()))
    })?;
    match a.as_slice() {
        Ok(s) if c_order => v.extend_from_slice(s),
        _ => v.extend(a.as_array().iter().copied()),
    }
    Ok(v)
}

/// A zeroed array of shape `lead + [last]`, allocated by numpy: its allocator asks the kernel
/// for huge pages for large arrays, so filling one costs a fraction of the page faults of a
/// `Vec` handed over (the faults and unmapping were ⅔ of `uplift`'s time, issue 22's profile).
/// Made by `numpy.zeros`, so an array too large is numpy's `MemoryError`, not a panic.
pub fn zeros<'py, T: numpy::Element>(
    py: Python<'py>,
    lead: &[usize],
    last: usize,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let mut shape = lead.to_vec();
    shape.push(last);
    let dtype = numpy::dtype::<T>(py);
    let array = py.import("numpy")?.call_method1("zeros", (shape, dtype))?;
    Ok(array.cast_into::<PyArrayDyn<T>>()?)
}

/// `values` as an array of shape `lead + [last]`.
pub fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    lead: &[usize],
    last: usize,
    values: Vec<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let mut shape = lead.to_vec();
    shape.push(last);
    let a = ArrayD::from_shape_vec(IxDyn(&shape), values)
        .map_err(|e| crate::errors::Kind::Option.err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// A 1-D float64 array.
pub fn vector<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyArrayDyn<f64>> {
    ArrayD::from_shape_vec(IxDyn(&[values.len()]), values.to_vec())
        .expect("a vector's shape is its length")
        .into_pyarray(py)
}
