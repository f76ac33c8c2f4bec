//! `flexmech reproduce`: the paper's numerical examples (data/paper) with all
//! integrators, their result files and the paper's figures.
//!
//! Every model of [`PAPER_MODELS`] runs with `newmark`, `momentum`,
//! `energy-momentum` and `energy-momentum-paper` ([`INTEGRATORS`]), all runs
//! in parallel (rayon), each writing `DIR/<model>/<integrator>.h5`; the two
//! energy–momentum schemes also run [`CONSISTENCY_MODEL`] at half the step
//! (`DIR/<model>/<integrator>-half-dt.h5`) for the consistency chart. A run that fails (Newmark's energy blow-up
//! in `screw_free`, paper §5.1) keeps its steps and is part of the result.
//! Then [`charts`] draws the figures into `DIR/charts/`, [`summary`]
//! writes the figures of merit (failure time, energy drift, step halvings)
//! to `DIR/summary.csv` and `DIR/summary.md`, and [`views`] writes a
//! ParaView series per run and an animation per example.
//!
//! The model files are compiled into the program, so the command works from
//! any directory; they are the files of `data/paper/`, byte for byte. So is
//! the table of the paper's figures, `data/paper/charts/charts.toml`
//! ([`chart_table`]), read when a reproduction starts.

pub mod chart_table;
pub mod charts;
pub mod runs;
pub mod summary;
pub mod views;

use std::path::{Path, PathBuf};

pub use runs::{run_all, RunRecord};

/// The paper's examples: `(name, path in the repository, model text)`.
pub const PAPER_MODELS: [(&str, &str, &str); 5] = [
    (
        "screw_free",
        "data/paper/screw_free.toml",
        include_str!("../../../data/paper/screw_free.toml"),
    ),
    (
        "screw_driven",
        "data/paper/screw_driven.toml",
        include_str!("../../../data/paper/screw_driven.toml"),
    ),
    (
        "rack_pinion",
        "data/paper/rack_pinion.toml",
        include_str!("../../../data/paper/rack_pinion.toml"),
    ),
    (
        "cam",
        "data/paper/cam.toml",
        include_str!("../../../data/paper/cam.toml"),
    ),
    (
        "lobe",
        "data/paper/lobe.toml",
        include_str!("../../../data/paper/lobe.toml"),
    ),
];

/// The integrators compared, in the order of the charts' legends: the
/// paper's three, with the toolkit's consistent `energy-momentum` in place of
/// the paper's, and the paper's own energy–momentum scheme beside them.
pub const INTEGRATORS: [&str; 4] = [
    "newmark",
    "momentum",
    "energy-momentum",
    "energy-momentum-paper",
];

/// The energy–momentum schemes rerun at half the step in the consistency
/// study (`<model>_consistency` chart), on [`CONSISTENCY_MODEL`].
pub const CONSISTENCY_INTEGRATORS: [&str; 2] = ["energy-momentum", "energy-momentum-paper"];

/// The example of the consistency study: the free screw (no drive, so the
/// energy is conserved and β is the whole correction).
pub const CONSISTENCY_MODEL: &str = "screw_free";

/// What to reproduce.
#[derive(Debug, Clone, PartialEq)]
pub struct ReproduceOptions {
    /// Output directory.
    pub out: PathBuf,
    /// Models to run (names of [`PAPER_MODELS`]); empty: all.
    pub models: Vec<String>,
    /// Factor on every model's `t_end` (1: the full examples; smaller for a
    /// quick look).
    pub time_scale: f64,
    /// Titles inside the charts (false: none, for papers whose captions
    /// carry them).
    pub titles: bool,
    /// Also a PDF of every chart (its PGFPlots copy through `pdflatex`).
    pub pdf: bool,
}

impl ReproduceOptions {
    /// All models, full length, into `out`.
    pub fn full(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            models: Vec::new(),
            time_scale: 1.0,
            titles: true,
            pdf: false,
        }
    }
}

/// Why a reproduction could not be carried out (a run that fails is not an
/// error: it is a result).
#[derive(Debug, thiserror::Error)]
pub enum ReproduceError {
    /// A model name that is not one of the paper's examples.
    #[error("unknown model `{name}`; the paper's examples are {known}")]
    UnknownModel {
        /// The name given.
        name: String,
        /// The examples' names.
        known: String,
    },
    /// `time_scale` must be positive and finite.
    #[error("the time scale must be positive and finite, found {0}")]
    TimeScale(f64),
    /// A run could not start (bad model, unwritable directory, HDF5 error).
    #[error("{model} with {integrator}: {message}")]
    Run {
        /// The example.
        model: String,
        /// The integrator.
        integrator: String,
        /// What went wrong.
        message: String,
    },
    /// Reading a result file back failed.
    #[error("reading {}: {message}", file.display())]
    Read {
        /// The result file.
        file: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The table of the paper's figures (`data/paper/charts/charts.toml`)
    /// is not valid TOML.
    #[error("{}{}: not valid TOML: {message}", .file.display(), at_line(.line))]
    ChartTableSyntax {
        /// The table's file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// An entry of the table of the paper's figures
    /// (`data/paper/charts/charts.toml`) is malformed.
    #[error("{}{}: key `{key}`: {message}", .file.display(), at_line(.line))]
    ChartTable {
        /// The table's file.
        file: PathBuf,
        /// 1-based line, where known.
        line: Option<usize>,
        /// The key, e.g. `chart[1].component`.
        key: String,
        /// What is wrong, and the fix.
        message: String,
    },
    /// Drawing a chart failed.
    #[error(transparent)]
    Chart(#[from] flexmech_plot::charts::ChartError),
    /// Writing the summary failed.
    #[error("writing {}: {source}", file.display())]
    Write {
        /// The summary file.
        file: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
}

/// `:<line>` where the line is known, for messages.
fn at_line(line: &Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

/// Everything a reproduction produced.
#[derive(Debug, Clone)]
pub struct Reproduction {
    /// One record per run at the models' step, in model then integrator order.
    pub runs: Vec<RunRecord>,
    /// The half-step runs of the consistency study (empty when
    /// [`CONSISTENCY_MODEL`] is not selected).
    pub half_step: Vec<RunRecord>,
    /// The charts written (PNG paths; an SVG sits next to each).
    pub charts: Vec<PathBuf>,
    /// `DIR/summary.csv` and `DIR/summary.md`.
    pub summary: (PathBuf, PathBuf),
    /// The ParaView series of every run (`DIR/<model>/<integrator>.pvd`)
    /// and each example's animation (`DIR/animations/<model>.gif`).
    pub views: Vec<PathBuf>,
}

/// Runs the selected examples with every integrator, draws the charts and
/// writes the summary.
pub fn reproduce(options: &ReproduceOptions) -> Result<Reproduction, ReproduceError> {
    if !(options.time_scale > 0.0 && options.time_scale.is_finite()) {
        return Err(ReproduceError::TimeScale(options.time_scale));
    }
    let known: Vec<&str> = PAPER_MODELS.iter().map(|m| m.0).collect();
    for name in &options.models {
        if !known.contains(&name.as_str()) {
            return Err(ReproduceError::UnknownModel {
                name: name.clone(),
                known: known.join(", "),
            });
        }
    }
    let selected: Vec<(&str, &str, &str)> = PAPER_MODELS
        .iter()
        .copied()
        .filter(|m| options.models.is_empty() || options.models.iter().any(|n| n == m.0))
        .collect();
    let paper_charts = chart_table::paper_charts()?;
    let (runs, half_step) = run_all(&selected, &options.out, options.time_scale)?;
    let style = charts::Style {
        titles: options.titles,
        pdf: options.pdf,
    };
    let mut charts = charts::draw_all(&runs, &paper_charts, &options.out, style)?;
    charts.extend(charts::draw_consistency(
        &runs,
        &half_step,
        &options.out,
        style,
    )?);
    let summary = summary::write(&runs, &options.out)?;
    let views = views::write_all(&runs, &options.out)?;
    Ok(Reproduction {
        runs,
        half_step,
        charts,
        summary,
        views,
    })
}

/// `DIR/<model>/<integrator>.h5`, or `<integrator>-half-dt.h5` for a
/// half-step run.
pub fn result_path(out: &Path, model: &str, integrator: &str, half_step: bool) -> PathBuf {
    let suffix = if half_step { "-half-dt" } else { "" };
    out.join(model).join(format!("{integrator}{suffix}.h5"))
}
