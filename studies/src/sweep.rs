//! From a grid to runs: the cartesian product of the swept values, and the
//! model-file text of each run (the base model with the run's values put at
//! their keys, [`super::key_path`]).

use std::path::{Path, PathBuf};

use toml::{Table, Value};

use super::key_path::lookup_mut;
use super::spec::{RunParams, RunSource, StudySpec};
use flexmech_model::{parse_model_with, Model, ModelError};

/// One run of a study: its position in grid order and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct RunPlan {
    /// 0-based index in grid order (the last key varies fastest).
    pub index: usize,
    /// `run-0000`, `run-0001`, … (more digits when there are more than 10 000 runs).
    pub id: String,
    /// The value of each grid key, in the order of [`StudySpec::grid`].
    pub values: Vec<Value>,
}

/// The id of run `index` of `total`: `run-` and the index with at least four
/// digits (as many as the largest index needs), so ids sort like indices.
pub fn run_id(index: usize, total: usize) -> String {
    let width = total.saturating_sub(1).to_string().len().max(4);
    format!("run-{index:0width$}")
}

/// The 0-based index in a run id written by [`run_id`].
pub fn run_index(id: &str) -> Option<usize> {
    let digits = id.strip_prefix("run-")?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Every run of the grid `lists` (one list of values per key), in grid order:
/// the cartesian product with the last key varying fastest. No keys give a
/// single run with no values.
pub fn expand(lists: &[&[Value]]) -> Vec<RunPlan> {
    let total: usize = lists.iter().map(|l| l.len()).product();
    (0..total)
        .map(|index| {
            let mut rest = index;
            let mut values = vec![Value::Boolean(false); lists.len()];
            for (slot, list) in values.iter_mut().zip(lists).rev() {
                *slot = list[rest % list.len()].clone();
                rest /= list.len();
            }
            RunPlan {
                index,
                id: run_id(index, total),
                values,
            }
        })
        .collect()
}

/// A run's model fails the model-file checks once the run's values are in.
#[derive(Debug, thiserror::Error)]
#[error(
    "{}: {run} ({overrides}): the base model {} with these values is invalid: {}{message}; \
     change the values in [grid]",
    .study.display(),
    .model.display(),
    if .key.is_empty() { String::new() } else { format!("key `{}`: ", .key) }
)]
pub struct InvalidRun {
    /// The study file.
    pub study: PathBuf,
    /// The run id.
    pub run: String,
    /// `key = value, …` of the run.
    pub overrides: String,
    /// The base model file.
    pub model: PathBuf,
    /// The model key the check is about (may be empty).
    pub key: String,
    /// What the model check says.
    pub message: String,
}

/// A run whose model text could not be produced or is not a valid model.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The overridden model fails the model-file checks.
    #[error(transparent)]
    InvalidRun(Box<InvalidRun>),
    /// A key no longer resolves (cannot happen for keys checked at load).
    #[error("{}: {run}: grid key `{key}` {problem}", .study.display())]
    Key {
        /// The study file.
        study: PathBuf,
        /// The run id.
        run: String,
        /// The grid key.
        key: String,
        /// What is wrong.
        problem: String,
    },
    /// The study's Rust function gave no model for a run.
    #[error("{}: {run} ({overrides}): the study's function gives no model: {message}", .study.display())]
    Function {
        /// The study (its description).
        study: PathBuf,
        /// The run id.
        run: String,
        /// `key = value, …` of the run.
        overrides: String,
        /// What the function said.
        message: String,
    },
    /// A figure's `derivative` key names no value the run's model can be
    /// differentiated by.
    #[error(
        "{}: {run}: a figure's `derivative` (in [output] figures) cannot be taken: {message}; \
         change the figure's derivative keys",
        .study.display()
    )]
    Derivative {
        /// The study file.
        study: PathBuf,
        /// The run id.
        run: String,
        /// Why, in the model's words.
        message: String,
    },
    /// The overridden model could not be written back as TOML.
    #[error("{}: {run}: cannot write the overridden model as TOML: {message}", .study.display())]
    Serialize {
        /// The study file.
        study: PathBuf,
        /// The run id.
        run: String,
        /// The serializer's message.
        message: String,
    },
}

/// `key = value, …` for a run, in grid order (`base model` with no keys).
pub fn describe_values(spec: &StudySpec, plan: &RunPlan) -> String {
    if spec.grid.is_empty() {
        return "base model".into();
    }
    spec.grid
        .iter()
        .zip(&plan.values)
        .map(|(g, v)| format!("{} = {v}", g.key))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The model-file text of `plan` over the base model `table`: each grid key
/// set to the run's value, serialized back to TOML.
fn model_text(spec: &StudySpec, table: &Table, plan: &RunPlan) -> Result<String, SweepError> {
    let mut table = table.clone();
    for (g, value) in spec.grid.iter().zip(&plan.values) {
        let slot = lookup_mut(&mut table, &g.path).map_err(|problem| SweepError::Key {
            study: spec.file.clone(),
            run: plan.id.clone(),
            key: g.key.clone(),
            problem,
        })?;
        *slot = value.clone();
    }
    toml::to_string(&table).map_err(|e| SweepError::Serialize {
        study: spec.file.clone(),
        run: plan.id.clone(),
        message: e.to_string(),
    })
}

/// The model of `plan`. Over a base model file, the base with each grid key
/// set to the run's value, written back as TOML and loaded with every
/// model-file check. From a Rust function, what the function returns for
/// the run's parameters, its model text headed by the study, run and values.
/// Either is also built ([`flexmech_model::build()`]: joints placed by
/// relation (1), the initial state checked), so a run that cannot start is
/// refused before any runs.
pub fn model_for(spec: &StudySpec, plan: &RunPlan) -> Result<Model, SweepError> {
    match &spec.source {
        RunSource::ModelFile { file, table } => {
            let text = model_text(spec, table, plan)?;
            let mut model = parse_model_with(&text, file, &spec.joints)
                .map_err(|e| invalid_run(spec, plan, file, &e))?;
            derivatives(spec, plan, &mut model)?;
            let built = flexmech_model::build(&model).map(|_| model);
            built.map_err(|e| invalid_run(spec, plan, file, &e))
        }
        RunSource::Function(build) => {
            let params = RunParams {
                run: &plan.id,
                keys: &spec.grid,
                values: &plan.values,
            };
            let overrides = describe_values(spec, plan);
            let refuse = |message: String| SweepError::Function {
                study: spec.file.clone(),
                run: plan.id.clone(),
                overrides: overrides.clone(),
                message,
            };
            let mut model = (build.0)(&params).map_err(refuse)?;
            derivatives(spec, plan, &mut model)?;
            flexmech_model::build(&model).map_err(|e| refuse(e.to_string()))?;
            let written = model.to_toml();
            model.source_text = format!(
                "# study `{}`, {} ({overrides}): the model was built by a Rust function; the \
                 text below is the model that ran\n{written}",
                spec.name, plan.id
            );
            model.source_written = written;
            Ok(model)
        }
    }
}

/// Asks `model` (run `plan`'s) for the derivatives the figures want.
fn derivatives(spec: &StudySpec, plan: &RunPlan, model: &mut Model) -> Result<(), SweepError> {
    model
        .add_sensitivity(&spec.derivative_keys())
        .map_err(|e| SweepError::Derivative {
            study: spec.file.clone(),
            run: plan.id.clone(),
            message: e.message().to_owned(),
        })
}

/// The base `file` with run `plan`'s values refused by the model checks.
fn invalid_run(spec: &StudySpec, plan: &RunPlan, file: &Path, e: &ModelError) -> SweepError {
    SweepError::InvalidRun(Box::new(InvalidRun {
        study: spec.file.clone(),
        run: plan.id.clone(),
        overrides: describe_values(spec, plan),
        model: file.to_path_buf(),
        key: e.key().to_owned(),
        message: e.message().to_owned(),
    }))
}
