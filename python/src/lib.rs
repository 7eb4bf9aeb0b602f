//! `rt_renderer._native`: the renderer's library crates as a Python extension module (PyO3),
//! over NumPy arrays. The Python package `rt_renderer` (python/rt_renderer) re-exports it and
//! adds what is plain Python (experiment rows as a pandas DataFrame).
//!
//! - `scene`: `Scene`, loaded from a TOML or Mitsuba XML file or TOML text, its
//!   cameras and objects changed in place; `Scene.render` runs an `rt_session::RenderJob` over
//!   it (`render`) with the GIL released, a progress callback and Ctrl-C at the next pass.
//! - `rays`: `Accel`, any `rt_accel::AccelSpec` built over NumPy triangles, tracing
//!   NumPy rays on all cores; the `render bench-accel` uniform rays.
//! - `images`: denoising NumPy frames with any `rt_denoise::DenoiserSpec` and sequences with
//!   any `rt_temporal::TemporalSpec` (SVGF), the CLI's metrics (`rt_metrics::compare`), EXR
//!   reading and experiments.
//! - `input`: a denoiser's input (channels, sample records, guide buffers, further samples)
//!   as a dict of arrays and back.
//!
//! Errors raise `rt_renderer.RtError` with the library's one-line message; arguments of the
//! wrong type or shape raise `TypeError` or `ValueError`.
//!
//! A runnable example is the walk-through in docs/python.md (`pip install ./python`, then the
//! Python snippets); the module has no Rust entry point of its own.

mod arrays;
mod images;
mod input;
mod rays;
mod render;
mod scene;

use pyo3::prelude::*;

pyo3::create_exception!(
    rt_renderer,
    RtError,
    pyo3::exceptions::PyException,
    "An error of the renderer's library: one line naming the file or argument and the problem."
);

/// The library's error as an `RtError`.
pub(crate) fn rt_err(e: impl std::fmt::Display) -> PyErr {
    RtError::new_err(e.to_string())
}

/// A bad argument as a `ValueError`.
pub(crate) fn value_err(message: impl Into<String>) -> PyErr {
    pyo3::exceptions::PyValueError::new_err(message.into())
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RtError", m.py().get_type::<RtError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<rays::Accel>()?;
    m.add_function(wrap_pyfunction!(rays::uniform_rays, m)?)?;
    m.add_function(wrap_pyfunction!(rays::accel_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(images::denoise, m)?)?;
    m.add_function(wrap_pyfunction!(images::denoise_sequence, m)?)?;
    m.add_function(wrap_pyfunction!(images::denoisers, m)?)?;
    m.add_function(wrap_pyfunction!(images::compare, m)?)?;
    m.add_function(wrap_pyfunction!(images::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(images::run_experiment, m)?)?;
    Ok(())
}
