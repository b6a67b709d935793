//! `specconv._specconv`: the conversion library from Python, numpy in and out. The pure-Python
//! package `specconv` (python/specconv) re-exports it with its exceptions, stubs and the
//! Mitsuba 3 plugins. Every function releases the GIL while it works; nothing is computed here
//! that the library does not compute for the command line (DESIGN.md: front-ends over one
//! library).

mod args;
mod arrays;
mod colour;
mod convert;
mod errors;
mod files;
mod model;
mod plan;

use pyo3::prelude::*;

#[pymodule]
fn _specconv(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(colour::uplift, m)?)?;
    m.add_function(wrap_pyfunction!(colour::spectra_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::rgb_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::_kernel_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(convert::convert, m)?)?;
    m.add_function(wrap_pyfunction!(convert::options, m)?)?;
    m.add_class::<files::SpectralImage>()?;
    m.add_function(wrap_pyfunction!(files::read_spectral, m)?)?;
    m.add_function(wrap_pyfunction!(files::write_spectral, m)?)?;
    Ok(())
}
