//! `flexmech plot --study DIR DATASET…`: a dataset (or one column of it,
//! `DATASET[k]`) across the runs of a study that ran before, one curve per
//! completed run, labelled by the swept values that differ between the runs
//! ([`StudyReport::overlay`]). `DIR` is the study's output directory
//! `<out>/<name>` (`summary.csv` and `runs/`). Writes
//! `<out>/<dataset path with / as _>[_<k>].png`, `.svg`, `.csv` and `.tex`
//! per dataset, e.g. `plots/joints_screw_released_translation_z.png`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use flexmech_plot::charts::{ChartError, LineChart, PlotOptions};
use flexmech_studies::{ReportError, StudyReport};

/// Why `plot --study` drew nothing; every variant names the study directory.
#[derive(Debug, thiserror::Error)]
pub enum PlotStudyError {
    /// The study's summary or a run's result file could not be read.
    #[error("--study {}: {source}", .dir.display())]
    Report {
        /// The study directory.
        dir: PathBuf,
        /// The cause.
        #[source]
        source: ReportError,
    },
    /// An option of `plot` that has no meaning across a study's runs.
    #[error("--study {}: {option} does not apply across a study's runs; leave it out", .dir.display())]
    Option {
        /// The study directory.
        dir: PathBuf,
        /// The option (`--x`, `--with`).
        option: &'static str,
    },
    /// No run of the study completed, so there is nothing to draw.
    #[error(
        "--study {}: dataset {dataset}: no run completed (see the status column of summary.csv)",
        .dir.display()
    )]
    NoCompletedRun {
        /// The study directory.
        dir: PathBuf,
        /// The dataset.
        dataset: String,
    },
    /// The chart could not be drawn or written.
    #[error("--study {}: dataset {dataset}: {source}", .dir.display())]
    Chart {
        /// The study directory.
        dir: PathBuf,
        /// The dataset.
        dataset: String,
        /// The chart's error, naming the output file.
        #[source]
        source: ChartError,
    },
}

/// Draws each of `datasets` across the completed runs of the study in `dir`
/// into `out` (see the module docs) with `options`' axis labels, title,
/// logarithmic axis and PDF; `--x` and `--with` (`options.x`,
/// `options.overlay`) are refused. Every dataset is read and checked before
/// the first chart is written. Returns the files written, PNG and SVG (and
/// PDF) per dataset, in argument order.
pub fn plot_study(
    dir: &Path,
    datasets: &[String],
    out: &Path,
    options: &PlotOptions,
) -> Result<Vec<PathBuf>, PlotStudyError> {
    let option = |option| PlotStudyError::Option {
        dir: dir.to_path_buf(),
        option,
    };
    if options.x.is_some() {
        return Err(option("--x"));
    }
    if !options.overlay.is_empty() {
        return Err(option("--with"));
    }
    let report = |source| PlotStudyError::Report {
        dir: dir.to_path_buf(),
        source,
    };
    let study = StudyReport::from_dir(dir).map_err(report)?;
    let mut charts: Vec<(&String, LineChart)> = Vec::with_capacity(datasets.len());
    for dataset in datasets {
        let mut chart = study.overlay(dataset).map_err(report)?;
        if chart.series.is_empty() {
            return Err(PlotStudyError::NoCompletedRun {
                dir: dir.to_path_buf(),
                dataset: dataset.clone(),
            });
        }
        chart.log_y = options.log_y;
        if let Some(t) = &options.title {
            chart.title.clone_from(t);
        }
        if let Some(l) = &options.x_label {
            chart.x_label.clone_from(l);
        }
        if let Some(l) = &options.y_label {
            chart.y_label.clone_from(l);
        }
        charts.push((dataset, chart));
    }
    let mut written = Vec::with_capacity(2 * charts.len());
    for (dataset, chart) in charts {
        let stem = out.join(stem_of(dataset));
        let error = |source| PlotStudyError::Chart {
            dir: dir.to_path_buf(),
            dataset: dataset.clone(),
            source,
        };
        written.extend(chart.render_all(&stem, options.pdf).map_err(error)?);
    }
    Ok(written)
}

/// The `plot --study` command: every positional argument (`first`, which
/// the command line parses as the result file, then `datasets`) is a
/// dataset. Prints the files written, or the error.
pub fn command(
    dir: &Path,
    first: &Path,
    datasets: &[String],
    out: &Path,
    options: &PlotOptions,
) -> ExitCode {
    let all: Vec<String> = std::iter::once(first.to_string_lossy().into_owned())
        .chain(datasets.iter().cloned())
        .collect();
    match plot_study(dir, &all, out, options) {
        Ok(files) => {
            for f in files {
                println!("{}", f.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `/joints/screw/released_translation[z]` → `joints_screw_released_translation_z`.
fn stem_of(dataset: &str) -> String {
    let (name, column) = match dataset.split_once('[') {
        Some((name, rest)) => (name, Some(rest.trim_end_matches(']').trim())),
        None => (dataset, None),
    };
    let mut stem = name.trim().trim_start_matches('/').replace('/', "_");
    if let Some(k) = column.filter(|k| !k.is_empty()) {
        stem.push('_');
        stem.push_str(k);
    }
    stem
}

#[cfg(test)]
mod tests {
    use super::stem_of;

    #[test]
    fn stems_name_the_dataset_and_its_column() {
        assert_eq!(
            stem_of("/joints/screw/released_translation[z]"),
            "joints_screw_released_translation_z"
        );
        assert_eq!(stem_of("energy/total"), "energy_total");
    }
}
