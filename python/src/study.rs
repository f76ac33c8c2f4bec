//! `flexmech.study`: a parameter study from Python, run by the studies
//! crate exactly as `flexmech study` runs a study file — over a base
//! model's key paths, or with each run's model built by a Python callable
//! (called under the interpreter lock, the solves outside it, in parallel).

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use flexmech::studies::spec::{SpecError, StudySpec};
use flexmech::studies::sweep::SweepError;
use flexmech::studies::{
    run_study, DatasetFigure, Figure, Study, StudyError, StudyOptions, StudyReport,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use toml::Value;

use crate::convert::{dict_to_table, to_python, to_toml};
use crate::errors::{from_model_error, key_error, run_error};
use crate::model::{registry, PyModel};

/// The grid: each name with its list of values.
fn grid(py: Python<'_>, grid: &Bound<'_, PyDict>) -> PyResult<Vec<(String, Vec<Value>)>> {
    let mut out = Vec::new();
    for (k, values) in grid.iter() {
        let key: String = k
            .extract()
            .map_err(|_| key_error(py, "grid", "grid keys must be strings"))?;
        let at = format!("grid.\"{key}\"");
        if values.is_instance_of::<PyString>() || values.is_instance_of::<PyDict>() {
            return Err(key_error(
                py,
                &at,
                "give a list of values, e.g. [0.05, 0.1]",
            ));
        }
        let list = match to_toml(&values, &at)? {
            Value::Array(list) => list,
            _ => {
                return Err(key_error(
                    py,
                    &at,
                    "give a list of values, e.g. [0.05, 0.1]",
                ))
            }
        };
        out.push((key, list));
    }
    Ok(out)
}

/// The figures: names of built-in ones, or dicts of a dataset figure
/// (`{"name", "dataset", "component", "reduce"}`, as in study files).
fn figures(py: Python<'_>, figures: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Figure>> {
    let Some(list) = figures.filter(|f| !f.is_none()) else {
        return Ok(Figure::ALL.to_vec());
    };
    let mut out = Vec::new();
    for (i, item) in list.try_iter()?.enumerate() {
        let item = item?;
        let at = format!("figures[{i}]");
        if let Ok(name) = item.extract::<String>() {
            let f = Figure::from_name(&name).ok_or_else(|| {
                let known: Vec<&str> = Figure::ALL.iter().map(Figure::name).collect();
                key_error(
                    py,
                    &at,
                    &format!("unknown figure \"{name}\"; the figures are {} or a dataset figure (a dict)", known.join(", ")),
                )
            })?;
            out.push(f);
        } else if let Ok(d) = item.cast::<PyDict>() {
            let table = dict_to_table(d, &at)?;
            let f =
                DatasetFigure::parse(&Value::Table(table)).map_err(|e| key_error(py, &at, &e))?;
            out.push(Figure::Dataset(f));
        } else {
            return Err(key_error(py, &at, "a figure is a name or a dict"));
        }
    }
    Ok(out)
}

/// Where a Python callable's exception is kept for the study's error.
type Raised = Arc<Mutex<Option<PyErr>>>;

/// The study whose runs are built by the Python callable `build`.
fn from_callable(
    name: &str,
    grid: Vec<(String, Vec<Value>)>,
    figures: Vec<Figure>,
    build: Py<PyAny>,
    raised: Raised,
) -> Result<StudySpec, SpecError> {
    StudySpec::from_fn(name, grid, figures, move |p| {
        Python::attach(|py| {
            let keep = |e: PyErr| {
                let text = e.to_string();
                if let Ok(mut slot) = raised.lock() {
                    slot.get_or_insert(e);
                }
                text
            };
            let params = PyDict::new(py);
            for (k, v) in p.iter() {
                let v = to_python(py, v).map_err(keep)?;
                params.set_item(k, v).map_err(keep)?;
            }
            let out = build.call1(py, (params,)).map_err(keep)?;
            let model = out.bind(py).cast::<PyModel>().map_err(|_| {
                format!(
                    "the function returned {}, not a flexmech.Model",
                    out.bind(py)
                        .get_type()
                        .name()
                        .map(|n| n.to_string())
                        .unwrap_or_default()
                )
            })?;
            let checked = model.borrow_mut().checked(py);
            checked.map_err(keep)
        })
    })
}

/// The exception of a study's error; `raised` holds a callable's own.
fn study_error(py: Python<'_>, e: StudyError, raised: &Raised) -> PyErr {
    let cause = raised.lock().ok().and_then(|mut s| s.take());
    let err = match &e {
        StudyError::Spec(SpecError::Model { source, .. }) => {
            from_model_error(py, source, Some(source.file()), true)
        }
        StudyError::Spec(
            SpecError::UnknownModelKey { key, .. }
            | SpecError::BadKey { key, .. }
            | SpecError::EmptyList { key, .. },
        ) => crate::errors::model_error(py, &e.to_string(), key, None, None, &e.to_string()),
        StudyError::Spec(_) => {
            crate::errors::model_error(py, &e.to_string(), "", None, None, &e.to_string())
        }
        StudyError::Sweep(SweepError::InvalidRun(run)) => {
            crate::errors::model_error(py, &e.to_string(), &run.key, None, None, &run.message)
        }
        StudyError::Sweep(SweepError::Function { .. })
            if cause.as_ref().is_some_and(|c| {
                c.get_type(py)
                    .is(py.get_type::<crate::errors::ModelError>())
            }) =>
        {
            let c = cause.as_ref().map(|c| c.value(py).clone());
            let key: String = c
                .as_ref()
                .and_then(|c| c.getattr("key").ok()?.extract().ok())
                .unwrap_or_default();
            crate::errors::model_error(py, &e.to_string(), &key, None, None, &e.to_string())
        }
        _ => run_error(e.to_string()),
    };
    if let Some(c) = cause {
        err.set_cause(py, Some(c));
    }
    err
}

/// Runs `spec` below `out` on `threads` threads (all of rayon's pool when
/// None), without the interpreter lock.
fn execute(
    py: Python<'_>,
    spec: &StudySpec,
    out: PathBuf,
    threads: Option<usize>,
) -> Result<StudyReport, Box<StudyError>> {
    let options = StudyOptions {
        out,
        shard: None,
        progress: true,
    };
    let study = || run_study(spec, &options).map_err(Box::new);
    py.detach(|| match threads {
        None => study(),
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(study),
            Err(_) => study(),
        },
    })
}

/// Runs a study and returns `(directory, summary.h5)`. See
/// `flexmech.study` for the arguments.
#[pyfunction]
#[pyo3(signature = (name, grid, build = None, figures = None, out = None, threads = None, base = None))]
#[allow(clippy::too_many_arguments)]
pub fn run_study_py(
    py: Python<'_>,
    name: &str,
    grid: &Bound<'_, PyDict>,
    build: Option<Py<PyAny>>,
    figures: Option<&Bound<'_, PyAny>>,
    out: Option<PathBuf>,
    threads: Option<usize>,
    base: Option<&Bound<'_, PyModel>>,
) -> PyResult<(String, String)> {
    if threads == Some(0) {
        return Err(key_error(py, "threads", "give at least one thread"));
    }
    let keys = self::grid(py, grid)?;
    let figures = self::figures(py, figures)?;
    let raised: Raised = Arc::new(Mutex::new(None));
    let spec = match (build, base) {
        (Some(f), None) => {
            if !f.bind(py).is_callable() {
                return Err(key_error(py, "build", "build must be a callable: build(params) -> flexmech.Model"));
            }
            from_callable(name, keys, figures, f, raised.clone())
        }
        (None, Some(b)) => {
            let model = b.borrow_mut().checked(py)?;
            let mut study = Study::over(name, &model).joints(registry());
            for (k, v) in keys {
                study = study.grid(&k, v);
            }
            for f in figures {
                study = study.figure(f);
            }
            study.spec()
        }
        _ => {
            return Err(key_error(
                py,
                "build",
                "give either build (a callable: params -> Model) or base (a Model whose key paths the grid sets)",
            ))
        }
    };
    let spec = spec.map_err(|e| study_error(py, StudyError::Spec(e), &raised))?;
    let out = out.unwrap_or_else(|| PathBuf::from("studies"));
    let report = execute(py, &spec, out, threads).map_err(|e| study_error(py, *e, &raised))?;
    Ok((
        report.dir.display().to_string(),
        report.h5.display().to_string(),
    ))
}

/// Runs the study file at `path` as `flexmech study PATH --out OUT` does;
/// returns `(directory, summary.h5)`.
#[pyfunction]
#[pyo3(signature = (path, out = None, threads = None))]
pub fn run_study_file(
    py: Python<'_>,
    path: PathBuf,
    out: Option<PathBuf>,
    threads: Option<usize>,
) -> PyResult<(String, String)> {
    let raised: Raised = Arc::new(Mutex::new(None));
    let spec = flexmech::studies::load_study_with(&path, registry())
        .map_err(|e| study_error(py, StudyError::Spec(e), &raised))?;
    let out = out.unwrap_or_else(|| PathBuf::from("studies"));
    let report = execute(py, &spec, out, threads).map_err(|e| study_error(py, *e, &raised))?;
    Ok((
        report.dir.display().to_string(),
        report.h5.display().to_string(),
    ))
}
