//! What a finished study tells its reader: where the summary, each run's
//! parameters and result file, and the charts are; and curves of one result
//! across the runs, labelled by their swept values.

use std::fmt;
use std::path::{Path, PathBuf};

use flexmech_plot::charts::{unit_of, LineChart, Series};
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
    /// A dataset of a run's result file is not one curve per run.
    #[error("{}: dataset {dataset}: {message}", .file.display())]
    Dataset {
        /// The run's result file.
        file: PathBuf,
        /// The dataset as asked for (`DATASET[k]`).
        dataset: String,
        /// What is wrong and how to fix it.
        message: String,
    },
}

impl StudyReport {
    /// The report of a study that ran before, from its output directory
    /// `<out>/<name>` as `flexmech study` wrote it (`summary.csv`,
    /// `summary.h5`, `runs/`, `charts/`): its name is the directory's, its
    /// run and failure counts the summary's, its charts the files in
    /// `charts/`. A directory without `summary.csv` is refused, saying what
    /// it should hold.
    pub fn from_dir(dir: &Path) -> Result<StudyReport, ReportError> {
        let csv = dir.join("summary.csv");
        if !csv.is_file() {
            let shards = std::fs::read_dir(dir)
                .into_iter()
                .flatten()
                .flatten()
                .any(|e| {
                    e.file_name()
                        .to_string_lossy()
                        .starts_with("summary-shard-")
                });
            let fix = if shards {
                "merge its shards first (`flexmech study STUDY.toml --merge`)"
            } else {
                "give a study's output directory <out>/<name>, as `flexmech study` writes it \
                 (summary.csv, summary.h5, runs/)"
            };
            return Err(ReportError::Summary {
                file: csv,
                message: format!("no such file: {fix}"),
            });
        }
        let mut charts: Vec<PathBuf> = std::fs::read_dir(dir.join("charts"))
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "png" || e == "svg"))
            .collect();
        charts.sort();
        let name = dir
            .canonicalize()
            .unwrap_or_else(|_| dir.to_path_buf())
            .file_name()
            .map_or_else(
                || dir.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
        let mut report = StudyReport {
            name,
            dir: dir.to_path_buf(),
            h5: dir.join("summary.h5"),
            csv,
            charts,
            runs: 0,
            failed: 0,
            shard: None,
        };
        let runs = report.study_runs()?;
        report.runs = runs.len();
        report.failed = runs
            .iter()
            .filter(|r| r.status.starts_with("failed"))
            .count();
        Ok(report)
    }

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

    /// A chart of `dataset` (a T-row dataset, or one column of a T×n one
    /// written `DATASET[k]`, `k` a number or `x`, `y`, `z`) against time,
    /// one curve per completed run, each labelled by the swept values that
    /// differ between the runs (`cam b = 0.03`). The title is the study's
    /// name, the axes are labelled `time (s)` (`load factor` in statics) and
    /// with the dataset's description, unit and column. A T×n dataset
    /// without a column, or a column it does not have, is refused.
    pub fn overlay(&self, dataset: &str) -> Result<LineChart, ReportError> {
        let (name, column) = split_column(dataset);
        let mut chart = LineChart::new(&self.name, "time (s)", dataset);
        let mut runs = self.study_runs()?;
        let varying: Vec<bool> = (0..runs.first().map_or(0, |r| r.params.len()))
            .map(|i| runs.iter().any(|r| r.params[i].1 != runs[0].params[i].1))
            .collect();
        for run in &mut runs {
            let mut keep = varying.iter();
            run.params.retain(|_| keep.next().copied().unwrap_or(true));
        }
        let mut labelled = false;
        for run in runs {
            if run.status != "completed" {
                continue;
            }
            let file = ResultReader::open(&run.file)?;
            let width: usize = file.shape(&name)?.iter().skip(1).product();
            let refuse = |message: String| ReportError::Dataset {
                file: run.file.clone(),
                dataset: dataset.to_owned(),
                message,
            };
            let k = match column {
                None if width > 1 => {
                    return Err(refuse(format!(
                        "it has {width} columns: give one, e.g. {name}[x] or {name}[0]"
                    )))
                }
                Some(k) if k >= width.max(1) => {
                    return Err(refuse(format!(
                        "it has {} column(s), so there is no column {k} (columns count from 0)",
                        width.max(1)
                    )))
                }
                k => k.unwrap_or(0),
            };
            if !labelled {
                (chart.x_label, chart.y_label) = axis_labels(&file, &name, column);
                labelled = true;
            }
            let values = file.values(&name)?;
            let y = values
                .chunks(width.max(1))
                .map(|row| row.get(k).copied().unwrap_or(f64::NAN))
                .collect();
            chart.series.push(Series::new(run.label(), file.time()?, y));
        }
        Ok(chart)
    }
}

/// The axis labels of a dataset of `file` over time: `time (s)` (or `load
/// factor`) and its description (else its name in words) with its unit and
/// column.
fn axis_labels(file: &ResultReader, name: &str, column: Option<usize>) -> (String, String) {
    let x = if file.integrator().as_deref() == Some("static") {
        "load factor"
    } else {
        "time (s)"
    };
    let mut y = match file.description(name) {
        Some(d) if !d.is_empty() => d,
        _ => name.rsplit('/').next().unwrap_or(name).replace('_', " "),
    };
    if let Some(k) = column {
        let axis = ["x", "y", "z"]
            .get(k)
            .map_or_else(|| k.to_string(), |a| (*a).to_owned());
        y = format!("{y}, {axis}");
    }
    if let Some(unit) = unit_of(name) {
        y = format!("{y} ({unit})");
    }
    (x.to_owned(), y)
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
            return (rooted(name), Some(k));
        }
    }
    (rooted(spec), None)
}

/// A dataset path with its leading `/`.
fn rooted(name: &str) -> String {
    format!("/{}", name.trim().trim_start_matches('/'))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_by_number_or_axis_and_paths_rooted() {
        assert_eq!(split_column("/a/b[x]"), ("/a/b".to_owned(), Some(0)));
        assert_eq!(split_column("a/b[2]"), ("/a/b".to_owned(), Some(2)));
        assert_eq!(
            split_column("/energy/total"),
            ("/energy/total".to_owned(), None)
        );
    }

    #[test]
    fn a_report_is_read_back_from_a_study_directory() {
        let dir = std::env::temp_dir().join(format!("flexmech-report-{}", std::process::id()));
        let study = dir.join("pitch");
        std::fs::create_dir_all(study.join("charts")).unwrap();
        std::fs::write(study.join("charts/wall_time.png"), b"").unwrap();
        std::fs::write(study.join("charts/wall_time.csv"), b"").unwrap();
        std::fs::write(
            study.join("summary.csv"),
            "run,joint.screw.pitch,status,wall_time\n\
             run-0000,0.01,completed,1\n\
             run-0001,0.02,failed: Newton,2\n",
        )
        .unwrap();
        let report = StudyReport::from_dir(&study).unwrap();
        assert_eq!(
            (report.name.as_str(), report.runs, report.failed),
            ("pitch", 2, 1)
        );
        assert_eq!(report.charts, [study.join("charts/wall_time.png")]);
        let runs = report.study_runs().unwrap();
        assert_eq!(runs[1].file, study.join("runs/run-0001.h5"));
        assert_eq!(runs[1].label(), "screw pitch = 0.02");

        let err = StudyReport::from_dir(&dir).unwrap_err().to_string();
        assert!(
            err.contains("summary.csv") && err.contains("output directory"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
