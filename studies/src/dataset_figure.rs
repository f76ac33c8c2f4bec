//! A study figure a researcher defines: a result dataset reduced to one number
//! per run.
//!
//! ```toml
//! [output]
//! figures = [
//!     "energy_drift",
//!     { name = "tip_lift", dataset = "/nodes/arm.end/displacement", component = "z", reduce = "max-abs" },
//! ]
//! ```
//!
//! `dataset` is any result dataset with one row per stored step (T or T×k);
//! `component` picks a column of a T×k dataset (`x`, `y`, `z` or an index
//! from 0) or its Euclidean `norm` (the default for T×k); `reduce` is one of
//! `max`, `min`, `max-abs`, `mean`, `final` (the last stored step) or `initial`.
//! NaN values are left out of `max`, `min`, `max-abs` and `mean`.
//!
//! `mode = k` (instead of `reduce`) takes the `k`-th value, counted from 1,
//! of a dataset with one value per mode — `/modes/frequency`,
//! `/modes/damping_ratio`, `/buckling/load_factor` of modal and buckling
//! runs: over `solver.rotation.rate`, a Campbell diagram — or the `k`-th
//! critical point of a static path, `/stability/critical_load_factor` (NaN
//! for a run that located fewer).
//!
//! `derivative = ["section.rod.EI[0]", ...]` adds, per key path, the
//! figure's exact derivative by that model value as the summary column
//! `d(<name>)|d(<key>)`: the runs write `/sensitivity/<key>/…` (the study
//! asks each run for it) and the reduction is differentiated along — the
//! derivative at the stored step the reduction picks (`final`, `initial`,
//! `max`, `min`; `max-abs` with the sign of the value there), or the mean of
//! the derivatives; a `norm` as `u·du/|u|`. Derivatives are written for
//! `/nodes/<label>/displacement` and `/energy/total`.

use toml::Value;

use flexmech_results::{ReadError, ResultReader};

/// How the rows of a dataset become one number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reduce {
    /// Largest value.
    Max,
    /// Smallest value.
    Min,
    /// Largest absolute value.
    MaxAbs,
    /// Mean over the stored steps.
    Mean,
    /// Value at the last stored step.
    Final,
    /// Value at the first stored step.
    Initial,
}

impl Reduce {
    const ALL: [(&'static str, Reduce); 6] = [
        ("max", Reduce::Max),
        ("min", Reduce::Min),
        ("max-abs", Reduce::MaxAbs),
        ("mean", Reduce::Mean),
        ("final", Reduce::Final),
        ("initial", Reduce::Initial),
    ];

    fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, r)| *r == self)
            .map_or("?", |(n, _)| n)
    }

    /// The reduction of `values` (one per stored step).
    pub fn apply(self, values: &[f64]) -> f64 {
        let finite = || values.iter().copied().filter(|v| !v.is_nan());
        match self {
            Reduce::Max => finite().fold(f64::NAN, f64::max),
            Reduce::Min => finite().fold(f64::NAN, f64::min),
            Reduce::MaxAbs => finite().map(f64::abs).fold(f64::NAN, f64::max),
            Reduce::Mean => {
                let (sum, n) = finite().fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
                if n == 0 {
                    f64::NAN
                } else {
                    sum / n as f64
                }
            }
            Reduce::Final => values.last().copied().unwrap_or(f64::NAN),
            Reduce::Initial => values.first().copied().unwrap_or(f64::NAN),
        }
    }

    /// The derivative of [`Reduce::apply`] of `values` whose derivatives
    /// are `derivatives` (one per stored step): the derivative at the step
    /// the reduction picks, or the mean of the derivatives.
    pub fn derivative(self, values: &[f64], derivatives: &[f64]) -> f64 {
        let rows = || (0..values.len()).filter(|&i| !values[i].is_nan());
        let pick = |key: &dyn Fn(usize) -> f64| rows().max_by(|&a, &b| key(a).total_cmp(&key(b)));
        let at = match self {
            Reduce::Max => pick(&|i| values[i]),
            Reduce::Min => pick(&|i| -values[i]),
            Reduce::MaxAbs => {
                let i = pick(&|i| values[i].abs());
                return i.map_or(f64::NAN, |i| values[i].signum() * derivatives[i]);
            }
            Reduce::Mean => {
                let (sum, n) = rows().fold((0.0, 0usize), |(s, n), i| (s + derivatives[i], n + 1));
                return if n == 0 { f64::NAN } else { sum / n as f64 };
            }
            Reduce::Final => values.len().checked_sub(1),
            Reduce::Initial => (!values.is_empty()).then_some(0),
        };
        at.map_or(f64::NAN, |i| derivatives[i])
    }
}

/// Which column of a T×k dataset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Component {
    /// Column `i`.
    Index(usize),
    /// The row's Euclidean norm.
    Norm,
}

/// A figure from a dataset: `reduce(component(dataset))`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct DatasetFigure {
    /// Its name (summary column, chart file).
    pub name: String,
    /// The dataset's absolute path.
    pub dataset: String,
    /// The column of a T×k dataset (ignored for T).
    pub component: Component,
    /// The reduction over the stored steps.
    pub reduce: Reduce,
    /// Key paths of model values to write the figure's derivatives by.
    pub derivative: Vec<String>,
    /// `mode = k`: the `k`-th value (from 1, the lowest mode) of a dataset
    /// with one value per mode (`/modes/frequency`, `/buckling/load_factor`,
    /// …) instead of a reduction over the stored steps.
    pub mode: Option<usize>,
}

impl DatasetFigure {
    /// Parses `{ name, dataset, component, reduce }`; the error says what is
    /// wrong and what is expected.
    pub fn parse(value: &Value) -> Result<Self, String> {
        let Value::Table(t) = value else {
            return Err(format!(
                "expected a figure name or a table {{ name, dataset, reduce, component }}, found {value}"
            ));
        };
        for key in t.keys() {
            if ![
                "name",
                "dataset",
                "component",
                "reduce",
                "derivative",
                "mode",
            ]
            .contains(&key.as_str())
            {
                return Err(format!(
                    "unknown key `{key}` in a dataset figure; it takes name, dataset, reduce and \
                     optionally component and derivative (or mode instead of reduce)"
                ));
            }
        }
        let text = |key: &str, example: &str| -> Result<String, String> {
            match t.get(key) {
                Some(Value::String(s)) if !s.trim().is_empty() => Ok(s.clone()),
                Some(v) => Err(format!("`{key}` must be a non-empty string, found {v}")),
                None => Err(format!(
                    "a dataset figure needs `{key}`, e.g. {key} = \"{example}\""
                )),
            }
        };
        let name = text("name", "tip_lift")?;
        if name.contains(['/', '\\']) {
            return Err(format!(
                "`name` \"{name}\" names files: it must not contain '/'"
            ));
        }
        let dataset = text("dataset", "/nodes/arm.end/displacement")?;
        let dataset = format!("/{}", dataset.trim_start_matches('/'));
        if let Some(k) = mode_index(t.get("mode"))? {
            return Self::of_mode(t, name, dataset, k);
        }
        let reduce_name = text("reduce", "max-abs")?;
        let reduce = Reduce::ALL
            .iter()
            .find(|(n, _)| *n == reduce_name)
            .map(|(_, r)| *r)
            .ok_or_else(|| {
                format!(
                    "unknown reduction \"{reduce_name}\"; expected one of {}",
                    Reduce::ALL.map(|(n, _)| n).join(", ")
                )
            })?;
        let component = match t.get("component") {
            None => Component::Norm,
            Some(Value::String(s)) => match s.as_str() {
                "x" => Component::Index(0),
                "y" => Component::Index(1),
                "z" => Component::Index(2),
                "norm" => Component::Norm,
                other => {
                    return Err(format!(
                        "unknown component \"{other}\"; expected \"x\", \"y\", \"z\", \"norm\" or \
                         a column index"
                    ))
                }
            },
            Some(Value::Integer(i)) if *i >= 0 => Component::Index(*i as usize),
            Some(v) => {
                return Err(format!(
                    "`component` must be x, y, z, norm or an index, found {v}"
                ))
            }
        };
        let derivative = derivative_keys(t.get("derivative"), &dataset)?;
        Ok(Self {
            name,
            dataset,
            component,
            reduce,
            derivative,
            mode: None,
        })
    }

    /// The figure `mode = k` of `dataset` (no reduction, component or
    /// derivative with it).
    fn of_mode(
        t: &toml::map::Map<String, Value>,
        name: String,
        dataset: String,
        k: usize,
    ) -> Result<Self, String> {
        if let Some(key) = ["reduce", "component", "derivative"]
            .iter()
            .find(|key| t.contains_key(**key))
        {
            return Err(format!(
                "`mode = {k}` picks one value of a dataset with one value per mode; `{key}` \
                 does not go with it: remove `{key}`"
            ));
        }
        Ok(Self {
            name,
            dataset,
            component: Component::Index(0),
            reduce: Reduce::Final,
            derivative: Vec::new(),
            mode: Some(k),
        })
    }

    /// The summary column of the derivative by `key`: `d(<name>)|d(<key>)`.
    pub fn derivative_column(&self, key: &str) -> String {
        format!("d({})|d({key})", self.name)
    }

    /// The dataset holding the derivative of [`Self::dataset`] by `key`.
    fn derivative_dataset(&self, key: &str) -> String {
        let group = flexmech_results::layout::sensitivity_group(key);
        format!("{group}{}", self.dataset)
    }

    /// Its derivatives for the run in `result`, by each of
    /// [`Self::derivative`], with their column names.
    pub fn derivative_values(
        &self,
        result: &ResultReader,
    ) -> Result<Vec<(String, f64)>, ReadError> {
        if self.derivative.is_empty() {
            return Ok(Vec::new());
        }
        let (values, width) = self.rows(result, &self.dataset)?;
        let mut out = Vec::with_capacity(self.derivative.len());
        for key in &self.derivative {
            let (derivatives, _) = self.rows(result, &self.derivative_dataset(key))?;
            let (column, by) = match (width, self.component) {
                (0, _) => (values.clone(), derivatives),
                (k, Component::Index(i)) => (
                    values.chunks_exact(k).map(|r| r[i]).collect(),
                    derivatives.chunks_exact(k).map(|r| r[i]).collect(),
                ),
                (k, Component::Norm) => norm_and_derivative(&values, &derivatives, k),
            };
            let d = self.reduce.derivative(&column, &by);
            out.push((self.derivative_column(key), d));
        }
        Ok(out)
    }

    /// A one-line meaning, for descriptions and chart axes.
    pub fn description(&self) -> String {
        if let Some(k) = self.mode {
            return format!("mode {k} of {}", self.dataset);
        }
        let part = match self.component {
            Component::Norm => "|·|".to_string(),
            Component::Index(i) => format!("[{i}]"),
        };
        format!("{} of {}{part}", self.reduce.name(), self.dataset)
    }

    /// Its value for the run in `result`.
    pub fn value(&self, result: &ResultReader) -> Result<f64, ReadError> {
        if let Some(k) = self.mode {
            if self.dataset.starts_with(STABILITY_PREFIX) && located_fewer(result, &self.dataset, k)
            {
                return Ok(f64::NAN);
            }
            let shape = result.shape(&self.dataset)?;
            return match shape.as_slice() {
                [n] if k <= *n => Ok(result.values(&self.dataset)?[k - 1]),
                _ => Err(ReadError::Shape {
                    path: result.path().to_path_buf(),
                    dataset: self.dataset.clone(),
                    shape,
                    expected: "N, one value per mode, with the figure's mode <= N",
                }),
            };
        }
        let (values, width) = self.rows(result, &self.dataset)?;
        let column: Vec<f64> = match (width, self.component) {
            (0, _) => values,
            (k, Component::Norm) => values
                .chunks_exact(k)
                .map(|r| r.iter().map(|v| v * v).sum::<f64>().sqrt())
                .collect(),
            (k, Component::Index(i)) => values.chunks_exact(k).map(|r| r[i]).collect(),
        };
        Ok(self.reduce.apply(&column))
    }

    /// The values of `dataset` (one row per stored step) and its row width
    /// (0 for a T dataset), checked against the figure's component.
    fn rows(&self, result: &ResultReader, dataset: &str) -> Result<(Vec<f64>, usize), ReadError> {
        let steps = result.time()?.len();
        let shape = result.shape(dataset)?;
        match (shape.as_slice(), self.component) {
            ([n], _) if *n == steps => Ok((result.values(dataset)?, 0)),
            ([n, k], Component::Norm) if *n == steps && *k > 0 => Ok((result.values(dataset)?, *k)),
            ([n, k], Component::Index(i)) if *n == steps && i < *k => {
                Ok((result.values(dataset)?, *k))
            }
            _ => Err(ReadError::Shape {
                path: result.path().to_path_buf(),
                dataset: dataset.to_owned(),
                shape,
                expected: "T or T×k with the chosen component (T = stored steps)",
            }),
        }
    }
}

/// The group of a static path's located critical points: written only
/// when the path crossed one, one entry per point.
const STABILITY_PREFIX: &str = "/stability/";

/// Whether the run in `result` located fewer than `k` critical points
/// (no `/stability` at all when it crossed none): the `k`-th point's figure
/// is NaN then, as a run's is where its path stops short of it.
fn located_fewer(result: &ResultReader, dataset: &str, k: usize) -> bool {
    if !result.has(dataset) {
        return true;
    }
    matches!(result.shape(dataset).as_deref(), Ok([n]) if k > *n)
}

/// `mode = k` of a figure (from 1), if given.
fn mode_index(value: Option<&Value>) -> Result<Option<usize>, String> {
    match value {
        None => Ok(None),
        Some(Value::Integer(k)) if *k >= 1 => Ok(Some(*k as usize)),
        Some(v) => Err(format!(
            "`mode` counts the modes from 1 (the lowest), found {v}"
        )),
    }
}

/// Each row's norm `|u|` and its derivative `u·du/|u|` (0 where `u` = 0).
fn norm_and_derivative(values: &[f64], derivatives: &[f64], k: usize) -> (Vec<f64>, Vec<f64>) {
    values
        .chunks_exact(k)
        .zip(derivatives.chunks_exact(k))
        .map(|(u, du)| {
            let norm = u.iter().map(|v| v * v).sum::<f64>().sqrt();
            let dot: f64 = u.iter().zip(du).map(|(a, b)| a * b).sum();
            (norm, if norm > 0.0 { dot / norm } else { 0.0 })
        })
        .unzip()
}

/// The `derivative` key paths of a figure over `dataset`; the error says
/// what is wrong.
fn derivative_keys(value: Option<&Value>, dataset: &str) -> Result<Vec<String>, String> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    let keys: Vec<String> = match value {
        Value::Array(a) => a
            .iter()
            .map(|v| match v {
                Value::String(s) => Ok(s.clone()),
                other => Err(format!(
                    "`derivative` lists key paths as strings, found {other}"
                )),
            })
            .collect::<Result<_, _>>()?,
        other => {
            return Err(format!(
            "`derivative` must be a list of key paths, e.g. derivative = [\"section.rod.EI[0]\"], \
                 found {other}"
        ))
        }
    };
    let parts: Vec<&str> = dataset.split('/').collect();
    let derivable = matches!(parts.as_slice(), ["", "nodes", _, "displacement"])
        || dataset == flexmech_results::layout::ENERGY_TOTAL;
    if !keys.is_empty() && !derivable {
        return Err(format!(
            "derivatives are written for /nodes/<label>/displacement and /energy/total, not for \
             {dataset}"
        ));
    }
    for key in &keys {
        flexmech_model::key_path::KeyPath::parse(key)
            .map_err(|why| format!("`derivative` key \"{key}\" {why}"))?;
    }
    Ok(keys)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reductions() {
        let v = [1.0, -3.0, f64::NAN, 2.0];
        assert_eq!(Reduce::Max.apply(&v), 2.0);
        assert_eq!(Reduce::Min.apply(&v), -3.0);
        assert_eq!(Reduce::MaxAbs.apply(&v), 3.0);
        assert_eq!(Reduce::Mean.apply(&v), 0.0);
        assert_eq!(Reduce::Final.apply(&v), 2.0);
        assert_eq!(Reduce::Initial.apply(&v), 1.0);
        assert!(Reduce::Max.apply(&[]).is_nan());
    }

    #[test]
    fn parsing_names_what_is_wrong() {
        let t = |s: &str| -> Value { toml::from_str::<toml::Table>(s).unwrap().into() };
        let f = DatasetFigure::parse(&t(
            "name = \"lift\"\ndataset = \"nodes/a.end/position\"\ncomponent = \"z\"\nreduce = \"final\"",
        ))
        .unwrap();
        assert_eq!(f.dataset, "/nodes/a.end/position");
        assert_eq!(
            (f.component, f.reduce),
            (Component::Index(2), Reduce::Final)
        );
        let e = DatasetFigure::parse(&t("name = \"a\"\ndataset = \"/time\"\nreduce = \"median\""))
            .unwrap_err();
        assert!(e.contains("median") && e.contains("max-abs"), "{e}");
        let e = DatasetFigure::parse(&t("name = \"a\"\nreduce = \"max\"")).unwrap_err();
        assert!(e.contains("`dataset`"), "{e}");
        let e = DatasetFigure::parse(&t(
            "name = \"a\"\ndataset = \"/time\"\nreduce = \"max\"\nscale = 2",
        ))
        .unwrap_err();
        assert!(e.contains("`scale`"), "{e}");
    }
}
