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
            if !["name", "dataset", "component", "reduce"].contains(&key.as_str()) {
                return Err(format!(
                    "unknown key `{key}` in a dataset figure; it takes name, dataset, reduce and \
                     optionally component"
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
        Ok(Self {
            name,
            dataset,
            component,
            reduce,
        })
    }

    /// A one-line meaning, for descriptions and chart axes.
    pub fn description(&self) -> String {
        let part = match self.component {
            Component::Norm => "|·|".to_string(),
            Component::Index(i) => format!("[{i}]"),
        };
        format!("{} of {}{part}", self.reduce.name(), self.dataset)
    }

    /// Its value for the run in `result`.
    pub fn value(&self, result: &ResultReader) -> Result<f64, ReadError> {
        let steps = result.time()?.len();
        let shape = result.shape(&self.dataset)?;
        let values = result.values(&self.dataset)?;
        let column: Vec<f64> = match (shape.as_slice(), self.component) {
            ([n], _) if *n == steps => values,
            ([n, k], Component::Norm) if *n == steps && *k > 0 => values
                .chunks_exact(*k)
                .map(|r| r.iter().map(|v| v * v).sum::<f64>().sqrt())
                .collect(),
            ([n, k], Component::Index(i)) if *n == steps && i < *k => {
                values.chunks_exact(*k).map(|r| r[i]).collect()
            }
            _ => {
                return Err(ReadError::Shape {
                    path: result.path().to_path_buf(),
                    dataset: self.dataset.clone(),
                    shape,
                    expected: "T or T×k with the chosen component (T = stored steps)",
                })
            }
        };
        Ok(self.reduce.apply(&column))
    }
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
