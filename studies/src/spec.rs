//! Reading a study file (`STUDY.toml`) into a checked [`StudySpec`].
//!
//! Everything that can be checked before a run starts is checked here: the
//! study's own keys, the base model (loaded with every model-file check), the
//! syntax of each grid key and that it names a value present in the base
//! model. Each problem is a [`SpecError`] naming the study file, the line
//! where known, the key and the fix.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use toml::{Table, Value};

use super::dataset_figure::DatasetFigure;
use super::key_path::{check_key, KeyPath};
use flexmech_model::{load_model_with, JointRegistry, Model, ModelError};

/// A per-run scalar of the summary table (see the module docs of
/// [`crate`] for the definitions).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Figure {
    /// `energy_drift`: [`flexmech_results::reader::energy_drift`].
    EnergyDrift,
    /// `max_displacement`: largest displacement of any tracked node.
    MaxDisplacement,
    /// `failure_time`: last stored time of a failed run, NaN otherwise.
    FailureTime,
    /// `wall_time`: the run's `wall_time_s`.
    WallTime,
    /// `newton_iterations`: total Newton iterations.
    NewtonIterations,
    /// A researcher's own: a dataset reduced to one number per run.
    Dataset(DatasetFigure),
}

impl Figure {
    /// Every figure, in the default order.
    pub const ALL: [Figure; 5] = [
        Figure::EnergyDrift,
        Figure::MaxDisplacement,
        Figure::FailureTime,
        Figure::WallTime,
        Figure::NewtonIterations,
    ];

    /// The name used in study files, summary columns and chart files.
    pub fn name(&self) -> &str {
        match self {
            Figure::Dataset(d) => &d.name,
            Figure::EnergyDrift => "energy_drift",
            Figure::MaxDisplacement => "max_displacement",
            Figure::FailureTime => "failure_time",
            Figure::WallTime => "wall_time",
            Figure::NewtonIterations => "newton_iterations",
        }
    }

    /// The summary columns of its derivatives (`d(<name>)|d(<key>)`), with
    /// their keys.
    pub fn derivative_columns(&self) -> Vec<(String, &str)> {
        match self {
            Figure::Dataset(d) => (d.derivative.iter())
                .map(|k| (d.derivative_column(k), k.as_str()))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// The figure called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The label of a summary chart's y axis.
    pub fn axis_label(&self) -> String {
        let label = match self {
            Figure::Dataset(d) => return d.description(),
            Figure::EnergyDrift => "relative energy drift",
            Figure::MaxDisplacement => "largest displacement",
            Figure::FailureTime => "failure time",
            Figure::WallTime => "wall time (s)",
            Figure::NewtonIterations => "Newton iterations",
        };
        label.to_string()
    }

    /// A one-line meaning, for HDF5 descriptions.
    pub fn description(&self) -> String {
        let text = match self {
            Figure::Dataset(d) => return d.description(),
            Figure::EnergyDrift => {
                "relative energy drift max|B-B0|/max(|E0|,max|W|,K0+U0), B = E - W (drivers' work)"
            }
            Figure::MaxDisplacement => "largest tracked-node displacement",
            Figure::FailureTime => "time of the last stored step of a failed run",
            Figure::WallTime => "wall time of the solve (s)",
            Figure::NewtonIterations => "total Newton iterations",
        };
        text.to_string()
    }
}

impl Figure {
    /// A figure of a result dataset, as a study file's
    /// `{ name, dataset, component, reduce }` table: `dataset` is a path,
    /// with a column `[x]`, `[y]`, `[z]`, `[k]` or `[norm]` where it has
    /// several (the norm when none is given), `reduce` one of `max`, `min`,
    /// `max-abs`, `mean`, `final`, `initial`. The error says what is wrong.
    ///
    /// ```
    /// use flexmech_studies::Figure;
    /// let lift = Figure::dataset("lift", "/nodes/arm.end/displacement[z]", "max-abs")?;
    /// assert_eq!(lift.name(), "lift");
    /// # Ok::<(), String>(())
    /// ```
    pub fn dataset(name: &str, dataset: &str, reduce: &str) -> Result<Self, String> {
        let mut t = toml::Table::new();
        let (path, column) = match dataset.split_once('[') {
            Some((path, rest)) => (path, rest.strip_suffix(']')),
            None => (dataset, None),
        };
        t.insert("name".into(), name.into());
        t.insert("dataset".into(), path.into());
        t.insert("reduce".into(), reduce.into());
        if let Some(c) = column {
            let c = c.trim();
            let value = c.parse::<i64>().map_or_else(|_| c.into(), Value::Integer);
            t.insert("component".into(), value);
        }
        DatasetFigure::parse(&Value::Table(t)).map(Self::Dataset)
    }
}

/// One swept key of `[grid]`.
#[derive(Debug, Clone, PartialEq)]
pub struct GridKey {
    /// The key as written, e.g. `joint.screw.pitch`.
    pub key: String,
    /// The parsed key.
    pub path: KeyPath,
    /// The values to try, in the order written (at least one).
    pub values: Vec<Value>,
}

impl GridKey {
    /// Whether every value is an integer or a float.
    pub fn is_numeric(&self) -> bool {
        self.values
            .iter()
            .all(|v| matches!(v, Value::Integer(_) | Value::Float(_)))
    }
}

/// The signature of a run-building function: the run's parameters to its
/// model, or a message saying why these values give no model.
pub type BuildFn = dyn Fn(&RunParams<'_>) -> Result<Model, String> + Send + Sync;

/// A shared run-building function (compared by identity).
#[derive(Clone)]
pub struct ModelFn(pub Arc<BuildFn>);

impl fmt::Debug for ModelFn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ModelFn(<Rust function>)")
    }
}

impl PartialEq for ModelFn {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Where the runs of a study come from.
#[derive(Debug, Clone, PartialEq)]
pub enum RunSource {
    /// A base model file: each run puts its grid values at their keys
    /// ([`super::key_path`]) and loads the result with every model-file
    /// check.
    ModelFile {
        /// The base model file (the study file's `model`, resolved against
        /// the study file's directory).
        file: PathBuf,
        /// The base model, parsed as TOML.
        table: Table,
    },
    /// A Rust function from a run's parameters to its model
    /// ([`StudySpec::from_fn`]).
    Function(ModelFn),
}

/// The parameters of one run of a study defined in Rust: each grid key with
/// the run's value.
#[derive(Debug, Clone, Copy)]
pub struct RunParams<'a> {
    /// The run id (`run-0003`).
    pub run: &'a str,
    pub(crate) keys: &'a [GridKey],
    pub(crate) values: &'a [Value],
}

impl<'a> RunParams<'a> {
    /// The value of grid key `key`, if the study has that key.
    pub fn get(&self, key: &str) -> Option<&'a Value> {
        self.keys
            .iter()
            .position(|g| g.key == key)
            .map(|i| &self.values[i])
    }

    /// `(key, value)` of every grid key, in grid order.
    pub fn iter(&self) -> impl Iterator<Item = (&'a str, &'a Value)> + 'a {
        let keys = self.keys;
        keys.iter().map(|g| g.key.as_str()).zip(self.values.iter())
    }

    fn value(&self, key: &str) -> Result<&'a Value, String> {
        self.get(key).ok_or_else(|| {
            let known: Vec<&str> = self.keys.iter().map(|g| g.key.as_str()).collect();
            format!(
                "the function asks for parameter `{key}`, which is not a grid key (the grid has {})",
                if known.is_empty() {
                    "no keys".to_string()
                } else {
                    known.join(", ")
                }
            )
        })
    }

    /// The number at `key` (an integer value is converted).
    pub fn f64(&self, key: &str) -> Result<f64, String> {
        match self.value(key)? {
            Value::Float(x) => Ok(*x),
            Value::Integer(i) => Ok(*i as f64),
            other => Err(format!("parameter `{key}` = {other} is not a number")),
        }
    }

    /// The non-negative integer at `key`.
    pub fn usize(&self, key: &str) -> Result<usize, String> {
        match self.value(key)? {
            Value::Integer(i) if *i >= 0 => Ok(*i as usize),
            other => Err(format!(
                "parameter `{key}` = {other} is not a non-negative integer"
            )),
        }
    }

    /// The string at `key`.
    pub fn str(&self, key: &str) -> Result<&'a str, String> {
        match self.value(key)? {
            Value::String(s) => Ok(s),
            other => Err(format!("parameter `{key}` = {other} is not a string")),
        }
    }
}

/// A checked study: a study file, or a study defined in Rust
/// ([`StudySpec::from_fn`], [`StudySpec::over_model`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StudySpec {
    /// The study file (for a study defined in Rust, a description naming
    /// it, used in messages).
    pub file: PathBuf,
    /// Its text (stored as the `study` attribute of the summary HDF5; for a
    /// study defined in Rust, its name, grid and figures as TOML).
    pub text: String,
    /// The study name; results go to `<out>/<name>/`.
    pub name: String,
    /// Where each run's model comes from: the base model file (a study
    /// file's `model`) or a Rust function ([`StudySpec::from_fn`]).
    pub source: RunSource,
    /// The swept keys, in the order written in `[grid]`.
    pub grid: Vec<GridKey>,
    /// The summary figures, in the order written.
    pub figures: Vec<Figure>,
    /// Titles inside the summary charts (`[output] titles = false`: none,
    /// for papers whose captions carry them).
    pub titles: bool,
    /// The joint kinds the runs' models are read with.
    pub joints: JointRegistry,
}

/// Why a study file was rejected.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error("{}: cannot read the study file: {source}", .file.display())]
    Read {
        /// The study file.
        file: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("{}{}: not valid TOML: {message}", .file.display(), at(.line))]
    Syntax {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A required key is missing.
    #[error("{}: missing key `{key}`; add it, e.g. {example}", .file.display())]
    Missing {
        /// The study file.
        file: PathBuf,
        /// The key.
        key: &'static str,
        /// A line to add.
        example: &'static str,
    },
    /// A key has a value of the wrong type.
    #[error("{}{}: key `{key}`: expected {expected}, found {found}", .file.display(), at(.line))]
    WrongType {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The key.
        key: String,
        /// What is expected.
        expected: &'static str,
        /// What was found.
        found: String,
    },
    /// A key the study format does not have (a typo, say).
    #[error(
        "{}{}: unknown key `{key}`; allowed here: {allowed} (swept model keys go in [grid])",
        .file.display(),
        at(.line)
    )]
    UnknownKey {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The key.
        key: String,
        /// The keys allowed at that level.
        allowed: &'static str,
    },
    /// The study name cannot be a directory name.
    #[error(
        "{}{}: key `name`: \"{name}\" {reason}; use a plain directory name such as \"pitch-dt\"",
        .file.display(),
        at(.line)
    )]
    BadName {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The name given.
        name: String,
        /// Why it is not usable.
        reason: &'static str,
    },
    /// A grid key has no values.
    #[error(
        "{}{}: key `grid.\"{key}\"`: the list of values is empty; give at least one, e.g. [0.01]",
        .file.display(),
        at(.line)
    )]
    EmptyList {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The grid key.
        key: String,
    },
    /// A grid key's syntax is wrong.
    #[error(
        "{}{}: grid key `{key}` {problem}; keys look like solver.dt, joint.screw.pitch or beam[0].elements",
        .file.display(),
        at(.line)
    )]
    BadKey {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The grid key.
        key: String,
        /// What is wrong.
        problem: String,
    },
    /// A grid key does not name a value of the base model.
    #[error(
        "{}{}: grid key `{key}` does not exist in the base model {}: {problem}; fix the key in \
         [grid] (a swept key must be present in the model file: write an optional key's \
         default there to sweep it)",
        .file.display(),
        at(.line),
        .model.display()
    )]
    UnknownModelKey {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The grid key.
        key: String,
        /// The base model file.
        model: PathBuf,
        /// What exists instead.
        problem: String,
    },
    /// An unknown figure name in `output.figures`.
    #[error(
        "{}{}: key `output.figures`: unknown figure \"{name}\"; known: {}",
        .file.display(),
        at(.line),
        known_figures()
    )]
    UnknownFigure {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The name given.
        name: String,
    },
    /// A dataset figure that does not parse.
    #[error("{}{}: key `output.figures`: {why}", .file.display(), at(.line))]
    BadFigure {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// What is wrong.
        why: String,
    },
    /// A figure listed twice in `output.figures`.
    #[error(
        "{}{}: key `output.figures`: \"{name}\" is listed twice; list each figure once",
        .file.display(),
        at(.line)
    )]
    DuplicateFigure {
        /// The study file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The figure.
        name: String,
    },
    /// The base model could not be loaded.
    #[error("{}: key `model`: the base model does not load: {source}", .file.display())]
    Model {
        /// The study file.
        file: PathBuf,
        /// The model's own error (file, key, line).
        source: ModelError,
    },
}

fn at(line: &Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

fn known_figures() -> String {
    let names: Vec<&str> = Figure::ALL.iter().map(Figure::name).collect();
    format!(
        "{}, or a table {{ name, dataset, reduce, component }} reducing a result dataset",
        names.join(", ")
    )
}

/// Short description of a TOML value's type and value, for messages.
fn found(v: &Value) -> String {
    let kind = match v {
        Value::String(_) => "string",
        Value::Integer(_) => "integer",
        Value::Float(_) => "float",
        Value::Boolean(_) => "boolean",
        Value::Datetime(_) => "datetime",
        Value::Array(_) => "array",
        Value::Table(_) => "table",
    };
    let text = v.to_string();
    if text.len() > 60 {
        format!("a {kind}")
    } else {
        format!("{kind} {text}")
    }
}

/// 1-based line numbers of the study file's keys, from the spans of the
/// parser (top-level keys as `key`, sub-table keys as `table.key`), and the
/// order of the `[grid]` keys.
struct Lines {
    text_lines: Vec<usize>,
    keys: Vec<(String, usize)>,
    grid_order: Vec<String>,
}

impl Lines {
    fn new(text: &str, root: &toml::de::DeTable<'_>) -> Self {
        let text_lines = text
            .char_indices()
            .filter(|(_, c)| *c == '\n')
            .map(|(i, _)| i)
            .collect();
        let mut lines = Self {
            text_lines,
            keys: Vec::new(),
            grid_order: Vec::new(),
        };
        for (k, v) in root.iter() {
            let name = k.get_ref().to_string();
            let line = lines.line_of(k.span().start);
            lines.keys.push((name.clone(), line));
            if let toml::de::DeValue::Table(t) = v.get_ref() {
                let mut sub: Vec<(String, usize)> = t
                    .iter()
                    .map(|(kk, _)| (kk.get_ref().to_string(), kk.span().start))
                    .collect();
                sub.sort_by_key(|(_, start)| *start);
                for (kk, start) in sub {
                    let line = lines.line_of(start);
                    if name == "grid" {
                        lines.grid_order.push(kk.clone());
                    }
                    lines.keys.push((format!("{name}.{kk}"), line));
                }
            }
        }
        lines
    }

    fn line_of(&self, offset: usize) -> usize {
        self.text_lines.partition_point(|&nl| nl < offset) + 1
    }

    fn get(&self, key: &str) -> Option<usize> {
        self.keys.iter().find(|(k, _)| k == key).map(|(_, l)| *l)
    }
}

/// Reads and checks the study file at `path` and the base model it names,
/// with flexmech's own joint kinds.
pub fn load_study(path: &Path) -> Result<StudySpec, SpecError> {
    load_study_with(path, &JointRegistry::builtin())
}

/// [`load_study`] with the joint kinds of `joints` (a user's kinds
/// included).
pub fn load_study_with(path: &Path, joints: &JointRegistry) -> Result<StudySpec, SpecError> {
    let text = std::fs::read_to_string(path).map_err(|source| SpecError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    parse_study_with(&text, path, joints)
}

/// Checks study-file `text`; `path` is the study file (for messages and for
/// resolving `model`). Joint kinds are flexmech's own.
pub fn parse_study(text: &str, path: &Path) -> Result<StudySpec, SpecError> {
    parse_study_with(text, path, &JointRegistry::builtin())
}

/// [`parse_study`] with the joint kinds of `joints`.
pub fn parse_study_with(
    text: &str,
    path: &Path,
    joints: &JointRegistry,
) -> Result<StudySpec, SpecError> {
    let file = path.to_path_buf();
    let (root, lines) = parse_root(text, &file)?;
    let study = StudyFile {
        file: &file,
        lines: &lines,
    };
    study.check_top_keys(&root)?;
    let name = study.name(&root)?;
    let (model_file, model_table) = study.base_model(&root, path, joints)?;
    let grid = study.grid(&root, &model_file, &model_table)?;
    let (figures, titles) = study.output(&root)?;
    Ok(StudySpec {
        file,
        text: text.to_owned(),
        name,
        source: RunSource::ModelFile {
            file: model_file,
            table: model_table,
        },
        grid,
        figures,
        titles,
        joints: joints.clone(),
    })
}

/// Study-file `text` as a TOML table, with the lines of its keys; a syntax
/// error names `file` and, where the parser knows it, the line.
fn parse_root(text: &str, file: &Path) -> Result<(Table, Lines), SpecError> {
    let de = toml::de::DeTable::parse(text).map_err(|e| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        SpecError::Syntax {
            file: file.to_path_buf(),
            line,
            message: e.message().trim().to_owned(),
        }
    })?;
    let lines = Lines::new(text, de.get_ref());
    let root: Table = toml::from_str(text).map_err(|e| SpecError::Syntax {
        file: file.to_path_buf(),
        line: None,
        message: e.message().trim().to_owned(),
    })?;
    Ok((root, lines))
}

/// A `model` line, for the message of a study file without one.
const MODEL_EXAMPLE: &str =
    "model = \"../dynamics/spinning_beam.toml\" (relative to the study file)";

/// What a grid key holds, for the message of one that holds something else.
const GRID_VALUES: &str = "a list of values, e.g. \"solver.dt\" = [0.02, 0.01] (quote dotted keys)";

/// The study file being read: its path and key lines, for the errors of
/// each part of it.
struct StudyFile<'a> {
    file: &'a Path,
    lines: &'a Lines,
}

impl StudyFile<'_> {
    /// Key `key` holds `v`, which is not `expected`.
    fn wrong_type(&self, key: &str, expected: &'static str, v: &Value) -> SpecError {
        SpecError::WrongType {
            file: self.file.to_path_buf(),
            line: self.lines.get(key),
            key: key.to_owned(),
            expected,
            found: found(v),
        }
    }

    /// Refuses a top-level key other than `name`, `model`, `[grid]` and
    /// `[output]`.
    fn check_top_keys(&self, root: &Table) -> Result<(), SpecError> {
        for key in root.keys() {
            if !matches!(key.as_str(), "name" | "model" | "grid" | "output") {
                return Err(SpecError::UnknownKey {
                    file: self.file.to_path_buf(),
                    line: self.lines.get(key),
                    key: key.clone(),
                    allowed: "name, model, [grid], [output]",
                });
            }
        }
        Ok(())
    }

    /// `name`: the study's name, which must name its output directory.
    fn name(&self, root: &Table) -> Result<String, SpecError> {
        let name = match root.get("name") {
            None => {
                return Err(SpecError::Missing {
                    file: self.file.to_path_buf(),
                    key: "name",
                    example: "name = \"pitch-dt\" (results go to <out>/<name>/)",
                })
            }
            Some(Value::String(s)) => s.clone(),
            Some(v) => return Err(self.wrong_type("name", "a string", v)),
        };
        if let Some(reason) = name_problem(&name) {
            return Err(SpecError::BadName {
                file: self.file.to_path_buf(),
                line: self.lines.get("name"),
                name,
                reason,
            });
        }
        Ok(name)
    }

    /// `model`: the base model file (resolved against the study file's
    /// directory `path`), loaded with every model-file check, and its text
    /// as a plain TOML table.
    fn base_model(
        &self,
        root: &Table,
        path: &Path,
        joints: &JointRegistry,
    ) -> Result<(PathBuf, Table), SpecError> {
        let file = self.file.to_path_buf();
        let model_rel = match root.get("model") {
            None => {
                return Err(SpecError::Missing {
                    file,
                    key: "model",
                    example: MODEL_EXAMPLE,
                })
            }
            Some(Value::String(s)) => PathBuf::from(s),
            Some(v) => return Err(self.wrong_type("model", "a string (a path)", v)),
        };
        let model_file = if model_rel.is_absolute() {
            model_rel
        } else {
            base_dir(path).join(model_rel)
        };
        load_model_with(&model_file, joints).map_err(|source| SpecError::Model {
            file: file.clone(),
            source,
        })?;
        // load_model read and parsed it; read it again as a plain TOML table.
        let model_text = std::fs::read_to_string(&model_file).map_err(|e| SpecError::Model {
            file: file.clone(),
            source: ModelError::new(&model_file, "", None, format!("cannot read: {e}")),
        })?;
        let model_table: Table = toml::from_str(&model_text).map_err(|e| SpecError::Model {
            file: file.clone(),
            source: ModelError::new(&model_file, "", None, e.message().trim().to_owned()),
        })?;
        Ok((model_file, model_table))
    }

    /// `[grid]`: the swept keys in the order written, each a list of values
    /// at a key present in the base model `model_table` (`model_file`).
    fn grid(
        &self,
        root: &Table,
        model_file: &Path,
        model_table: &Table,
    ) -> Result<Vec<GridKey>, SpecError> {
        let t = match root.get("grid") {
            None => return Ok(Vec::new()),
            Some(Value::Table(t)) => t,
            Some(v) => return Err(self.wrong_type("grid", "a table ([grid])", v)),
        };
        let mut grid = Vec::new();
        for key in &self.lines.grid_order {
            let Some(v) = t.get(key) else { continue };
            grid.push(self.grid_key(key, v, model_file, model_table)?);
        }
        Ok(grid)
    }

    /// Grid key `key` with its values `v`, checked against the base model.
    fn grid_key(
        &self,
        key: &str,
        v: &Value,
        model_file: &Path,
        model_table: &Table,
    ) -> Result<GridKey, SpecError> {
        let file = self.file.to_path_buf();
        let line = self.lines.get(&format!("grid.{key}"));
        let values = match v {
            Value::Array(a) => a.clone(),
            other => {
                return Err(SpecError::WrongType {
                    file,
                    line,
                    key: format!("grid.\"{key}\""),
                    expected: GRID_VALUES,
                    found: found(other),
                })
            }
        };
        if values.is_empty() {
            return Err(SpecError::EmptyList {
                file,
                line,
                key: key.to_owned(),
            });
        }
        let path = KeyPath::parse(key).map_err(|problem| SpecError::BadKey {
            file: file.clone(),
            line,
            key: key.to_owned(),
            problem,
        })?;
        check_key(model_table, &path).map_err(|problem| SpecError::UnknownModelKey {
            file: file.clone(),
            line,
            key: key.to_owned(),
            model: model_file.to_path_buf(),
            problem,
        })?;
        Ok(GridKey {
            key: key.to_owned(),
            path,
            values,
        })
    }

    /// `[output]`: the summary figures (every one by default) and whether
    /// the summary charts have titles.
    fn output(&self, root: &Table) -> Result<(Vec<Figure>, bool), SpecError> {
        let mut figures = Figure::ALL.to_vec();
        let mut titles = true;
        let t = match root.get("output") {
            None => return Ok((figures, titles)),
            Some(Value::Table(t)) => t,
            Some(v) => return Err(self.wrong_type("output", "a table ([output])", v)),
        };
        for key in t.keys() {
            if key != "figures" && key != "titles" {
                return Err(SpecError::UnknownKey {
                    file: self.file.to_path_buf(),
                    line: self.lines.get(&format!("output.{key}")),
                    key: format!("output.{key}"),
                    allowed: "output.figures, output.titles",
                });
            }
        }
        match t.get("titles") {
            None => {}
            Some(Value::Boolean(b)) => titles = *b,
            Some(v) => return Err(self.wrong_type("output.titles", "true or false", v)),
        }
        if let Some(v) = t.get("figures") {
            figures = self.figures(v)?;
        }
        Ok((figures, titles))
    }

    /// `output.figures`: a list of figure names and dataset-figure tables,
    /// each figure once.
    fn figures(&self, v: &Value) -> Result<Vec<Figure>, SpecError> {
        let line = self.lines.get("output.figures");
        let Value::Array(names) = v else {
            return Err(self.wrong_type("output.figures", "a list of figure names", v));
        };
        let mut figures = Vec::new();
        for n in names {
            let figure = match n {
                Value::String(s) => {
                    Figure::from_name(s).ok_or_else(|| SpecError::UnknownFigure {
                        file: self.file.to_path_buf(),
                        line,
                        name: s.clone(),
                    })?
                }
                other => Figure::Dataset(DatasetFigure::parse(other).map_err(|why| {
                    SpecError::BadFigure {
                        file: self.file.to_path_buf(),
                        line,
                        why,
                    }
                })?),
            };
            if figures.iter().any(|f: &Figure| f.name() == figure.name()) {
                return Err(SpecError::DuplicateFigure {
                    file: self.file.to_path_buf(),
                    line,
                    name: figure.name().to_string(),
                });
            }
            figures.push(figure);
        }
        Ok(figures)
    }
}

/// Why `name` cannot name a study's output directory, if it cannot.
pub(crate) fn name_problem(name: &str) -> Option<&'static str> {
    if name.trim().is_empty() {
        Some("is empty")
    } else if name == "." || name == ".." {
        Some("names a directory that is not the study's own")
    } else if name.contains(['/', '\\', '\0']) {
        Some("contains a path separator")
    } else {
        None
    }
}

impl fmt::Display for Figure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The directory of a study file, for resolving the model path.
pub(crate) fn base_dir(study: &Path) -> &Path {
    study
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}
