//! The package's exceptions and the conversion of the Rust errors into them:
//! a model's error keeps its located message and its key, file and line.

use std::path::Path;

use flexmech::model::ModelError as RustModelError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    flexmech,
    ModelError,
    PyValueError,
    "A model was refused: a model file, text or builder call, a key set with \
     `Model.set`, or a run's model in a study. `str(e)` is the located message \
     (`file:line: key `solver.dt`: must be > 0, found -0.01`); `e.key` is the \
     key path (`solver.dt`, `joint[0].pitch`; empty when the error concerns the \
     whole model), `e.file` the model file or text name and `e.line` the \
     1-based line where known (both None for a model built in Python), \
     `e.message` the message without its location."
);

pyo3::create_exception!(
    flexmech,
    RunError,
    PyRuntimeError,
    "A run, stepping or study could not go on for a reason other than its model \
     or its solver: a result file that cannot be written or read, a restart of \
     another mechanism, a study whose runs cannot be written. (A solver that \
     stops part-way is not an exception of `run`: its result has status \
     `failed: ...`.) `Simulation.step` raises it when the solver stops."
);

/// A `ModelError` exception with its attributes.
pub fn model_error(
    py: Python<'_>,
    message: &str,
    key: &str,
    file: Option<&Path>,
    line: Option<usize>,
    short: &str,
) -> PyErr {
    let err = ModelError::new_err(message.to_owned());
    let value = err.value(py);
    let file = file.map(|f| f.display().to_string());
    // Setting attributes of a fresh exception instance cannot fail but for
    // memory; the message is kept either way.
    let _ = value.setattr("key", key);
    let _ = value.setattr("file", file);
    let _ = value.setattr("line", line);
    let _ = value.setattr("message", short);
    err
}

/// The `ModelError` exception of a Rust model error. `file` names the model
/// file or text (None for a model built in Python, whose text is
/// generated); `lines` says whether the error's line refers to that text as
/// its user wrote it (not after a change made in Python).
pub fn from_model_error(
    py: Python<'_>,
    e: &RustModelError,
    file: Option<&Path>,
    lines: bool,
) -> PyErr {
    let line = if lines { e.line() } else { None };
    let mut text = e.file().display().to_string();
    if let Some(l) = line {
        text.push_str(&format!(":{l}"));
    }
    text.push_str(": ");
    if !e.key().is_empty() {
        text.push_str(&format!("key `{}`: ", e.key()));
    }
    text.push_str(e.message());
    model_error(py, &text, e.key(), file, line, e.message())
}

/// A `ModelError` about `key` of a model built or changed in Python.
pub fn key_error(py: Python<'_>, key: &str, message: &str) -> PyErr {
    let text = if key.is_empty() {
        message.to_owned()
    } else {
        format!("key `{key}`: {message}")
    };
    model_error(py, &text, key, None, None, message)
}

/// A `RunError` exception with `message`.
pub fn run_error(message: impl std::fmt::Display) -> PyErr {
    RunError::new_err(message.to_string())
}
