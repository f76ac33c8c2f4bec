//! The summary table of a study: one row per run, written as CSV and HDF5,
//! and read back from a shard's CSV for `--merge`.
//!
//! Columns: `run` (the run id), one per grid key (named by the key), `status`,
//! then one per figure. A grid column whose values are all numbers and every
//! figure column is numeric; other columns are text (strings as written,
//! booleans and arrays in their TOML form). In the CSV a number is written in
//! its shortest round-trip form ([`number_text`]: `0.01`, `2`, `3.5e-16`, `NaN`), so a CSV read
//! back gives the same numbers bit for bit.

use std::path::{Path, PathBuf};

use flexmech_results::table::{write_table, TableColumn, TableError, TableValues};
use toml::Value;

use super::figures::{is_failed, RunFigures};
use super::shard::Shard;
use super::spec::StudySpec;
use super::sweep::RunPlan;

/// A summary cell.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A number (NaN where a figure does not apply).
    Number(f64),
    /// Text.
    Text(String),
}

impl Cell {
    /// The cell as written in the CSV.
    pub fn csv_text(&self) -> String {
        match self {
            Cell::Number(v) => number_text(*v),
            Cell::Text(s) => s.clone(),
        }
    }

    /// The number, or NaN for a text cell.
    pub fn number(&self) -> f64 {
        match self {
            Cell::Number(v) => *v,
            Cell::Text(_) => f64::NAN,
        }
    }
}

/// A number in its shortest round-trip form: plain (`0.01`, `2`) for
/// magnitudes in [1e-4, 1e15), with an exponent (`3.49e-16`) otherwise;
/// `NaN`, `inf`, `-inf` for the non-finite.
pub fn number_text(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && a != 0.0 && !(1e-4..1e15).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Whether a column holds numbers or text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    /// `f64` (an HDF5 `f64` dataset).
    Number,
    /// Text (an HDF5 variable-length UTF-8 string dataset).
    Text,
}

/// A summary column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    /// The header: `run`, a grid key, `status` or a figure name.
    pub name: String,
    /// Its kind.
    pub kind: ColumnKind,
    /// One line of meaning (the HDF5 dataset's `description`).
    pub description: String,
}

/// A study's summary table.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The columns, in order.
    pub columns: Vec<Column>,
    /// The rows, each with one cell per column, sorted by run id.
    pub rows: Vec<Vec<Cell>>,
}

/// Index of the `status` column: after `run` and the grid keys.
pub fn status_column(spec: &StudySpec) -> usize {
    1 + spec.grid.len()
}

/// The columns of `spec`'s summary.
pub fn columns(spec: &StudySpec) -> Vec<Column> {
    let mut cols = vec![Column {
        name: "run".into(),
        kind: ColumnKind::Text,
        description: "run id; the run's results are runs/<run>.h5".into(),
    }];
    for g in &spec.grid {
        cols.push(Column {
            name: g.key.clone(),
            kind: if g.is_numeric() {
                ColumnKind::Number
            } else {
                ColumnKind::Text
            },
            description: format!("swept model key {}", g.key),
        });
    }
    cols.push(Column {
        name: "status".into(),
        kind: ColumnKind::Text,
        description: "\"completed\" or \"failed: <reason>\"".into(),
    });
    for f in &spec.figures {
        cols.push(Column {
            name: f.name().into(),
            kind: ColumnKind::Number,
            description: f.description(),
        });
        for (name, key) in f.derivative_columns() {
            cols.push(Column {
                name,
                kind: ColumnKind::Number,
                description: format!("exact derivative of {} by the model value {key}", f.name()),
            });
        }
    }
    cols
}

/// The cell of a swept value in a column of `kind`.
pub fn value_cell(value: &Value, kind: ColumnKind) -> Cell {
    match (value, kind) {
        (Value::Integer(i), ColumnKind::Number) => Cell::Number(*i as f64),
        (Value::Float(f), ColumnKind::Number) => Cell::Number(*f),
        (Value::String(s), _) => Cell::Text(s.clone()),
        (other, _) => Cell::Text(other.to_string()),
    }
}

/// The summary row of run `plan` with outcome `figures`.
pub fn row(spec: &StudySpec, cols: &[Column], plan: &RunPlan, figures: &RunFigures) -> Vec<Cell> {
    let mut cells = vec![Cell::Text(plan.id.clone())];
    for (value, col) in plan.values.iter().zip(&cols[1..]) {
        cells.push(value_cell(value, col.kind));
    }
    cells.push(Cell::Text(figures.status.clone()));
    for f in &spec.figures {
        cells.push(Cell::Number(figures.get(f)));
        for (name, _) in f.derivative_columns() {
            cells.push(Cell::Number(figures.named(&name)));
        }
    }
    cells
}

/// Why a summary could not be written or read; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum SummaryError {
    /// Writing or reading the CSV failed.
    #[error("{}: {what}: {source}", .file.display())]
    Csv {
        /// The CSV file.
        file: PathBuf,
        /// What was being done.
        what: String,
        /// The CSV library's error.
        #[source]
        source: csv::Error,
    },
    /// Writing the HDF5 copy failed.
    #[error(transparent)]
    Hdf5(#[from] TableError),
    /// A shard CSV's header is not this study's.
    #[error(
        "{}: the header is {found:?} but this study's summary has {expected:?}; the file was \
         written for another version of the study file: run that shard again",
        .file.display()
    )]
    Header {
        /// The CSV file.
        file: PathBuf,
        /// The header found.
        found: Vec<String>,
        /// The header expected.
        expected: Vec<String>,
    },
    /// A cell of a numeric column is not a number.
    #[error("{}:{line}: column `{column}`: \"{text}\" is not a number", .file.display())]
    NotNumber {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the record.
        line: u64,
        /// The column.
        column: String,
        /// The cell.
        text: String,
    },
}

impl Summary {
    /// How many rows have a `failed…` status (`status_col` is its column).
    pub fn failed(&self, status_col: usize) -> usize {
        self.rows
            .iter()
            .filter(|r| matches!(&r[status_col], Cell::Text(s) if is_failed(s)))
            .count()
    }

    /// Writes the table as CSV with a header line.
    pub fn write_csv(&self, file: &Path) -> Result<(), SummaryError> {
        let err = |what: &str| {
            let what = what.to_owned();
            move |source| SummaryError::Csv {
                file: file.to_path_buf(),
                what,
                source,
            }
        };
        let mut w = csv::Writer::from_path(file).map_err(err("creating the file"))?;
        w.write_record(self.columns.iter().map(|c| c.name.as_str()))
            .map_err(err("writing the header"))?;
        for r in &self.rows {
            w.write_record(r.iter().map(Cell::csv_text))
                .map_err(err("writing a row"))?;
        }
        w.flush()
            .map_err(|e| err("flushing the file")(csv::Error::from(e)))
    }

    /// Reads a CSV written by [`write_csv`](Self::write_csv) whose header
    /// must be `columns`.
    pub fn read_csv(file: &Path, columns: &[Column]) -> Result<Self, SummaryError> {
        let err = |what: &str| {
            let what = what.to_owned();
            move |source| SummaryError::Csv {
                file: file.to_path_buf(),
                what,
                source,
            }
        };
        let mut r = csv::Reader::from_path(file).map_err(err("opening the file"))?;
        let header: Vec<String> = r
            .headers()
            .map_err(err("reading the header"))?
            .iter()
            .map(str::to_owned)
            .collect();
        let expected: Vec<String> = columns.iter().map(|c| c.name.clone()).collect();
        if header != expected {
            return Err(SummaryError::Header {
                file: file.to_path_buf(),
                found: header,
                expected,
            });
        }
        let mut rows = Vec::new();
        for record in r.records() {
            let record = record.map_err(err("reading a row"))?;
            let line = record.position().map_or(0, |p| p.line());
            let mut cells = Vec::with_capacity(columns.len());
            for (text, col) in record.iter().zip(columns) {
                cells.push(match col.kind {
                    ColumnKind::Text => Cell::Text(text.to_owned()),
                    ColumnKind::Number => {
                        Cell::Number(text.parse().map_err(|_| SummaryError::NotNumber {
                            file: file.to_path_buf(),
                            line,
                            column: col.name.clone(),
                            text: text.to_owned(),
                        })?)
                    }
                });
            }
            rows.push(cells);
        }
        Ok(Self {
            columns: columns.to_vec(),
            rows,
        })
    }

    /// Writes the table as HDF5: one 1-D dataset per column at the root,
    /// named by the column (a `/` in a name becomes `_`), `f64` for numbers
    /// and variable-length UTF-8 strings for text, each with a `description`
    /// attribute; root attributes `study` (the study file text), `columns`
    /// (the column names in order) and, for a shard, `shard` (`"K/N"`).
    pub fn write_h5(
        &self,
        file: &Path,
        study_text: &str,
        shard: Option<Shard>,
    ) -> Result<(), SummaryError> {
        let columns: Vec<TableColumn> = self
            .columns
            .iter()
            .enumerate()
            .map(|(j, col)| TableColumn {
                name: col.name.clone(),
                description: col.description.clone(),
                values: match col.kind {
                    ColumnKind::Number => {
                        TableValues::Numbers(self.rows.iter().map(|r| r[j].number()).collect())
                    }
                    ColumnKind::Text => {
                        TableValues::Texts(self.rows.iter().map(|r| r[j].csv_text()).collect())
                    }
                },
            })
            .collect();
        let shard = shard.map(|s| s.to_string());
        let mut attrs = vec![("study", study_text)];
        if let Some(s) = &shard {
            attrs.push(("shard", s.as_str()));
        }
        Ok(write_table(file, &columns, &attrs)?)
    }
}
