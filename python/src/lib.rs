//! `flexmech._flexmech`, the extension module of the Python package
//! `flexmech` (see `python/flexmech/__init__.py` for the package and
//! `docs/book/python.md` for the chapter): models, runs into result files
//! read back as NumPy arrays, stepping, studies. Everything goes through the
//! Rust front door, the `flexmech` crate, with the interpreter released
//! while Rust works.

mod convert;
mod errors;
mod h5read;
mod model;
mod run;
mod simulation;
mod study;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _flexmech(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ModelError", py.get_type::<errors::ModelError>())?;
    m.add("RunError", py.get_type::<errors::RunError>())?;
    m.add_class::<model::PyModel>()?;
    m.add_function(wrap_pyfunction!(model::joint_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_model, m)?)?;
    m.add_function(wrap_pyfunction!(h5read::read_h5, m)?)?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_function(wrap_pyfunction!(study::run_study_py, m)?)?;
    m.add_function(wrap_pyfunction!(study::run_study_file, m)?)?;
    Ok(())
}
