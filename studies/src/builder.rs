//! A study built in Rust with a few calls: over a base model whose keys the
//! grid sets, as a study file does.
//!
//! ```no_run
//! use flexmech_model::load_model;
//! use flexmech_studies::{Figure, Study};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let base = load_model("data/paper/screw_driven.toml".as_ref())?;
//! let report = Study::over("pitch", &base)
//!     .grid("joint.screw.pitch", [0.05, 0.1])
//!     .figure(Figure::MaxDisplacement)
//!     .run("studies")?;
//! println!("{report}");
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use toml::Value;

use super::spec::{Figure, SpecError, StudySpec};
use super::{run_study, StudyError, StudyOptions, StudyReport};
use flexmech_model::{JointRegistry, Model};

/// A study being put together: its base model, grid and figures. Runs are
/// the cartesian product of the grid (the last key varying fastest); with
/// no figure given, every built-in one ([`Figure::ALL`]).
#[derive(Debug, Clone)]
pub struct Study {
    name: String,
    model_file: PathBuf,
    model_text: String,
    grid: Vec<(String, Vec<Value>)>,
    figures: Vec<Figure>,
    joints: JointRegistry,
    progress: bool,
}

impl StudySpec {
    /// Runs every run in parallel below `<out>/<name>/` and writes the
    /// summary and charts ([`run_study`], no shard, a progress bar on a
    /// terminal).
    pub fn run(&self, out: impl AsRef<Path>) -> Result<StudyReport, StudyError> {
        let options = StudyOptions {
            out: out.as_ref().to_path_buf(),
            shard: None,
            progress: true,
        };
        run_study(self, &options)
    }

    /// Every key path the figures ask derivatives by (`derivative = [...]`),
    /// once each: the runs' models write them (`[output] sensitivity`).
    pub fn derivative_keys(&self) -> Vec<String> {
        let mut keys: Vec<String> = Vec::new();
        for f in &self.figures {
            for (_, key) in f.derivative_columns() {
                if !keys.iter().any(|k| k == key) {
                    keys.push(key.to_owned());
                }
            }
        }
        keys
    }
}

impl Study {
    /// A study named `name` over `base`: grid keys are the model key paths
    /// of study files (`joint.cam.b`, `section.rod.EI[0]`, `solver.dt`), set
    /// in the model's text ([`Model::text`]: the file's own while `base` is
    /// unchanged since it was read, else [`Model::to_toml`]).
    pub fn over(name: &str, base: &Model) -> Self {
        Self {
            name: name.to_owned(),
            model_file: base.path.clone(),
            model_text: base.text(),
            grid: Vec::new(),
            figures: Vec::new(),
            joints: JointRegistry::builtin(),
            progress: true,
        }
    }

    /// The joint kinds the runs' models are read with (a user's included).
    pub fn joints(mut self, joints: &JointRegistry) -> Self {
        self.joints = joints.clone();
        self
    }

    /// Sweeps the model key `key` over `values`.
    pub fn grid<V: Into<Value>>(mut self, key: &str, values: impl IntoIterator<Item = V>) -> Self {
        self.grid
            .push((key.to_owned(), values.into_iter().map(Into::into).collect()));
        self
    }

    /// Adds a figure to the summary (a column and a chart).
    pub fn figure(mut self, figure: Figure) -> Self {
        self.figures.push(figure);
        self
    }

    /// Whether to draw a progress bar on standard error (when it is a
    /// terminal; default true).
    pub fn progress(mut self, on: bool) -> Self {
        self.progress = on;
        self
    }

    /// The checked study: every check of a study file applies.
    pub fn spec(&self) -> Result<StudySpec, SpecError> {
        let figures = if self.figures.is_empty() {
            Figure::ALL.to_vec()
        } else {
            self.figures.clone()
        };
        StudySpec::over_model_with(
            &self.name,
            &self.model_file,
            &self.model_text,
            self.grid.clone(),
            figures,
            &self.joints,
        )
    }

    /// Runs every run in parallel below `<out>/<name>/` and writes the
    /// summary and charts ([`run_study`]).
    pub fn run(&self, out: impl AsRef<Path>) -> Result<StudyReport, StudyError> {
        let options = StudyOptions {
            out: out.as_ref().to_path_buf(),
            shard: None,
            progress: self.progress,
        };
        run_study(&self.spec()?, &options)
    }
}
