//! The table of the paper's node-path figures,
//! `data/paper/charts/charts.toml`: for each figure, the example, the
//! dataset column it draws over time, the chart's file name, title and y
//! label, and how a blown-up run is cut and which curve carries markers.
//! [`super::charts`] draws them.
//!
//! The table is compiled into the program with the model files
//! ([`PAPER_CHARTS`]) and read when a reproduction starts; a malformed entry
//! is a [`ReproduceError::ChartTable`] naming the file, the line and the key
//! (e.g. `chart[1].component`). It sits in a directory of its own: every
//! `.toml` directly in `data/paper/` is a model file.

use super::{ReproduceError, INTEGRATORS, PAPER_MODELS};
use std::path::PathBuf;
use toml::{Table, Value};

/// The chart table: `(path in the repository, text)`.
pub const PAPER_CHARTS: (&str, &str) = (
    "data/paper/charts/charts.toml",
    include_str!("../../../data/paper/charts/charts.toml"),
);

/// The keys of a `[[chart]]` entry.
const CHART_KEYS: &str =
    "name, model, dataset, component, title, y_label, cut_at_energy_error, markers";

/// One figure of the table: a column of a `T×3` dataset of one example's
/// result files over time, one curve per integrator.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperChart {
    /// The chart's file name in `DIR/charts/`, without extension.
    pub name: String,
    /// The paper example whose runs it draws (a name of [`PAPER_MODELS`]).
    pub model: String,
    /// The `T×3` dataset, e.g. `/nodes/arm.end/displacement`.
    pub dataset: String,
    /// The column drawn: 0, 1 or 2.
    pub component: usize,
    /// The chart's title.
    pub title: String,
    /// The label of the y axis.
    pub y_label: String,
    /// A run's curve ends (NaN) from the first step whose energy balance is
    /// off its initial value by more than this many times the run's energy
    /// scale.
    pub cut_at_energy_error: Option<f64>,
    /// Markers on one integrator's curve.
    pub markers: Option<Markers>,
}

/// Markers on one integrator's curve of a [`PaperChart`].
#[derive(Debug, Clone, PartialEq)]
pub struct Markers {
    /// The integrator whose curve carries them (one of [`INTEGRATORS`]).
    pub integrator: String,
    /// About this many markers (at least one).
    pub count: usize,
}

/// The table compiled into the program ([`PAPER_CHARTS`]).
pub fn paper_charts() -> Result<Vec<PaperChart>, ReproduceError> {
    let (file, text) = PAPER_CHARTS;
    parse(file, text)
}

/// Reads chart table `text`; `file` names it in errors.
pub fn parse(file: &str, text: &str) -> Result<Vec<PaperChart>, ReproduceError> {
    let de = toml::de::DeTable::parse(text).map_err(|e| ReproduceError::ChartTableSyntax {
        file: PathBuf::from(file),
        line: e.span().map(|s| line_of(text, s.start)),
        message: e.message().trim().to_owned(),
    })?;
    let at = Located {
        file,
        lines: key_lines(text, de.get_ref()),
    };
    let root: Table = toml::from_str(text).map_err(|e| ReproduceError::ChartTableSyntax {
        file: PathBuf::from(file),
        line: None,
        message: e.message().trim().to_owned(),
    })?;
    if let Some(key) = root.keys().find(|k| k.as_str() != "chart") {
        return Err(at.error(key, "unknown key; the table holds [[chart]] entries only"));
    }
    let entries = match root.get("chart") {
        None => return Ok(Vec::new()),
        Some(Value::Array(entries)) => entries,
        Some(v) => return Err(at.wrong_type("chart", "[[chart]] entries", v)),
    };
    let mut charts: Vec<PaperChart> = Vec::with_capacity(entries.len());
    for (i, entry) in entries.iter().enumerate() {
        let key = format!("chart[{i}]");
        let Value::Table(table) = entry else {
            return Err(at.wrong_type(&key, "a [[chart]] table", entry));
        };
        let chart = Entry {
            table,
            key: &key,
            at: &at,
        }
        .chart()?;
        if charts.iter().any(|c| c.name == chart.name) {
            return Err(at.error(
                &format!("{key}.name"),
                format!(
                    "\"{}\" names another chart too; give each its own",
                    chart.name
                ),
            ));
        }
        charts.push(chart);
    }
    Ok(charts)
}

/// 1-based line of byte `offset` of `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The 1-based line of every key of the table, from the parser's spans:
/// `chart[i]` (the entry) and `chart[i].key`, `chart[i].key.sub` within it.
fn key_lines(text: &str, root: &toml::de::DeTable<'_>) -> Vec<(String, usize)> {
    /// Adds the keys of `table` under `prefix`, and those of its sub-tables.
    fn add(
        text: &str,
        prefix: &str,
        table: &toml::de::DeTable<'_>,
        lines: &mut Vec<(String, usize)>,
    ) {
        for (k, v) in table.iter() {
            let key = format!("{prefix}{}", k.get_ref());
            lines.push((key.clone(), line_of(text, k.span().start)));
            match v.get_ref() {
                toml::de::DeValue::Table(t) => add(text, &format!("{key}."), t, lines),
                toml::de::DeValue::Array(items) => {
                    for (i, item) in items.iter().enumerate() {
                        let entry = format!("{key}[{i}]");
                        lines.push((entry.clone(), line_of(text, item.span().start)));
                        if let toml::de::DeValue::Table(t) = item.get_ref() {
                            add(text, &format!("{entry}."), t, lines);
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let mut lines = Vec::new();
    add(text, "", root, &mut lines);
    lines
}

/// The table's name and key lines, for its errors.
struct Located<'a> {
    file: &'a str,
    lines: Vec<(String, usize)>,
}

impl Located<'_> {
    /// The error `message` at `key`, on the line of the key or else of the
    /// nearest entry holding it.
    fn error(&self, key: &str, message: impl Into<String>) -> ReproduceError {
        let mut at = key;
        let line = loop {
            if let Some((_, line)) = self.lines.iter().find(|(k, _)| k == at) {
                break Some(*line);
            }
            match at.rfind(['.', '[']) {
                Some(end) => at = &at[..end],
                None => break None,
            }
        };
        ReproduceError::ChartTable {
            file: PathBuf::from(self.file),
            line,
            key: key.to_owned(),
            message: message.into(),
        }
    }

    /// A value of the wrong type at `key`.
    fn wrong_type(&self, key: &str, expected: &str, found: &Value) -> ReproduceError {
        self.error(key, format!("expected {expected}, found {found}"))
    }
}

/// One `[[chart]]` entry (or its `markers` table) being read.
struct Entry<'a> {
    table: &'a Table,
    /// Its key, `chart[i]` or `chart[i].markers`.
    key: &'a str,
    at: &'a Located<'a>,
}

impl Entry<'_> {
    /// The entry as a chart, every key checked.
    fn chart(&self) -> Result<PaperChart, ReproduceError> {
        self.only(CHART_KEYS)?;
        let name = self.string("name")?;
        if name.is_empty() || name.contains(['/', '\\']) {
            return Err(self.error(
                "name",
                format!("\"{name}\" cannot name a chart file; give a plain file name"),
            ));
        }
        let model = self.string("model")?;
        if !PAPER_MODELS.iter().any(|m| m.0 == model) {
            let known: Vec<&str> = PAPER_MODELS.iter().map(|m| m.0).collect();
            return Err(self.error(
                "model",
                format!(
                    "\"{model}\" is not a paper example; one of {}",
                    known.join(", ")
                ),
            ));
        }
        let component = match self.integer("component")? {
            c @ 0..=2 => c as usize,
            c => return Err(self.error("component", format!("expected 0, 1 or 2, found {c}"))),
        };
        Ok(PaperChart {
            name,
            model,
            dataset: self.string("dataset")?,
            component,
            title: self.string("title")?,
            y_label: self.string("y_label")?,
            cut_at_energy_error: self.cut()?,
            markers: self.markers()?,
        })
    }

    /// `cut_at_energy_error`, if given: a positive number.
    fn cut(&self) -> Result<Option<f64>, ReproduceError> {
        let limit = match self.table.get("cut_at_energy_error") {
            None => return Ok(None),
            Some(Value::Float(x)) => *x,
            Some(Value::Integer(i)) => *i as f64,
            Some(v) => return Err(self.wrong_type("cut_at_energy_error", "a number", v)),
        };
        if limit > 0.0 && limit.is_finite() {
            Ok(Some(limit))
        } else {
            Err(self.error(
                "cut_at_energy_error",
                format!("expected a positive number, found {limit}"),
            ))
        }
    }

    /// `markers = { integrator, count }`, if given.
    fn markers(&self) -> Result<Option<Markers>, ReproduceError> {
        let table = match self.table.get("markers") {
            None => return Ok(None),
            Some(Value::Table(t)) => t,
            Some(v) => {
                return Err(self.wrong_type("markers", "{ integrator = \"…\", count = N }", v))
            }
        };
        let key = format!("{}.markers", self.key);
        let markers = Entry {
            table,
            key: &key,
            at: self.at,
        };
        markers.only("integrator, count")?;
        let integrator = markers.string("integrator")?;
        if !INTEGRATORS.contains(&integrator.as_str()) {
            return Err(markers.error(
                "integrator",
                format!(
                    "\"{integrator}\" is not an integrator of the reproduction; one of {}",
                    INTEGRATORS.join(", ")
                ),
            ));
        }
        let count = match markers.integer("count")? {
            c if c >= 1 => c as usize,
            c => return Err(markers.error("count", format!("expected at least 1, found {c}"))),
        };
        Ok(Some(Markers { integrator, count }))
    }

    /// Refuses a key not among `allowed` (comma-separated).
    fn only(&self, allowed: &str) -> Result<(), ReproduceError> {
        match self
            .table
            .keys()
            .find(|k| !allowed.split(", ").any(|a| a == k.as_str()))
        {
            Some(k) => Err(self.error(k, format!("unknown key; allowed here: {allowed}"))),
            None => Ok(()),
        }
    }

    /// The required string at `name`.
    fn string(&self, name: &str) -> Result<String, ReproduceError> {
        match self.required(name)? {
            Value::String(s) => Ok(s.clone()),
            v => Err(self.wrong_type(name, "a string", v)),
        }
    }

    /// The required integer at `name`.
    fn integer(&self, name: &str) -> Result<i64, ReproduceError> {
        match self.required(name)? {
            Value::Integer(i) => Ok(*i),
            v => Err(self.wrong_type(name, "an integer", v)),
        }
    }

    /// The value at `name`, which must be there.
    fn required(&self, name: &str) -> Result<&Value, ReproduceError> {
        self.table
            .get(name)
            .ok_or_else(|| self.error(name, "missing; every chart gives it"))
    }

    /// The error `message` at key `name` of this entry.
    fn error(&self, name: &str, message: impl Into<String>) -> ReproduceError {
        self.at.error(&format!("{}.{name}", self.key), message)
    }

    /// A value of the wrong type at key `name` of this entry.
    fn wrong_type(&self, name: &str, expected: &str, found: &Value) -> ReproduceError {
        self.at
            .wrong_type(&format!("{}.{name}", self.key), expected, found)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error text of `text` as a chart table.
    fn refusal(text: &str) -> String {
        parse("charts.toml", text).unwrap_err().to_string()
    }

    const ENTRY: &str =
        "[[chart]]\nname = \"a\"\nmodel = \"cam\"\ndataset = \"/nodes/arm.end/rotation\"\n\
                         component = 0\ntitle = \"t\"\ny_label = \"y\"\n";

    #[test]
    fn the_compiled_table_reads() {
        let charts = paper_charts().unwrap();
        let names: Vec<&str> = charts.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "fig6_screw_free_post_top_y",
                "fig8_screw_driven_tip_uz",
                "fig9_screw_driven_tip_rotation_x"
            ]
        );
        assert_eq!(charts[0].cut_at_energy_error, Some(10.0));
        assert_eq!(
            charts[1].markers,
            Some(Markers {
                integrator: "energy-momentum".into(),
                count: 25
            })
        );
        assert_eq!(charts[2].component, 0);
    }

    #[test]
    fn malformed_entries_name_the_file_line_and_key() {
        assert_eq!(parse("charts.toml", ENTRY).unwrap().len(), 1);
        let wrong = ENTRY.replace("component = 0", "component = 3");
        assert_eq!(
            refusal(&wrong),
            "charts.toml:5: key `chart[0].component`: expected 0, 1 or 2, found 3"
        );
        let twice = format!("{ENTRY}{}", ENTRY.replace("component = 0", "component = 1"));
        assert!(refusal(&twice).starts_with("charts.toml:9: key `chart[1].name`: \"a\""));
        let missing = ENTRY.replace("title = \"t\"\n", "");
        let text = refusal(&missing);
        assert!(text.contains("key `chart[0].title`: missing"), "{text}");
        let typo = ENTRY.replace("y_label", "ylabel");
        let text = refusal(&typo);
        assert!(
            text.starts_with("charts.toml:7: key `chart[0].ylabel`: unknown key"),
            "{text}"
        );
        let marker = format!("{ENTRY}markers = {{ integrator = \"euler\", count = 5 }}\n");
        let text = refusal(&marker);
        assert!(
            text.starts_with("charts.toml:8: key `chart[0].markers.integrator`"),
            "{text}"
        );
        let model = ENTRY.replace("\"cam\"", "\"crank\"");
        assert!(refusal(&model).starts_with("charts.toml:3: key `chart[0].model`"));
        let text = refusal("[[chart]\n");
        assert!(text.starts_with("charts.toml:1: not valid TOML"), "{text}");
    }
}
