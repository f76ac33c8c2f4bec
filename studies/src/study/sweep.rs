//! From a grid to runs: the cartesian product of the swept values, and the
//! model-file text of each run (the base model with the run's values put at
//! their keys).
//!
//! A key is a dotted path into the model TOML. A segment names a table key;
//! `name[i]` takes entry `i` (from 0) of the array `name`; a segment after an
//! array of tables picks the entry whose `name` field equals it
//! (`joint.screw.pitch`). A segment may be double-quoted to hold dots
//! (`joint."arm.pin".pitch`).

use std::fmt;
use std::path::{Path, PathBuf};

use toml::{Table, Value};

use super::spec::StudySpec;
use crate::model::{parse_model, Model};

/// One step of a [`KeyPath`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    /// A table key, or the `name` of an entry of an array of tables.
    Key(String),
    /// An array index, from 0.
    Index(usize),
}

/// A parsed grid key such as `joint.screw.pitch` or `beam[0].elements`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath {
    /// The segments, in order.
    pub segments: Vec<Segment>,
}

impl KeyPath {
    /// Parses `key`; the error says what is wrong with its syntax.
    pub fn parse(key: &str) -> Result<Self, String> {
        let mut segments = Vec::new();
        let mut rest = key;
        loop {
            // One segment: a bare or quoted name, then any number of [i].
            let name;
            if let Some(quoted) = rest.strip_prefix('"') {
                let end = quoted
                    .find('"')
                    .ok_or_else(|| "has an unclosed '\"'".to_owned())?;
                name = &quoted[..end];
                rest = &quoted[end + 1..];
            } else {
                let end = rest.find(['.', '[']).unwrap_or(rest.len());
                name = &rest[..end];
                rest = &rest[end..];
            }
            if name.is_empty() {
                return Err("has an empty segment (write keys as a.b.c or name[0].c)".into());
            }
            segments.push(Segment::Key(name.to_owned()));
            while let Some(inner) = rest.strip_prefix('[') {
                let end = inner
                    .find(']')
                    .ok_or_else(|| "has an unclosed '['".to_owned())?;
                let index = inner[..end].trim();
                let i = index
                    .parse::<usize>()
                    .ok()
                    .filter(|_| index.bytes().all(|b| b.is_ascii_digit()))
                    .ok_or_else(|| format!("has index [{index}], expected a whole number"))?;
                segments.push(Segment::Index(i));
                rest = &inner[end + 1..];
            }
            if rest.is_empty() {
                return Ok(Self { segments });
            }
            rest = rest
                .strip_prefix('.')
                .ok_or_else(|| format!("has \"{rest}\" after a segment, expected '.' or '['"))?;
        }
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.segments.iter().enumerate() {
            match s {
                Segment::Key(k) => {
                    if i > 0 {
                        write!(f, ".")?;
                    }
                    if k.contains(['.', '[', ']']) {
                        write!(f, "\"{k}\"")?;
                    } else {
                        write!(f, "{k}")?;
                    }
                }
                Segment::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a float",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a datetime",
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table) => "an array of tables",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

fn list(items: impl IntoIterator<Item = String>) -> String {
    let items: Vec<String> = items.into_iter().collect();
    if items.is_empty() {
        "(none)".into()
    } else {
        items.join(", ")
    }
}

/// Finds the value `path` addresses in `root`. The error describes the first
/// segment that does not exist and what exists there instead.
pub fn lookup_mut<'a>(root: &'a mut Table, path: &KeyPath) -> Result<&'a mut Value, String> {
    let mut prefix = String::new();
    let (first, rest) = match path.segments.split_first() {
        Some((Segment::Key(k), rest)) => (k, rest),
        _ => return Err("is empty".into()),
    };
    let keys: Vec<String> = root.keys().cloned().collect();
    let mut current = root.get_mut(first).ok_or_else(|| {
        format!(
            "the model has no top-level key `{first}`; it has: {}",
            list(keys)
        )
    })?;
    prefix.push_str(first);
    for segment in rest {
        current = match (segment, current) {
            (Segment::Key(k), Value::Table(t)) => {
                let keys: Vec<String> = t.keys().cloned().collect();
                let next = t.get_mut(k).ok_or_else(|| {
                    format!(
                        "the model has no key `{prefix}.{k}`; keys in `{prefix}`: {}",
                        list(keys)
                    )
                })?;
                prefix = format!("{prefix}.{k}");
                next
            }
            (Segment::Key(k), Value::Array(entries)) => {
                let names: Vec<Option<&str>> = entries
                    .iter()
                    .map(|e| e.get("name").and_then(Value::as_str))
                    .collect();
                let hits: Vec<usize> = (0..names.len())
                    .filter(|&i| names[i] == Some(k.as_str()))
                    .collect();
                match hits.as_slice() {
                    [i] => {
                        prefix = format!("{prefix}.{k}");
                        &mut entries[*i]
                    }
                    [] => {
                        let existing = names.iter().flatten().map(|n| format!("\"{n}\""));
                        return Err(format!(
                            "the model has no [[{prefix}]] entry named \"{k}\"; entries: {} \
                             (or address one by position, {prefix}[0] to {prefix}[{}])",
                            list(existing),
                            names.len().saturating_sub(1)
                        ));
                    }
                    _ => {
                        return Err(format!(
                            "several [[{prefix}]] entries are named \"{k}\"; address one by \
                             position, e.g. {prefix}[{}]",
                            hits[0]
                        ))
                    }
                }
            }
            (Segment::Index(i), Value::Array(entries)) => {
                let n = entries.len();
                let next = entries.get_mut(*i).ok_or_else(|| {
                    format!(
                        "`{prefix}` has {n} entries, so [{i}] does not exist (indices count from 0)"
                    )
                })?;
                prefix = format!("{prefix}[{i}]");
                next
            }
            (Segment::Key(k), other) => {
                return Err(format!(
                    "`{prefix}` is {}, so it has no key `{k}`",
                    type_name(other)
                ))
            }
            (Segment::Index(i), other) => {
                return Err(format!(
                    "`{prefix}` is {}, not an array, so [{i}] does not exist",
                    type_name(other)
                ))
            }
        };
    }
    if current.is_table()
        || matches!(current, Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table))
    {
        return Err(format!(
            "`{prefix}` is {}; a grid key must name a single value inside it",
            type_name(current)
        ));
    }
    Ok(current)
}

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

/// The model-file text of `plan`: the base model with each grid key set to
/// the run's value, serialized back to TOML.
pub fn model_text(spec: &StudySpec, plan: &RunPlan) -> Result<String, SweepError> {
    let mut table = spec.model_table.clone();
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

/// The validated model of `plan` (see [`model_text`]): every model-file check
/// applies to the overridden text.
pub fn model_for(spec: &StudySpec, plan: &RunPlan) -> Result<Model, SweepError> {
    let text = model_text(spec, plan)?;
    parse_model(&text, &spec.model_file).map_err(|e| {
        SweepError::InvalidRun(Box::new(InvalidRun {
            study: spec.file.clone(),
            run: plan.id.clone(),
            overrides: describe_values(spec, plan),
            model: spec.model_file.clone(),
            key: e.key().to_owned(),
            message: e.message().to_owned(),
        }))
    })
}

/// Checks that `path` addresses a value of the model table `model`; the
/// error says what exists instead.
pub fn check_key(model: &Table, path: &KeyPath) -> Result<(), String> {
    let mut copy = model.clone();
    lookup_mut(&mut copy, path).map(|_| ())
}

/// The directory of a study file, for resolving the model path.
pub(crate) fn base_dir(study: &Path) -> &Path {
    study
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}
