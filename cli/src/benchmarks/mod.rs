//! `flexmech reproduce --benchmarks`: the community's benchmark set
//! (`data/benchmarks/`) solved and set beside its references — published
//! values, the exact solutions, independent codes' runs — as one chart per
//! benchmark and one table: benchmark, quantity, reference, ours,
//! difference, mesh and step.
//!
//! The model files and the reference data (`data/benchmarks/reference/`)
//! are compiled into the program, byte for byte, so the command works from
//! any directory. Each benchmark has its own file: how it is run, which
//! quantities it reports, what its chart shows.

mod elastica;
mod four_bar;
mod lateral_buckling;
mod lee_frame;
mod princeton;
pub mod reference;
mod rotating_shaft;
pub mod table;

use crate::reproduce::ReproduceError;
use flexmech_model::parse_model;
use flexmech_plot::charts::{LineChart, Panels, Series};
use flexmech_results::run::run_model_to;
use flexmech_results::ResultReader;
use std::path::{Path, PathBuf};

pub use table::Row;

/// What one benchmark gives: its table rows and its chart.
pub struct Outcome {
    /// Rows of the table, in order.
    pub rows: Vec<Row>,
    /// The chart (one or more panels).
    pub chart: Panels,
}

/// A benchmark: its name (the chart's file stem) and how it runs.
type Benchmark = (
    &'static str,
    fn(&Path, bool) -> Result<Outcome, ReproduceError>,
);

/// The benchmarks, in the table's order.
const BENCHMARKS: [Benchmark; 6] = [
    ("princeton_beam", princeton::run),
    ("four_bar", four_bar::run),
    ("lateral_buckling", lateral_buckling::run),
    ("rotating_shaft", rotating_shaft::run),
    ("elastica", elastica::run),
    ("lee_frame", lee_frame::run),
];

/// Everything the benchmark reproduction wrote.
#[derive(Debug, Clone)]
pub struct BenchmarkReport {
    /// The table's rows, benchmark by benchmark.
    pub rows: Vec<Row>,
    /// Each benchmark's chart (PNG; SVG, PGFPlots copy and CSV beside it).
    pub charts: Vec<PathBuf>,
    /// `DIR/benchmarks/table.md` and `table.csv`.
    pub table: (PathBuf, PathBuf),
}

/// Runs every benchmark into `out/benchmarks/` (result files under
/// `out/benchmarks/runs/`), draws the charts (`titles`: inside them; `pdf`:
/// also through pdflatex) and writes the table.
pub fn reproduce_benchmarks(
    out: &Path,
    titles: bool,
    pdf: bool,
) -> Result<BenchmarkReport, ReproduceError> {
    let dir = out.join("benchmarks");
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs).map_err(|source| ReproduceError::Write {
        file: runs.clone(),
        source,
    })?;
    let (mut rows, mut charts) = (Vec::new(), Vec::new());
    for (name, run) in BENCHMARKS {
        let outcome = run(&runs, titles)?;
        let stem = dir.join(name);
        let png = if pdf {
            outcome.chart.render_with_pdf(&stem)?.0
        } else {
            outcome.chart.render(&stem)?.0
        };
        charts.push(png);
        rows.extend(outcome.rows);
    }
    let table = table::write(&rows, &dir)?;
    Ok(BenchmarkReport {
        rows,
        charts,
        table,
    })
}

/// Runs the model `text` (read from `path` in the repository) into
/// `dir/<stem>.h5` and opens its result, which must have completed.
fn solve(text: &str, path: &str, dir: &Path, stem: &str) -> Result<ResultReader, ReproduceError> {
    let fail = |message: String| ReproduceError::Run {
        model: path.to_string(),
        integrator: "its own".to_string(),
        message,
    };
    let model = parse_model(text, Path::new(path)).map_err(|e| fail(e.to_string()))?;
    let file = dir.join(format!("{stem}.h5"));
    run_model_to(&model, &file).map_err(|e| fail(e.to_string()))?;
    let reader = ResultReader::open(&file).map_err(|e| read_error(&file, e))?;
    let status = reader.status().map_err(|e| read_error(&file, e))?;
    if status != "completed" {
        return Err(fail(format!("the run ended {status}")));
    }
    Ok(reader)
}

/// A result file that could not be read back.
fn read_error(file: &Path, e: impl std::fmt::Display) -> ReproduceError {
    ReproduceError::Read {
        file: file.to_path_buf(),
        message: e.to_string(),
    }
}

/// `name`'s rows of three components in `reader`.
fn rows3(reader: &ResultReader, name: &str) -> Result<Vec<[f64; 3]>, ReproduceError> {
    reader.rows3(name).map_err(|e| read_error(reader.path(), e))
}

/// The stored times of `reader`.
fn times(reader: &ResultReader) -> Result<Vec<f64>, ReproduceError> {
    reader.time().map_err(|e| read_error(reader.path(), e))
}

/// The index of the stored time nearest `t`.
fn nearest(times: &[f64], t: f64) -> usize {
    (0..times.len())
        .min_by(|&a, &b| (times[a] - t).abs().total_cmp(&(times[b] - t).abs()))
        .unwrap_or(0)
}

/// Two panels of a mid-span history over time, `u_y` and `u_z` (`names`
/// for the axes), flexmech's (`t`, `u`) against an independent run's rows
/// `[t, ux, uy, uz]`; `title` above the first.
fn against_twin(
    title: Option<String>,
    t: &[f64],
    u: &[[f64; 3]],
    twin: &[Vec<f64>],
    names: [&str; 2],
) -> Panels {
    let twin_t = reference::column(twin, 0);
    let panels = (1..3)
        .map(|c| {
            let label = format!("mid-span {} displacement (m)", names[c - 1]);
            let mut chart = LineChart::new("", "time (s)", label);
            chart.series = vec![
                Series::new("flexmech", t.to_vec(), u.iter().map(|d| d[c]).collect()),
                Series::new(
                    "independent run",
                    twin_t.clone(),
                    reference::column(twin, c + 1),
                ),
            ];
            chart
        })
        .collect::<Vec<_>>();
    let mut panels = Panels::row(panels);
    if let Some(title) = title {
        panels.charts[0].title = title;
    }
    panels
}
