//! Parameter sweeps: `flexmech study STUDY.toml` runs one base model over a
//! grid of values for some of its keys, in parallel, and summarises every
//! run in one table (CSV and HDF5) with one chart per figure.
//!
//! # Study files
//!
//! ```toml
//! name = "screw-pitch-dt"             # study name; results go to <out>/<name>/
//! model = "../paper/screw_free.toml"  # base model, path relative to the study file
//!
//! [grid]                              # cartesian product of every list
//! "solver.dt" = [0.02, 0.01]
//! "solver.integrator" = ["newmark", "momentum", "energy-momentum"]
//! "joint.screw.pitch" = [0.05, 0.1]   # the [[joint]] entry whose name = "screw"
//!
//! [output]                            # optional
//! figures = ["energy_drift", "max_displacement", "failure_time", "wall_time", "newton_iterations"]
//! ```
//!
//! `name` and `model` are required; `[grid]` may be left out (one run of the
//! base model); `output.figures` defaults to all five figures in the order
//! above. Any other key is an error.
//!
//! **Grid keys** are dotted paths into the model TOML and must be quoted in
//! `[grid]`. A segment names a table key (`solver.dt`); `name[i]` takes entry
//! `i`, from 0, of an array (`joint[0].pitch`, `gravity[2]`); a segment after
//! an array of tables picks the entry whose `name` field equals it
//! (`joint.screw.pitch`, `beam.arm.elements`, `section.rod.EA`). A segment
//! may be double-quoted to hold dots (`"joint.\"arm.pin\".pitch"`). The key
//! must name a value that is present in the base model (write an optional
//! key's default into the model to sweep it); a key that does not exist is an
//! error naming the study file, the key and what exists there. Values keep
//! the type the grid gives (float, integer, string, boolean, array).
//!
//! For each run the values are put into the parsed base model, which is then
//! written back as TOML text and loaded with
//! [`parse_model`](flexmech_model::parse_model), so every model-file check
//! applies; every run's model is checked before the first run starts. (The
//! result file's `model` attribute holds that rewritten text, without the
//! base file's comments.)
//!
//! # Runs and output
//!
//! Runs are numbered in grid order, the last key varying fastest: `run-0000`,
//! `run-0001`, … (more digits past 10 000 runs). They execute in parallel
//! (rayon), handed to the threads one at a time, the longest (by an estimate:
//! nodes × steps × the scheme's relative step cost) first, and each writes `<out>/<name>/runs/<run id>.h5` in the layout of
//! [`flexmech_results`]. A run whose solve fails still leaves its file with
//! `status = "failed: …"` and is a failed row of the summary, not an error of
//! the study (so is a run whose model cannot be built; it has no file and NaN
//! figures).
//!
//! The summary ([`summary`]) has one row per run: `run`, one column per grid
//! key (named by the key), `status`, and the figures ([`figures`]):
//!
//! | figure | value |
//! |---|---|
//! | `energy_drift` | [`flexmech_results::reader::energy_drift`] over every converged step (the result file's root attribute) |
//! | `max_displacement` | max over tracked nodes and every converged step of the displacement's norm (NaN if none is tracked) |
//! | `failure_time` | last `/time` of a run whose status starts with `failed`, else NaN |
//! | `wall_time` | root attribute `wall_time_s` |
//! | `newton_iterations` | Newton iterations of every converged step |
//!
//! It is written to `<out>/<name>/summary.csv` and `summary.h5` (one 1-D
//! dataset per column: numbers `f64`, text variable-length UTF-8; root
//! attribute `study` = the study file text, `columns` = the column names in
//! order), and [`charts`] draws `<out>/<name>/charts/<figure>.png` and
//! `.svg`.
//!
//! # Shards
//!
//! `--shard K/N` ([`shard`]) runs only the runs whose index `i` has
//! `i % N == K − 1` and writes `summary-shard-K-of-N.csv/.h5` instead (no
//! charts). Without `--shard`, a Slurm array task is shard
//! `K = (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN) / SLURM_ARRAY_TASK_STEP + 1`
//! of `N = SLURM_ARRAY_TASK_COUNT` (MIN defaults to 0, STEP to 1), so
//! `--array=0-3` gives shards 1/4 … 4/4. `--merge` ([`merge`]) checks that
//! shards 1..=N of a single N are all present and hold every run exactly
//! once, then writes the summary and charts exactly as an unsharded run.
//!
//! ```no_run
//! use std::path::Path;
//! use flexmech_studies::{load_study, run_study, StudyOptions};
//!
//! # fn main() -> Result<(), flexmech_studies::StudyError> {
//! let spec = load_study(Path::new("data/studies/pitch_dt.toml"))?;
//! let options = StudyOptions { out: "studies".into(), shard: None, progress: true };
//! let report = run_study(&spec, &options)?;
//! println!("{} runs, {} failed: {}", report.runs, report.failed, report.csv.display());
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use flexmech_model::JointRegistry;

mod builder;
pub mod charts;
pub mod dataset_figure;
pub mod execute;
pub mod figures;
pub use flexmech_model::key_path;
pub mod merge;
mod report;
mod schedule;
pub mod shard;
pub mod source;
pub mod spec;
pub mod summary;
pub mod sweep;

pub use builder::Study;
pub use charts::key_words;
pub use dataset_figure::{Component, DatasetFigure, Reduce};
pub use execute::{run_study, StudyOptions};
pub use merge::{merge_study, MergeError};
pub use report::{ReportError, StudyRun};
pub use shard::{select_shard, Shard, ShardError, SlurmArray};
pub use spec::{
    load_study, load_study_with, parse_study, parse_study_with, BuildFn, Figure, ModelFn,
    RunParams, RunSource, SpecError, StudySpec,
};
pub use sweep::SweepError;

/// Why a study could not be run or merged. Failed runs are not errors: they
/// are rows of the summary.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The study file was rejected.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// A run's model could not be produced or is invalid.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// The shard could not be determined.
    #[error(transparent)]
    Shard(#[from] ShardError),
    /// The summary could not be written or a shard summary read.
    #[error(transparent)]
    Summary(#[from] summary::SummaryError),
    /// A run's result file could not be read back.
    #[error(transparent)]
    Figures(#[from] figures::FigureError),
    /// The shard summaries could not be merged.
    #[error(transparent)]
    Merge(#[from] MergeError),
    /// A summary chart could not be drawn.
    #[error("{}: summary chart: {source}", .study.display())]
    Chart {
        /// The study file.
        study: PathBuf,
        /// The chart's error, naming the output file.
        source: flexmech_plot::charts::ChartError,
    },
    /// A run could not write its result file.
    #[error("{}: {run}: {source}", .study.display())]
    Run {
        /// The study file.
        study: PathBuf,
        /// The run id.
        run: String,
        /// The run's error.
        source: Box<flexmech_results::run::RunError>,
    },
    /// A file or directory operation failed.
    #[error("{}: {what}: {source}", .path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// What was being done.
        what: &'static str,
        /// The cause.
        source: std::io::Error,
    },
}

/// Where a study (or shard) wrote its summary, and how its runs went.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StudyReport {
    /// The study's name.
    pub name: String,
    /// `<out>/<name>`.
    pub dir: PathBuf,
    /// The summary CSV (`summary.csv` or `summary-shard-K-of-N.csv`).
    pub csv: PathBuf,
    /// The summary HDF5 file.
    pub h5: PathBuf,
    /// The chart files (PNG and SVG per figure; none for a shard).
    pub charts: Vec<PathBuf>,
    /// Rows in the summary.
    pub runs: usize,
    /// Rows whose status starts with `failed`.
    pub failed: usize,
    /// The shard run, if any.
    pub shard: Option<Shard>,
}

/// The `flexmech study` command: loads the study file `file` and, with
/// `merge`, merges its shard summaries below `out`; otherwise runs it (the
/// shard given by the `--shard` text `shard`, else by the Slurm array
/// `slurm`, else every run). The Slurm variables are not consulted for a
/// merge. Model files are read with the joint kinds of `joints`.
pub fn study_command(
    joints: &JointRegistry,
    file: &Path,
    out: &Path,
    shard: Option<&str>,
    merge: bool,
    slurm: &SlurmArray,
    progress: bool,
) -> Result<StudyReport, StudyError> {
    let spec = load_study_with(file, joints)?;
    if merge {
        return merge_study(&spec, out);
    }
    let shard = select_shard(shard, slurm)?;
    let options = StudyOptions {
        out: out.to_path_buf(),
        shard,
        progress,
    };
    run_study(&spec, &options)
}
