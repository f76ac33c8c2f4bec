//! A result file (or a study summary) read whole: every dataset with its
//! path, shape and type, and the attributes of the root, of every group and
//! of every dataset — read without the interpreter, then handed to Python
//! as NumPy arrays and plain values.

use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenAscii, VarLenUnicode};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;

/// The values of a dataset or attribute, flattened in row-major order.
pub enum Data {
    /// Floating point (`f64`).
    Float(Vec<f64>),
    /// Unsigned integers (`u64`).
    Unsigned(Vec<u64>),
    /// Signed integers (`i64`).
    Signed(Vec<i64>),
    /// Booleans.
    Bool(Vec<bool>),
    /// Strings (variable-length UTF-8 or ASCII).
    Text(Vec<String>),
}

/// A dataset or attribute: its shape and values.
pub struct Array {
    shape: Vec<usize>,
    data: Data,
}

/// Everything in a file.
#[derive(Default)]
pub struct Contents {
    /// `(path, array)` of every dataset, in the file's order.
    pub datasets: Vec<(String, Array)>,
    /// `(path, attributes)` of the root (`/`), every group and every dataset.
    pub attrs: Vec<(String, Vec<(String, Array)>)>,
}

fn read<T: hdf5::H5Type>(c: &hdf5::Container) -> hdf5::Result<Vec<T>> {
    c.read_raw::<T>()
}

/// The values of `c` in the type its datatype holds; `None` for types no
/// result file has (compounds, references, fixed-length strings).
fn array(c: &hdf5::Container) -> hdf5::Result<Option<Array>> {
    let shape = c.shape();
    let data = match c.dtype()?.to_descriptor()? {
        TypeDescriptor::Float(_) => Data::Float(read::<f64>(c)?),
        TypeDescriptor::Unsigned(_) => Data::Unsigned(read::<u64>(c)?),
        TypeDescriptor::Integer(_) => Data::Signed(read::<i64>(c)?),
        TypeDescriptor::Boolean => Data::Bool(read::<bool>(c)?),
        TypeDescriptor::VarLenUnicode => Data::Text(
            read::<VarLenUnicode>(c)?
                .into_iter()
                .map(|s| s.as_str().to_owned())
                .collect(),
        ),
        TypeDescriptor::VarLenAscii => Data::Text(
            read::<VarLenAscii>(c)?
                .into_iter()
                .map(|s| s.as_str().to_owned())
                .collect(),
        ),
        _ => return Ok(None),
    };
    Ok(Some(Array { shape, data }))
}

fn attributes(loc: &hdf5::Location) -> hdf5::Result<Vec<(String, Array)>> {
    let mut out = Vec::new();
    for name in loc.attr_names()? {
        let attr = loc.attr(&name)?;
        if let Some(a) = array(&attr)? {
            out.push((name, a));
        }
    }
    Ok(out)
}

fn walk(group: &hdf5::Group, out: &mut Contents) -> hdf5::Result<()> {
    out.attrs.push((group.name(), attributes(group)?));
    for ds in group.datasets()? {
        let name = ds.name();
        out.attrs.push((name.clone(), attributes(&ds)?));
        if let Some(a) = array(&ds)? {
            out.datasets.push((name, a));
        }
    }
    for g in group.groups()? {
        walk(&g, out)?;
    }
    Ok(())
}

/// Reads every dataset and attribute of the HDF5 file at `path`.
pub fn read_file(path: &Path) -> Result<Contents, String> {
    let file =
        hdf5::File::open(path).map_err(|e| format!("{}: cannot open: {e}", path.display()))?;
    let mut out = Contents::default();
    walk(&file, &mut out).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    Ok(out)
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

impl Array {
    /// A dataset as Python: a NumPy array (strings: a list of str).
    fn into_py_array(self, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
        match self.data {
            Data::Float(v) => numpy(py, &self.shape, v),
            Data::Unsigned(v) => numpy(py, &self.shape, v),
            Data::Signed(v) => numpy(py, &self.shape, v),
            Data::Bool(v) => numpy(py, &self.shape, v),
            Data::Text(v) => Ok(PyList::new(py, v)?.into_any()),
        }
    }

    /// An attribute as Python: a scalar as float, int or str; an array as
    /// a NumPy array (strings: a list of str).
    fn into_py_value(self, py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
        if !self.shape.is_empty() {
            return self.into_py_array(py);
        }
        match self.data {
            Data::Float(v) => v.first().copied().unwrap_or(f64::NAN).into_bound_py_any(py),
            Data::Unsigned(v) => v.first().copied().unwrap_or(0).into_bound_py_any(py),
            Data::Signed(v) => v.first().copied().unwrap_or(0).into_bound_py_any(py),
            Data::Bool(v) => v.first().copied().unwrap_or(false).into_bound_py_any(py),
            Data::Text(v) => v
                .into_iter()
                .next()
                .unwrap_or_default()
                .into_bound_py_any(py),
        }
    }
}

impl Contents {
    /// `(datasets, attributes)`: dataset path → array, object path →
    /// {attribute → value}.
    pub fn into_py(self, py: Python<'_>) -> PyResult<(Bound<'_, PyDict>, Bound<'_, PyDict>)> {
        let datasets = PyDict::new(py);
        for (name, a) in self.datasets {
            datasets.set_item(name, a.into_py_array(py)?)?;
        }
        let attrs = PyDict::new(py);
        for (name, list) in self.attrs {
            let d = PyDict::new(py);
            for (k, a) in list {
                d.set_item(k, a.into_py_value(py)?)?;
            }
            attrs.set_item(name, d)?;
        }
        Ok((datasets, attrs))
    }
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
    contents.into_py(py)
}
