//! Python values to model-file values (TOML) and back. A value that has no
//! TOML form (None, a NaN, an object) is refused with the key it was given
//! for, never passed on half-read.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use pyo3::IntoPyObjectExt;
use toml::{Table, Value};

use crate::errors::key_error;

/// A short name of `obj`'s type, for messages.
fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "object".into())
}

/// `obj` as a model-file value for `key`: bool, int, float (finite), str,
/// a sequence (list, tuple, NumPy array) of values, a dict of values.
pub fn to_toml(obj: &Bound<'_, PyAny>, key: &str) -> PyResult<Value> {
    let py = obj.py();
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract::<bool>()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj.extract::<i64>().map(Value::Integer).map_err(|_| {
            key_error(
                py,
                key,
                &format!("the integer {obj} does not fit in 64 bits"),
            )
        });
    }
    if obj.is_instance_of::<PyFloat>() {
        return finite(py, obj.extract::<f64>()?, key);
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return dict_to_table(d, key).map(Value::Table);
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, item) in obj.try_iter()?.enumerate() {
            items.push(to_toml(&item?, &format!("{key}[{i}]"))?);
        }
        return Ok(Value::Array(items));
    }
    if obj.is_none() {
        return Err(key_error(
            py,
            key,
            "None is not a model-file value (leave the key out instead)",
        ));
    }
    // NumPy arrays and scalars: their Python form.
    if obj.hasattr("tolist")? && obj.hasattr("dtype")? {
        let plain = obj.call_method0("tolist")?;
        if !plain.hasattr("dtype")? {
            return to_toml(&plain, key);
        }
    }
    if obj.hasattr("__index__")? {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::Integer(i));
        }
    }
    if obj.hasattr("__float__")? {
        if let Ok(x) = obj.extract::<f64>() {
            return finite(py, x, key);
        }
    }
    Err(key_error(
        py,
        key,
        &format!(
            "a value of type {} has no model-file form (give a number, string, boolean, list or dict)",
            type_name(obj)
        ),
    ))
}

fn finite(py: Python<'_>, x: f64, key: &str) -> PyResult<Value> {
    if x.is_finite() {
        Ok(Value::Float(x))
    } else {
        Err(key_error(
            py,
            key,
            &format!("{x} is not a finite number; give a finite value"),
        ))
    }
}

/// A dict of model-file values; its keys must be strings.
pub fn dict_to_table(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Table> {
    let mut table = Table::new();
    for (k, v) in d.iter() {
        let Ok(name) = k.extract::<String>() else {
            return Err(key_error(
                d.py(),
                key,
                &format!("dict keys must be strings, found {}", type_name(&k)),
            ));
        };
        let path = if key.is_empty() {
            name.clone()
        } else {
            format!("{key}.{name}")
        };
        table.insert(name, to_toml(&v, &path)?);
    }
    Ok(table)
}

/// A model-file value as a Python value (tables as dicts, arrays as lists,
/// dates as their text).
pub fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    match value {
        Value::String(s) => s.into_bound_py_any(py),
        Value::Integer(i) => i.into_bound_py_any(py),
        Value::Float(x) => x.into_bound_py_any(py),
        Value::Boolean(b) => b.into_bound_py_any(py),
        Value::Datetime(d) => d.to_string().into_bound_py_any(py),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_python(py, item)?)?;
            }
            Ok(list.into_any())
        }
        Value::Table(t) => {
            let dict = PyDict::new(py);
            for (k, v) in t {
                dict.set_item(k, to_python(py, v)?)?;
            }
            Ok(dict.into_any())
        }
    }
}
