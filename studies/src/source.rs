//! Where a study's runs come from: a base model file whose keys the grid
//! overrides, or a Rust function from a run's parameters to its [`Model`].
//!
//! A study defined in Rust ([`StudySpec::from_fn`]) runs exactly like a study
//! file: the same grid expansion and run ids, parallel execution, progress
//! bar, shards (`--shard K/N` or a Slurm array) and merge, one HDF5 file per
//! run, summary table and charts. Only the model of each run is produced by
//! the researcher's function instead of by editing the base model's TOML.
//!
//! ```no_run
//! use flexmech_model::load_model;
//! use flexmech_studies::{run_study, Figure, StudyOptions, StudySpec};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let base = load_model("data/statics/screw_driven.toml".as_ref())?;
//! let spec = StudySpec::from_fn(
//!     "stiffness",
//!     vec![("EI".into(), vec![500.0.into(), 1000.0.into()])],
//!     Figure::ALL.to_vec(),
//!     move |p| {
//!         let mut model = base.clone();
//!         let ei = p.f64("EI")?;
//!         model.sections[0].values.ei = [ei, ei];
//!         Ok(model)
//!     },
//! )?;
//! let options = StudyOptions { out: "studies".into(), shard: None, progress: true };
//! run_study(&spec, &options)?;
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;

use toml::{Table, Value};

use super::key_path::{check_key, KeyPath};
use super::spec::{
    name_problem, Figure, GridKey, ModelFn, RunParams, RunSource, SpecError, StudySpec,
};
use flexmech_model::{parse_model_with, JointRegistry, Model, ModelError};

impl StudySpec {
    /// The base model file, for a study over one (`None` for runs built by
    /// a Rust function).
    pub fn model_file(&self) -> Option<&Path> {
        match &self.source {
            RunSource::ModelFile { file, .. } => Some(file),
            RunSource::Function(_) => None,
        }
    }

    /// A study whose runs are built by `build` from their parameters: the
    /// cartesian product of `grid` (`(key, values)` in order, the last key
    /// varying fastest), summarised by `figures`.
    ///
    /// The checks of a study file apply: a usable `name` (it names the
    /// output directory), non-empty value lists, distinct keys and figure
    /// names. `build` is called for every run before the first run starts;
    /// an error it returns stops the study with a message naming the run and
    /// its values. Each run's result file stores, as its model text, a header
    /// naming the study, run and values followed by the `source_text` of the
    /// model `build` returned (for a model loaded from a file and changed in
    /// Rust, that is the file it started from, before the changes).
    pub fn from_fn<F>(
        name: &str,
        grid: Vec<(String, Vec<Value>)>,
        figures: Vec<Figure>,
        build: F,
    ) -> Result<StudySpec, SpecError>
    where
        F: Fn(&RunParams<'_>) -> Result<Model, String> + Send + Sync + 'static,
    {
        let file = PathBuf::from(format!("study `{name}` (defined in Rust)"));
        let grid = checked(&file, name, grid, &figures, None)?;
        Ok(StudySpec {
            text: describe(name, &grid, &figures, None),
            file,
            name: name.to_owned(),
            source: RunSource::Function(ModelFn(Arc::new(build))),
            grid,
            figures,
            titles: true,
            joints: JointRegistry::builtin(),
        })
    }

    /// A study defined in Rust over a base model given as text (`model_file`
    /// names it in messages and result files): each grid key is a model key
    /// path, exactly as in a study file's `[grid]`, and every run's model is
    /// the base with the run's values put in and every model-file check
    /// applied. Joint kinds are flexmech's own; [`StudySpec::over_model_with`]
    /// takes a registry with a user's kinds.
    pub fn over_model(
        name: &str,
        model_file: &Path,
        model_text: &str,
        grid: Vec<(String, Vec<Value>)>,
        figures: Vec<Figure>,
    ) -> Result<StudySpec, SpecError> {
        let joints = JointRegistry::builtin();
        Self::over_model_with(name, model_file, model_text, grid, figures, &joints)
    }

    /// [`StudySpec::over_model`] with the joint kinds of `joints`.
    pub fn over_model_with(
        name: &str,
        model_file: &Path,
        model_text: &str,
        grid: Vec<(String, Vec<Value>)>,
        figures: Vec<Figure>,
        joints: &JointRegistry,
    ) -> Result<StudySpec, SpecError> {
        let file = PathBuf::from(format!("study `{name}` (defined in Rust)"));
        parse_model_with(model_text, model_file, joints).map_err(|source| SpecError::Model {
            file: file.clone(),
            source,
        })?;
        let table: Table = toml::from_str(model_text).map_err(|e| SpecError::Model {
            file: file.clone(),
            source: ModelError::new(model_file, "", None, e.message().trim().to_owned()),
        })?;
        let grid = checked(&file, name, grid, &figures, Some((model_file, &table)))?;
        Ok(StudySpec {
            text: describe(name, &grid, &figures, Some(model_file)),
            file,
            name: name.to_owned(),
            source: RunSource::ModelFile {
                file: model_file.to_path_buf(),
                table,
            },
            grid,
            figures,
            titles: true,
            joints: joints.clone(),
        })
    }
}

/// The checks of a study file on a study defined in Rust: a usable name,
/// non-empty value lists, distinct keys that parse (and, over a base model,
/// name a value present in it), distinct figure names.
fn checked(
    file: &Path,
    name: &str,
    grid: Vec<(String, Vec<Value>)>,
    figures: &[Figure],
    model: Option<(&Path, &Table)>,
) -> Result<Vec<GridKey>, SpecError> {
    let file = file.to_path_buf();
    if let Some(reason) = name_problem(name) {
        return Err(SpecError::BadName {
            file,
            line: None,
            name: name.to_owned(),
            reason,
        });
    }
    let mut keys: Vec<GridKey> = Vec::with_capacity(grid.len());
    for (key, values) in grid {
        if values.is_empty() {
            return Err(SpecError::EmptyList {
                file,
                line: None,
                key,
            });
        }
        let path = KeyPath::parse(&key).map_err(|problem| SpecError::BadKey {
            file: file.clone(),
            line: None,
            key: key.clone(),
            problem,
        })?;
        if keys.iter().any(|g| g.key == key) {
            return Err(SpecError::BadKey {
                file,
                line: None,
                key,
                problem: "is given twice; give each key once".into(),
            });
        }
        if let Some((model_file, table)) = model {
            check_key(table, &path).map_err(|problem| SpecError::UnknownModelKey {
                file: file.clone(),
                line: None,
                key: key.clone(),
                model: model_file.to_path_buf(),
                problem,
            })?;
        }
        keys.push(GridKey { key, path, values });
    }
    for (i, figure) in figures.iter().enumerate() {
        if figures[..i].iter().any(|f| f.name() == figure.name()) {
            return Err(SpecError::DuplicateFigure {
                file,
                line: None,
                name: figure.name().to_owned(),
            });
        }
    }
    Ok(keys)
}

/// The study-file-like text of a study defined in Rust (the `study`
/// attribute of its summary): name, grid and figures.
fn describe(name: &str, keys: &[GridKey], figures: &[Figure], model: Option<&Path>) -> String {
    let mut grid = Table::new();
    for g in keys {
        grid.insert(g.key.clone(), Value::Array(g.values.clone()));
    }
    let mut root = Table::new();
    root.insert("name".into(), Value::String(name.to_owned()));
    if let Some(m) = model {
        root.insert("model".into(), Value::String(m.display().to_string()));
    }
    root.insert("grid".into(), Value::Table(grid));
    let mut output = Table::new();
    output.insert(
        "figures".into(),
        Value::Array(
            figures
                .iter()
                .map(|f| Value::String(f.name().to_owned()))
                .collect(),
        ),
    );
    root.insert("output".into(), Value::Table(output));
    let body = toml::to_string(&root).unwrap_or_default();
    match model {
        Some(_) => format!("# a study defined in Rust over a base model\n{body}"),
        None => format!("# runs built by a Rust function (no base model file)\n{body}"),
    }
}
