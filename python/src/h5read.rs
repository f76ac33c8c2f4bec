//! A result file (or a study summary) read whole — every dataset with its
//! path, shape and type, and the attributes of the root, of every group and
//! of every dataset — by the results crate without the interpreter, then
//! handed to Python as NumPy arrays and plain values.

use std::path::Path;

use flexmech::results::{Array, Contents, Values};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;

/// Every dataset and attribute of `path`, or the error as text (naming
/// the file).
pub fn read_file(path: &Path) -> Result<Contents, String> {
    flexmech::results::read_contents(path).map_err(|e| e.to_string())
}

fn numpy<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    v: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), v)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// An array as a NumPy array (strings as a list).
fn py_array(a: Array, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    match a.values {
        Values::Float(v) => numpy(py, &a.shape, v),
        Values::Unsigned(v) => numpy(py, &a.shape, v),
        Values::Signed(v) => numpy(py, &a.shape, v),
        Values::Bool(v) => numpy(py, &a.shape, v),
        Values::Text(v) => Ok(PyList::new(py, v)?.into_any()),
    }
}

/// A scalar as a Python number or string; anything else as [`py_array`].
fn py_value(a: Array, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    if !a.shape.is_empty() {
        return py_array(a, py);
    }
    match a.values {
        Values::Float(v) => v.first().copied().unwrap_or(f64::NAN).into_bound_py_any(py),
        Values::Unsigned(v) => v.first().copied().unwrap_or(0).into_bound_py_any(py),
        Values::Signed(v) => v.first().copied().unwrap_or(0).into_bound_py_any(py),
        Values::Bool(v) => v.first().copied().unwrap_or(false).into_bound_py_any(py),
        Values::Text(v) => v
            .into_iter()
            .next()
            .unwrap_or_default()
            .into_bound_py_any(py),
    }
}

/// `(datasets, attributes)`: dataset path → array, object path →
/// {attribute → value}.
pub fn into_py(
    contents: Contents,
    py: Python<'_>,
) -> PyResult<(Bound<'_, PyDict>, Bound<'_, PyDict>)> {
    let datasets = PyDict::new(py);
    for (name, a) in contents.datasets {
        datasets.set_item(name, py_array(a, py)?)?;
    }
    let attrs = PyDict::new(py);
    for (name, list) in contents.attrs {
        let d = PyDict::new(py);
        for (k, a) in list {
            d.set_item(k, py_value(a, py)?)?;
        }
        attrs.set_item(name, d)?;
    }
    Ok((datasets, attrs))
}

/// Reads the HDF5 file at `path` (a result file or a study summary) whole:
/// `(datasets, attributes)` as for `flexmech.Result`.
#[pyfunction]
pub fn read_h5(
    py: Python<'_>,
    path: std::path::PathBuf,
) -> PyResult<(Bound<'_, PyDict>, Bound<'_, PyDict>)> {
    let contents = py
        .detach(|| read_file(&path))
        .map_err(crate::errors::run_error)?;
    into_py(contents, py)
}
