//! `flexmech.Simulation`: a dynamic model stepped from Python — the Rust
//! `Simulation` of the model's mechanism, its state read as the result
//! file's `/configuration` rows, its kept steps saved as a result file with
//! its `/restart` state, continued from such a file.

use std::path::{Path, PathBuf};
use std::time::Instant;

use flexmech::integrators::dynamics::{DynamicSettings, Simulation};
use flexmech::integrators::StepRecord;
use flexmech::model::build::{build, Built};
use flexmech::model::{Analysis, Model};
use flexmech::results::layout;
use flexmech::results::{FileSink, Merit, RunChecks, RunEnd, RunMeta, Sink, SinkError};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{key_error, run_error};
use crate::model::PyModel;
use crate::run::Interrupt;

/// The Rust simulation borrowing its mechanism.
type Sim<'a> = Simulation<'a>;

self_cell::self_cell!(
    /// A built model and the simulation stepping its mechanism.
    struct Stepper {
        owner: Built,
        #[not_covariant]
        dependent: Sim,
    }
);

/// A sink that keeps the run's description and stops the run before its
/// first step: how a simulation gets the `RunMeta` a run would write.
#[derive(Default)]
struct MetaOnly(Option<RunMeta>);

const META_ONLY: &str = "description taken";

impl Sink for MetaOnly {
    fn begin(&mut self, meta: &RunMeta) -> Result<(), SinkError> {
        self.0 = Some(meta.clone());
        Err(META_ONLY.into())
    }
    fn step(&mut self, _: &StepRecord) -> Result<(), SinkError> {
        Ok(())
    }
    fn finish(&mut self, _: &RunEnd) -> Result<(), SinkError> {
        Ok(())
    }
}

/// Moves a value into a closure run while the interpreter is released: the
/// closure runs on this thread (`Python::detach`), which owns the value.
struct OnThisThread<T>(T);

// SAFETY: `Python::detach` runs its closure on the calling thread, the
// thread that owns the simulation (`unsendable`); the value never moves to
// another thread.
unsafe impl<T> Send for OnThisThread<T> {}

impl<T> OnThisThread<T> {
    fn get(self) -> T {
        self.0
    }
}

/// A dynamic model stepped from Python.
#[pyclass(name = "Simulation", module = "flexmech", unsendable)]
pub struct PySimulation {
    stepper: Stepper,
    model: Model,
    meta: RunMeta,
    /// The kept steps (every `output.every`-th; the last is `pending`).
    kept: Vec<StepRecord>,
    pending: Option<StepRecord>,
    count: usize,
    merit: Merit,
    /// The checks a run passes (energy balance), for the file's `warnings`.
    checks: RunChecks,
    current: StepRecord,
    failed: Option<String>,
    finished: bool,
    wall_time_s: f64,
    restarted_from: Option<(PathBuf, f64)>,
}

/// The dynamic settings of `model`, as a run uses them.
fn settings(model: &Model) -> Option<(flexmech::model::IntegratorKind, DynamicSettings)> {
    model.solver.dynamic_settings()
}

impl PySimulation {
    /// Builds `model` and starts its simulation: from t = 0, or from the
    /// restart state stored in `restart`.
    fn start(
        py: Python<'_>,
        pymodel: &Bound<'_, PyModel>,
        restart: Option<&Path>,
    ) -> PyResult<Self> {
        let model = pymodel.borrow_mut().checked(py)?;
        let Some((integrator, settings)) = settings(&model) else {
            return Err(key_error(
                py,
                "solver.analysis",
                "a Simulation steps a dynamic analysis; run a static one with flexmech.run",
            ));
        };
        let mut meta = MetaOnly::default();
        match flexmech::results::run(&model, &mut meta) {
            Err(flexmech::results::RunError::Model(e)) => {
                return Err(pymodel.borrow().model_error(py, &e))
            }
            _ if meta.0.is_none() => {
                return Err(run_error("the model's run description could not be made"))
            }
            _ => {}
        }
        let meta = meta.0.unwrap_or_default();
        let built = build(&model).map_err(|e| pymodel.borrow().model_error(py, &e))?;
        let checkpoint = match restart {
            None => None,
            Some(path) => Some(restart_state(&model, &built, path)?),
        };
        let stepper = Stepper::try_new(built, |b| match &checkpoint {
            Some(c) => Simulation::resume(&b.mechanism, integrator, &settings, c),
            None => Simulation::new(&b.mechanism, integrator, &settings, &b.motion),
        })
        .map_err(|e| {
            run_error(format!(
                "{}: model \"{}\": {e}",
                model.path.display(),
                model.name
            ))
        })?;
        let current = stepper.with_dependent(|_, sim| sim.record());
        let merit = Merit::new(
            meta.tracked
                .iter()
                .map(|&(_, n)| (n, meta.initial_positions[n]))
                .collect(),
        );
        let checks = RunChecks::new(&model);
        let mut sim = Self {
            stepper,
            model,
            meta,
            kept: Vec::new(),
            pending: None,
            count: 0,
            merit,
            checks,
            current: current.clone(),
            failed: None,
            finished: false,
            wall_time_s: 0.0,
            restarted_from: checkpoint
                .map(|c| (restart.unwrap_or(Path::new("")).to_path_buf(), c.time)),
        };
        sim.keep(current);
        Ok(sim)
    }

    /// Counts a converged step's record and keeps it as a run would
    /// (every `output.every`-th, and the last).
    fn keep(&mut self, record: StepRecord) {
        self.merit.push(&record);
        let mech = &self.stepper.borrow_owner().mechanism;
        self.checks.push(mech, &record);
        self.count += 1;
        if flexmech::results::run::is_kept(self.count, self.model.output.every) {
            self.pending = None;
            self.kept.push(record);
        } else {
            self.pending = Some(record);
        }
    }

    /// Steps while `go(time)` holds (and t_end is not reached), looking for
    /// Ctrl-C; returns the steps taken. Runs without the interpreter.
    fn advance(&mut self, mut go: impl FnMut(f64) -> bool) -> Result<usize, Stop> {
        if let Some(f) = &self.failed {
            return Err(Stop::Failed(f.clone()));
        }
        let mut interrupt = Interrupt::default();
        let mut taken = 0;
        while !self.finished && go(self.current.time) {
            let start = Instant::now();
            let outcome = self.stepper.with_dependent_mut(|_, sim| sim.step());
            self.wall_time_s += start.elapsed().as_secs_f64();
            match outcome {
                Ok(Some(record)) => {
                    self.current = record.clone();
                    self.keep(record);
                    taken += 1;
                }
                Ok(None) => self.finished = true,
                Err(e) => {
                    let message = format!(
                        "{}: model \"{}\": {e}",
                        self.model.path.display(),
                        self.model.name
                    );
                    self.failed = Some(message.clone());
                    return Err(Stop::Failed(message));
                }
            }
            if interrupt.interrupted() {
                return Err(Stop::Interrupted(interrupt.error.take()));
            }
        }
        Ok(taken)
    }

    /// Writes the kept steps, the restart state and the end into `file`.
    fn write(&self, file: &Path) -> Result<(), SinkError> {
        let mut sink = FileSink::new(file);
        if let Some((from, time)) = &self.restarted_from {
            sink = sink.restarted_from(from, *time);
        }
        sink.begin(&self.meta)?;
        for r in self.kept.iter().chain(&self.pending) {
            sink.step(r)?;
        }
        sink.checkpoint(&self.stepper.with_dependent(|_, sim| sim.checkpoint()))?;
        let status = match (&self.failed, self.finished || self.at_end()) {
            (Some(f), _) => layout::failed_status(f),
            (None, true) => layout::STATUS_COMPLETED.to_owned(),
            (None, false) => layout::STATUS_RUNNING.to_owned(),
        };
        // As a run's: the checks speak for a completed run only.
        let completed = status == layout::STATUS_COMPLETED;
        sink.finish(&RunEnd {
            status,
            wall_time_s: self.wall_time_s,
            merit: self.merit.clone(),
            warnings: if completed {
                self.checks.warnings()
            } else {
                Vec::new()
            },
            end_reason: None,
            critical: Vec::new(),
        })
    }

    fn t_end(&self) -> f64 {
        match self.model.solver.analysis {
            Analysis::Dynamic { t_end, .. } => t_end,
            _ => 0.0,
        }
    }

    /// Whether the time is t_end (a further step would return nothing).
    fn at_end(&self) -> bool {
        self.current.time >= self.t_end()
    }
}

/// Why stepping stopped early.
enum Stop {
    Failed(String),
    Interrupted(Option<PyErr>),
}

impl From<Stop> for PyErr {
    fn from(s: Stop) -> Self {
        match s {
            Stop::Failed(m) => run_error(m),
            Stop::Interrupted(Some(e)) => e,
            Stop::Interrupted(None) => pyo3::exceptions::PyKeyboardInterrupt::new_err(()),
        }
    }
}

/// The restart state in `path`, checked against `model` as `flexmech run
/// --restart` checks it.
fn restart_state(
    model: &Model,
    built: &Built,
    path: &Path,
) -> PyResult<flexmech::integrators::dynamics::Checkpoint> {
    flexmech::results::restart_state(model, built, path).map_err(run_error)
}

/// Rows of `n` numbers as a NumPy array (rows × n).
fn rows<'py, const N: usize>(py: Python<'py>, rows: &[[f64; N]]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let a = Array2::from_shape_vec((rows.len(), N), flat)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

#[pymethods]
impl PySimulation {
    /// Starts the simulation of the dynamic `model` at t = 0 (its drivers
    /// imposed, initial velocities set), as a run starts it.
    #[new]
    fn new(py: Python<'_>, model: &Bound<'_, PyModel>) -> PyResult<Self> {
        Self::start(py, model, None)
    }

    /// Continues the run stored in the result file `path` (its `/restart`
    /// state, written by `save` or by any dynamic run) with `model` — the
    /// same mechanism, integrator and `dt`, a later `t_end` — as `flexmech
    /// run MODEL --restart RESULT` does.
    #[staticmethod]
    fn restart(py: Python<'_>, model: &Bound<'_, PyModel>, path: PathBuf) -> PyResult<Self> {
        Self::start(py, model, Some(&path))
    }

    /// Advances one converged step (halving and retrying as the run would);
    /// returns False, without stepping, once `t_end` is reached. Raises
    /// `RunError` when the solver stops (the state stays the last converged
    /// one; `save` keeps the steps with `status = "failed: ..."`).
    fn step(mut slf: PyRefMut<'_, Self>) -> PyResult<bool> {
        let py = slf.py();
        let this = OnThisThread(&mut *slf);
        let mut first = true;
        let taken =
            py.detach(move || this.get().advance(|_| std::mem::replace(&mut first, false)))?;
        Ok(taken == 1)
    }

    /// Steps until the time reaches `t` (or `t_end`); returns the number of
    /// steps taken. With `t` a multiple of `dt` the state equals that of a
    /// run to `t_end = t`. Ctrl-C stops after the step in progress.
    fn run_until(mut slf: PyRefMut<'_, Self>, t: f64) -> PyResult<usize> {
        let py = slf.py();
        let dt = match slf.model.solver.analysis {
            Analysis::Dynamic { dt, .. } => dt,
            _ => 0.0,
        };
        let this = OnThisThread(&mut *slf);
        // Stored times are n·dt: a relative margin keeps t itself a stop.
        let target = t - 1e-9 * dt;
        Ok(py.detach(move || this.get().advance(|time| time < target))?)
    }

    /// Steps to `t_end`; returns the number of steps taken.
    fn run(mut slf: PyRefMut<'_, Self>) -> PyResult<usize> {
        let py = slf.py();
        let this = OnThisThread(&mut *slf);
        Ok(py.detach(move || this.get().advance(|_| true))?)
    }

    /// The current time.
    #[getter]
    fn time(&self) -> f64 {
        self.current.time
    }

    /// The model's end time.
    #[getter(t_end)]
    fn get_t_end(&self) -> f64 {
        self.t_end()
    }

    /// Converged steps taken (the initial state not counted).
    #[getter]
    fn steps(&self) -> usize {
        self.count.saturating_sub(1)
    }

    /// `"running"`, `"completed"` (t_end reached) or `"failed: ..."`.
    #[getter]
    fn status(&self) -> String {
        match &self.failed {
            Some(f) => layout::failed_status(f),
            None if self.finished || self.at_end() => layout::STATUS_COMPLETED.to_owned(),
            None => layout::STATUS_RUNNING.to_owned(),
        }
    }

    /// Every node's position (nodes × 3), as a row of
    /// `/configuration/position`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.current.positions)
    }

    /// Every node's triad as a unit quaternion (w, x, y, z) (nodes × 4), as
    /// a row of `/configuration/quaternion`.
    #[getter]
    fn quaternions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.current.quaternions)
    }

    /// Every node's translational velocity (nodes × 3), as a row of
    /// `/configuration/velocity`.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.current.velocities)
    }

    /// Every node's angular velocity `ω = R W` in spatial components
    /// (nodes × 3), as a row of `/configuration/angular_velocity`.
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows(py, &self.current.angular_velocities)
    }

    /// Every node's label in `/configuration` order (`/mesh/node_labels`).
    #[getter]
    fn node_labels(&self) -> Vec<String> {
        self.meta
            .mesh
            .as_ref()
            .map(|m| m.node_labels.clone())
            .unwrap_or_default()
    }

    /// The energies of the current state: `kinetic`, `strain`,
    /// `potential`, `total`, `driver_work` (as `/energy/*`).
    #[getter]
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = &self.current.energy;
        let d = PyDict::new(py);
        d.set_item("kinetic", e.kinetic)?;
        d.set_item("strain", e.strain)?;
        d.set_item("potential", e.potential)?;
        d.set_item("total", e.total)?;
        d.set_item("driver_work", e.driver_work)?;
        Ok(d)
    }

    /// Writes the kept steps (every `output.every`-th and the last) into
    /// the result file `path` with the `/restart` state of the current step
    /// — the file a run to the current time writes, with `status`
    /// `"running"` before `t_end`. Returns `path`.
    fn save(mut slf: PyRefMut<'_, Self>, path: PathBuf) -> PyResult<String> {
        let py = slf.py();
        let this = OnThisThread(&mut *slf);
        let file = path.clone();
        py.detach(move || this.get().write(&file))
            .map_err(|e| run_error(format!("{}: {e}", path.display())))?;
        Ok(path.display().to_string())
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulation({:?}, time={}, steps={}, status={:?})",
            self.model.name,
            self.current.time,
            self.steps(),
            self.status()
        )
    }
}
