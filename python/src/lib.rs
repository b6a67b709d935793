//! `specconv._specconv`: the conversion library from Python, numpy in and out. The pure-Python
//! package `specconv` (python/specconv) re-exports it with its exceptions, stubs and the
//! Mitsuba 3 plugins. Every function releases the GIL while it works; nothing is computed here
//! that the library does not compute for the command line (DESIGN.md: front-ends over one
//! library).

mod args;
mod arrays;
mod asset;
mod colour;
mod convert;
mod errors;
mod evaluate;
mod files;
mod model;
mod paths;
mod texels;

use pyo3::prelude::*;

#[pymodule]
fn _specconv(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(colour::uplift, m)?)?;
    m.add_function(wrap_pyfunction!(colour::encode, m)?)?;
    m.add_function(wrap_pyfunction!(colour::spectra_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::rgb_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::_kernel_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(convert::convert, m)?)?;
    m.add_function(wrap_pyfunction!(convert::options, m)?)?;
    m.add_function(wrap_pyfunction!(asset::convert_asset, m)?)?;
    m.add_class::<files::SpectralImage>()?;
    m.add_function(wrap_pyfunction!(files::read_spectral, m)?)?;
    m.add_function(wrap_pyfunction!(files::write_spectral, m)?)?;
    m.add_class::<files::CompactImage>()?;
    m.add_function(wrap_pyfunction!(files::read_compact, m)?)?;
    m.add_function(wrap_pyfunction!(files::check_compact_header, m)?)?;
    m.add_function(wrap_pyfunction!(files::compact_limits, m)?)?;
    m.add_function(wrap_pyfunction!(files::check_readable, m)?)?;
    m.add_function(wrap_pyfunction!(texels::compact_texels, m)?)?;
    m.add_function(wrap_pyfunction!(texels::palette, m)?)?;
    // A data copy interrupted by Ctrl-C returns at once; its writer, inside OpenImageIO, ends
    // later. The interpreter's exit waits for it: C++ destructors under it would crash.
    let settle = wrap_pyfunction!(_settle, m)?;
    m.py()
        .import("atexit")?
        .call_method1("register", (settle,))?;
    Ok(())
}

/// Waits (the GIL released, 10 minutes at most) for the writers of interrupted data copies.
#[pyfunction]
fn _settle(py: Python<'_>) {
    py.detach(|| specconv_conversion::settle_copies(std::time::Duration::from_secs(600)));
}
