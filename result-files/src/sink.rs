//! Where a run's steps go: a [`Sink`]. The result file ([`FileSink`]; its errors
//! are [`crate::ResultError`]s) is one
//! sink among others — steps kept in memory ([`Memory`]) or handed to a
//! closure ([`OnStep`]) — and every sink sees the same run: the
//! [`RunMeta`] first, then every kept step (every `output.every`-th and the
//! last), the restart state after a kept step of a dynamic run, and the end
//! ([`RunEnd`]: status, wall time, figures of merit, warnings).
//!
//! ```no_run
//! use flexmech_model::load_model;
//! use flexmech_results::{run, Memory};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let model = load_model("data/paper/screw_driven.toml".as_ref())?;
//! let mut memory = Memory::default();
//! run(&model, &mut memory)?;
//! println!("{} steps, {}", memory.records.len(), memory.status());
//! # Ok(())
//! # }
//! ```

use flexmech_integrators::modal::ModeSet;
use std::path::{Path, PathBuf};

use flexmech_integrators::dynamics::Checkpoint;
use flexmech_integrators::StepRecord;

use crate::{layout, Merit, ResultWriter, RunMeta};

/// What a sink may fail with; a result file's errors are [`crate::ResultError`]s.
pub type SinkError = Box<dyn std::error::Error + Send + Sync>;

/// How a run ended, as its sink records it.
#[derive(Debug, Clone)]
pub struct RunEnd {
    /// `completed`, or `failed: <reason>` (the result contract's status).
    pub status: String,
    /// Wall time of the solve, seconds.
    pub wall_time_s: f64,
    /// The figures of merit over every converged step
    /// ([`Merit::figures`]: `energy_drift`, `max_displacement`,
    /// `newton_iterations`, `steps`).
    pub merit: Merit,
    /// What the run's checks found doubtful in a completed run.
    pub warnings: Vec<String>,
    /// Why a completed static path ended (root attribute `end_reason`).
    pub end_reason: Option<String>,
    /// The critical points located on a static path (`/stability`).
    pub critical: Vec<flexmech_integrators::critical::CriticalPoint>,
}

impl RunEnd {
    pub(crate) fn new(status: String, wall_time_s: f64, merit: &Merit) -> Self {
        Self {
            status,
            wall_time_s,
            merit: merit.clone(),
            warnings: Vec::new(),
            end_reason: None,
            critical: Vec::new(),
        }
    }
}

/// A receiver of a run: what the run is, its kept steps, its restart
/// states, its end. The first error a sink returns stops the steps it is
/// given; the run then ends `failed` with that error.
pub trait Sink {
    /// Called once, before the first step.
    fn begin(&mut self, meta: &RunMeta) -> Result<(), SinkError>;
    /// A kept step.
    fn step(&mut self, record: &StepRecord) -> Result<(), SinkError>;
    /// A kept step handed over, as a run gives its steps (default:
    /// [`Self::step`] of it): a sink that keeps its steps takes them
    /// without copying them.
    fn take_step(&mut self, record: StepRecord) -> Result<(), SinkError> {
        self.step(&record)
    }
    /// The restart state of a dynamic run after a kept step: after every
    /// kept step for which [`Self::wants_checkpoint`] says so, and after the
    /// last one.
    fn checkpoint(&mut self, _state: &Checkpoint) -> Result<(), SinkError> {
        Ok(())
    }
    /// Whether the sink takes the restart state of the step it was given
    /// last (building it copies the whole state). Default: always.
    fn wants_checkpoint(&self) -> bool {
        true
    }
    /// The modes of a modal or buckling analysis, after its steps;
    /// `joints` names the model's joints. Default: ignored.
    fn modes(&mut self, _set: &ModeSet, _joints: &[String]) -> Result<(), SinkError> {
        Ok(())
    }
    /// The run's end; also called after a failure, with its status.
    fn finish(&mut self, end: &RunEnd) -> Result<(), SinkError>;
    /// The file the steps went to, if the sink writes one (named in a
    /// failed run's error).
    fn file(&self) -> Option<&Path> {
        None
    }
}

/// Keeps the run in memory: its description, every kept step and its end.
#[derive(Debug, Clone, Default)]
pub struct Memory {
    /// What the run is.
    pub meta: RunMeta,
    /// Every kept step, in order.
    pub records: Vec<StepRecord>,
    /// The last restart state.
    pub checkpoint: Option<Checkpoint>,
    /// How the run ended (`None` while it runs).
    pub end: Option<RunEnd>,
    /// The modes of a modal or buckling analysis.
    pub modes: Option<ModeSet>,
}

impl Memory {
    /// The run's status: `running`, `completed` or `failed: …`.
    pub fn status(&self) -> &str {
        self.end
            .as_ref()
            .map_or(layout::STATUS_RUNNING, |e| e.status.as_str())
    }

    /// The stored times (statics: load factors).
    pub fn time(&self) -> Vec<f64> {
        self.records.iter().map(|r| r.time).collect()
    }

    /// The positions of the node labelled `label` (a tracked node's label,
    /// as in `/nodes/<label>`), one row per kept step.
    pub fn positions(&self, label: &str) -> Option<Vec<[f64; 3]>> {
        let &(_, node) = self.meta.tracked.iter().find(|(l, _)| l == label)?;
        Some(self.records.iter().map(|r| r.positions[node]).collect())
    }
}

impl Sink for Memory {
    fn begin(&mut self, meta: &RunMeta) -> Result<(), SinkError> {
        self.meta = meta.clone();
        Ok(())
    }

    fn step(&mut self, record: &StepRecord) -> Result<(), SinkError> {
        self.records.push(record.clone());
        Ok(())
    }

    fn take_step(&mut self, record: StepRecord) -> Result<(), SinkError> {
        self.records.push(record);
        Ok(())
    }

    fn checkpoint(&mut self, state: &Checkpoint) -> Result<(), SinkError> {
        self.checkpoint = Some(state.clone());
        Ok(())
    }

    fn modes(&mut self, set: &ModeSet, _joints: &[String]) -> Result<(), SinkError> {
        self.modes = Some(set.clone());
        Ok(())
    }

    fn finish(&mut self, end: &RunEnd) -> Result<(), SinkError> {
        self.end = Some(end.clone());
        Ok(())
    }
}

/// Hands every kept step to a closure (a live plot, a controller, a
/// convergence monitor); nothing is stored.
pub struct OnStep<F: FnMut(&StepRecord)>(pub F);

impl<F: FnMut(&StepRecord)> Sink for OnStep<F> {
    fn begin(&mut self, _meta: &RunMeta) -> Result<(), SinkError> {
        Ok(())
    }

    fn step(&mut self, record: &StepRecord) -> Result<(), SinkError> {
        (self.0)(record);
        Ok(())
    }

    fn finish(&mut self, _end: &RunEnd) -> Result<(), SinkError> {
        Ok(())
    }
}

/// The result file (HDF5, the contract of `MODEL_FORMAT.md`), written
/// incrementally: a run that fails part-way leaves a valid file holding
/// every step computed before, with `status = "failed: …"`.
#[derive(Debug)]
pub struct FileSink {
    path: PathBuf,
    restarted_from: Option<(PathBuf, f64)>,
    writer: Option<ResultWriter>,
    written: usize,
}

impl FileSink {
    /// A sink writing `path` (parent directories must exist).
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            restarted_from: None,
            writer: None,
            written: 0,
        }
    }

    /// The file records that the run continues `result` from time `time`.
    pub fn restarted_from(mut self, result: &Path, time: f64) -> Self {
        self.restarted_from = Some((result.to_path_buf(), time));
        self
    }

    /// Steps written so far.
    pub fn steps_written(&self) -> usize {
        self.writer
            .as_ref()
            .map_or(self.written, ResultWriter::steps_written)
    }

    fn writer(&mut self) -> Result<&mut ResultWriter, SinkError> {
        self.writer
            .as_mut()
            .ok_or_else(|| "the result file was not created (no `begin`)".into())
    }
}

impl Sink for FileSink {
    fn begin(&mut self, meta: &RunMeta) -> Result<(), SinkError> {
        let dir = self
            .path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|source| OutputDirError {
            dir: dir.to_path_buf(),
            source,
        })?;
        let mut writer = ResultWriter::create(&self.path, meta)?;
        if let Some((from, time)) = &self.restarted_from {
            writer.restarted_from(from, *time)?;
        }
        self.writer = Some(writer);
        Ok(())
    }

    fn step(&mut self, record: &StepRecord) -> Result<(), SinkError> {
        Ok(self.writer()?.append(record)?)
    }

    fn take_step(&mut self, record: StepRecord) -> Result<(), SinkError> {
        Ok(self.writer()?.append_owned(record)?)
    }

    fn checkpoint(&mut self, state: &Checkpoint) -> Result<(), SinkError> {
        Ok(self.writer()?.checkpoint(state)?)
    }

    fn wants_checkpoint(&self) -> bool {
        // Only the state at the last step of a write is kept.
        self.writer
            .as_ref()
            .is_none_or(ResultWriter::wants_checkpoint)
    }

    fn modes(&mut self, set: &ModeSet, joints: &[String]) -> Result<(), SinkError> {
        Ok(self.writer()?.modes(set, joints)?)
    }

    fn finish(&mut self, end: &RunEnd) -> Result<(), SinkError> {
        let mut writer = self
            .writer
            .take()
            .ok_or("the result file was not created (no `begin`)")?;
        self.written = writer.steps_written();
        if let Err(e) = writer.figures(&end.merit) {
            let _ = writer.finish(&layout::failed_status(&e.to_string()), end.wall_time_s);
            return Err(e.into());
        }
        if !end.warnings.is_empty() {
            writer.warn(&end.warnings.join("; "))?;
        }
        writer.path_end(end.end_reason.as_deref(), &end.critical)?;
        writer.finish(&end.status, end.wall_time_s)?;
        Ok(())
    }

    fn file(&self) -> Option<&Path> {
        Some(&self.path)
    }
}

/// The directory of a result file could not be created.
#[derive(Debug, thiserror::Error)]
#[error("cannot create the output directory {}: {source}", .dir.display())]
pub struct OutputDirError {
    /// The directory.
    pub dir: PathBuf,
    /// The system's error.
    #[source]
    pub source: std::io::Error,
}
