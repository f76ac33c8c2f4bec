//! Running a study's runs in parallel and writing its summary.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::charts::summary_charts;
use super::figures::{read_figures, RunFigures};
use super::schedule::{estimated_cost, longest_first, run_queue};
use super::shard::Shard;
use super::spec::StudySpec;
use super::summary::{self, Summary};
use super::sweep::{expand, model_for, RunPlan};
use super::{StudyError, StudyReport};
use flexmech_model::Model;
use flexmech_results::layout;
use flexmech_results::run::{run_model_to, RunError};

/// How to run a study.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StudyOptions {
    /// Output root; the study writes to `<out>/<name>/`.
    pub out: PathBuf,
    /// Run only this shard's runs and write its shard summary.
    pub shard: Option<Shard>,
    /// Draw a progress bar on standard error (only when it is a terminal).
    pub progress: bool,
}

/// The directory of `spec`'s results below `out`: `<out>/<name>`.
pub fn study_dir(spec: &StudySpec, out: &Path) -> PathBuf {
    out.join(&spec.name)
}

/// Every run of `spec` in grid order.
pub fn plans(spec: &StudySpec) -> Vec<RunPlan> {
    let lists: Vec<&[toml::Value]> = spec.grid.iter().map(|g| g.values.as_slice()).collect();
    expand(&lists)
}

fn progress_bar(len: usize, enabled: bool) -> ProgressBar {
    let target = if enabled && std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(len as u64), target);
    let style = ProgressStyle::with_template(
        "{prefix} [{elapsed_precise}] {bar:40} {pos}/{len} runs (eta {eta}) {msg}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar
}

/// Runs one run: its result file is `runs/<id>.h5`. A failed solve is a
/// failed row; a model that cannot be built is a failed row without a file;
/// not being able to write is an error of the study.
fn run_one(
    spec: &StudySpec,
    runs_dir: &Path,
    plan: &RunPlan,
    model: &Model,
) -> Result<RunFigures, StudyError> {
    let file = runs_dir.join(format!("{}.h5", plan.id));
    // A stale file from an earlier study would otherwise be read back if
    // this run leaves none.
    match std::fs::remove_file(&file) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(source) => {
            return Err(StudyError::Io {
                path: file,
                what: "removing the previous result file",
                source,
            })
        }
    }
    match run_model_to(model, &file) {
        Ok(_) | Err(RunError::Solve { .. }) => Ok(read_figures(&file, &spec.figures)?),
        Err(RunError::Model(e)) => Ok(RunFigures::without_file(layout::failed_status(
            &e.to_string(),
        ))),
        Err(source) => Err(StudyError::Run {
            study: spec.file.clone(),
            run: plan.id.clone(),
            source: Box::new(source),
        }),
    }
}

/// Runs `spec` (or the shard `options.shard` of it) and writes the summary.
///
/// Every run's model is built and checked before the first run starts. Runs
/// execute in parallel; each writes `<out>/<name>/runs/<run id>.h5`. Without
/// a shard the summary is `summary.csv`, `summary.h5` and
/// `charts/<figure>.png/.svg`; with shard K/N it is
/// `summary-shard-K-of-N.csv/.h5` (no charts; `--merge` draws them).
pub fn run_study(spec: &StudySpec, options: &StudyOptions) -> Result<StudyReport, StudyError> {
    let all = plans(spec);
    // Check every run's model, not only this shard's: every shard of a
    // study then fails (or not) alike.
    let models: Vec<Model> = all
        .iter()
        .map(|p| model_for(spec, p))
        .collect::<Result<_, _>>()?;
    let selected: Vec<(&RunPlan, &Model)> = all
        .iter()
        .zip(&models)
        .filter(|(p, _)| options.shard.is_none_or(|s| s.includes(p.index)))
        .collect();

    let dir = study_dir(spec, &options.out);
    let runs_dir = dir.join("runs");
    std::fs::create_dir_all(&runs_dir).map_err(|source| StudyError::Io {
        path: runs_dir.clone(),
        what: "creating the output directory",
        source,
    })?;

    let bar = progress_bar(selected.len(), options.progress);
    bar.set_prefix(match options.shard {
        Some(s) => format!("{} (shard {s})", spec.name),
        None => spec.name.clone(),
    });
    // Longest first, one run at a time per free thread (see `schedule`).
    let costs: Vec<f64> = selected.iter().map(|(_, m)| estimated_cost(m)).collect();
    let outcomes: Vec<Result<RunFigures, StudyError>> = run_queue(&longest_first(&costs), |i| {
        let (plan, model) = selected[i];
        let outcome = run_one(spec, &runs_dir, plan, model);
        bar.inc(1);
        outcome
    });
    bar.finish_and_clear();

    let cols = summary::columns(spec);
    let mut rows = Vec::with_capacity(selected.len());
    for ((plan, _), outcome) in selected.iter().zip(outcomes) {
        rows.push(summary::row(spec, &cols, plan, &outcome?));
    }
    let table = Summary {
        columns: cols,
        rows,
    };
    write_summary(spec, &dir, &table, options.shard)
}

/// Writes `table` as the study's summary (or a shard's) into `dir` and, for
/// a whole study, draws the charts.
pub(crate) fn write_summary(
    spec: &StudySpec,
    dir: &Path,
    table: &Summary,
    shard: Option<Shard>,
) -> Result<StudyReport, StudyError> {
    let stem = shard.map_or_else(|| "summary".to_owned(), |s| s.summary_stem());
    let csv = dir.join(format!("{stem}.csv"));
    let h5 = dir.join(format!("{stem}.h5"));
    table.write_csv(&csv)?;
    table.write_h5(&h5, &spec.text, shard)?;
    let charts = if shard.is_none() {
        summary_charts(spec, table, &dir.join("charts")).map_err(|source| StudyError::Chart {
            study: spec.file.clone(),
            source,
        })?
    } else {
        Vec::new()
    };
    Ok(StudyReport {
        name: spec.name.clone(),
        dir: dir.to_path_buf(),
        csv,
        h5,
        charts,
        runs: table.rows.len(),
        failed: table.failed(summary::status_column(spec)),
        shard,
    })
}
