//! What a finished study tells its reader: where the summary, each run's
//! parameters and result file, and the charts are; and curves of one result
//! across the runs, labelled by their swept values.

use std::fmt;
use std::path::PathBuf;

use flexmech_plot::charts::{LineChart, Series};
use flexmech_results::{ReadError, ResultReader};

use super::charts::key_words;
use super::StudyReport;

/// One row of a study's summary: the run, its swept values and its file.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRun {
    /// Its id (`run-0003`), also its result file's stem.
    pub id: String,
    /// `(grid key, value as written in the summary)`, in grid order.
    pub params: Vec<(String, String)>,
    /// `completed`, or `failed: …`.
    pub status: String,
    /// Its result file, `<dir>/runs/<id>.h5` (absent for a run whose model
    /// could not be built).
    pub file: PathBuf,
}

impl StudyRun {
    /// The swept values as a legend entry, keys as words: `cam b = 0.03`.
    pub fn label(&self) -> String {
        self.params
            .iter()
            .map(|(k, v)| format!("{} = {v}", key_words(k)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Why the runs of a study could not be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The summary CSV could not be read.
    #[error("{}: {message}", .file.display())]
    Summary {
        /// The CSV file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A run's result file could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
}

impl StudyReport {
    /// Every run of the summary with its swept values and result file.
    pub fn study_runs(&self) -> Result<Vec<StudyRun>, ReportError> {
        let err = |message: String| ReportError::Summary {
            file: self.csv.clone(),
            message,
        };
        let mut reader = csv::Reader::from_path(&self.csv).map_err(|e| err(e.to_string()))?;
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| err(e.to_string()))?
            .iter()
            .map(str::to_owned)
            .collect();
        let status = header
            .iter()
            .position(|h| h == "status")
            .ok_or_else(|| err("no `status` column: not a study summary".into()))?;
        let mut runs = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| err(e.to_string()))?;
            let cell = |i: usize| record.get(i).unwrap_or_default().to_owned();
            runs.push(StudyRun {
                id: cell(0),
                params: (1..status).map(|i| (header[i].clone(), cell(i))).collect(),
                status: cell(status),
                file: self.dir.join("runs").join(format!("{}.h5", cell(0))),
            });
        }
        Ok(runs)
    }

    /// A chart of `dataset` (a T-row dataset, or one column of it written
    /// `DATASET[k]`, `k` a number or `x`, `y`, `z`) against time, one curve
    /// per completed run, each labelled by the swept values that differ
    /// between the runs (`cam b = 0.03`).
    pub fn overlay(&self, dataset: &str) -> Result<LineChart, ReportError> {
        let (name, column) = split_column(dataset);
        let mut chart = LineChart::new(&self.name, "time", dataset);
        let mut runs = self.study_runs()?;
        let varying: Vec<bool> = (0..runs.first().map_or(0, |r| r.params.len()))
            .map(|i| runs.iter().any(|r| r.params[i].1 != runs[0].params[i].1))
            .collect();
        for run in &mut runs {
            let mut keep = varying.iter();
            run.params.retain(|_| keep.next().copied().unwrap_or(true));
        }
        for run in runs {
            if run.status != "completed" {
                continue;
            }
            let file = ResultReader::open(&run.file)?;
            let width: usize = file.shape(&name)?.iter().skip(1).product();
            let values = file.values(&name)?;
            let y = values
                .chunks(width.max(1))
                .map(|row| row.get(column.unwrap_or(0)).copied().unwrap_or(f64::NAN))
                .collect();
            chart.series.push(Series::new(run.label(), file.time()?, y));
        }
        Ok(chart)
    }
}

/// `DATASET[k]` as the dataset and the column `k` (`x`, `y`, `z` name 0, 1, 2).
fn split_column(spec: &str) -> (String, Option<usize>) {
    let column = |k: &str| match k.trim() {
        "x" => Some(0),
        "y" => Some(1),
        "z" => Some(2),
        k => k.parse().ok(),
    };
    if let Some((name, rest)) = spec.split_once('[') {
        if let Some(k) = rest.strip_suffix(']').and_then(column) {
            return (name.to_owned(), Some(k));
        }
    }
    (spec.to_owned(), None)
}

impl fmt::Display for StudyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "study \"{}\": {} runs, {} failed",
            self.name, self.runs, self.failed
        )?;
        writeln!(
            f,
            "  summary  {} (a row per run: its id, swept values, status and figures; also {})",
            self.csv.display(),
            self.h5.display()
        )?;
        writeln!(
            f,
            "  runs     {} (<run id>.h5: each run's result file)",
            self.dir.join("runs").display()
        )?;
        if !self.charts.is_empty() {
            write!(
                f,
                "  charts   {} (a chart per figure)",
                self.dir.join("charts").display()
            )?;
        }
        Ok(())
    }
}
