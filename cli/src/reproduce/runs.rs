//! The runs of a reproduction: every (model, integrator) pair in parallel,
//! and what each left in its result file. Each example's runs are a study
//! defined in Rust over the example's model ([`example_study`]): its grid
//! sets the integrator (and the step and end time), the study machinery
//! builds each run's model.

use super::{result_path, ReproduceError, CONSISTENCY_INTEGRATORS, CONSISTENCY_MODEL, INTEGRATORS};
use flexmech_integrators::threads::one_thread_each;
use flexmech_model::{parse_model, Analysis};
use flexmech_results::reader::drift_of;
use flexmech_results::run::{run_model_to, RunError};
use flexmech_results::{ReadError, ResultReader};
use flexmech_studies::execute::plans;
use flexmech_studies::sweep::{model_for, RunPlan};
use flexmech_studies::{Figure, StudySpec};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use toml::Value;

/// One run of a reproduction, with the series the charts and the summary use.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Model name (`screw_free`, …).
    pub model: String,
    /// Integrator name (`newmark`, `momentum`, `energy-momentum`).
    pub integrator: String,
    /// The result file.
    pub file: PathBuf,
    /// `completed` or `failed: …`.
    pub status: String,
    /// Time of the last converged step when the run failed.
    pub failure_time: Option<f64>,
    /// Nominal step of the run (the model's, or half of it in the
    /// consistency study).
    pub nominal_dt: f64,
    /// Stored times (the first row is t = 0).
    pub time: Vec<f64>,
    /// Total energy minus the drivers' work (the conserved quantity).
    pub balance: Vec<f64>,
    /// Step size actually used.
    pub dt: Vec<f64>,
    /// Newton iterations per step.
    pub iterations: Vec<f64>,
    /// Energy–momentum β (NaN for the other schemes).
    pub beta: Vec<f64>,
    /// Wall time of the solve, seconds.
    pub wall_time_s: f64,
    /// The scale energy errors are measured against: the larger of the
    /// initial energy |E₀| and the largest |driver work| of the run.
    pub energy_scale: f64,
}

impl RunRecord {
    /// The run's energy drift ([`flexmech_results::reader::energy_drift`]).
    pub fn energy_drift(&self) -> f64 {
        drift_of(&self.balance, self.energy_scale)
    }

    /// Steps taken with less than the nominal step (halvings in force); the
    /// last step, which may be shortened to end at `t_end`, is not counted.
    pub fn reduced_steps(&self) -> usize {
        let n = self.dt.len();
        self.dt
            .iter()
            .take(n.saturating_sub(1))
            .skip(1)
            .filter(|&&d| d < self.nominal_dt * (1.0 - 1e-9))
            .count()
    }

    /// The smallest step used (the last, possibly shortened, step aside).
    pub fn min_dt(&self) -> f64 {
        let n = self.dt.len();
        self.dt
            .iter()
            .take(n.saturating_sub(1))
            .skip(1)
            .fold(self.nominal_dt, |m, &d| m.min(d))
    }
}

/// The study of one paper example: a grid over `solver.integrator`
/// (`integrators`), with `solver.t_end` scaled by `time_scale` (when it is
/// not 1) and `solver.dt` halved for the consistency study's `half_step`
/// runs. Every run's model is the example's with those values put in and
/// every model-file check applied, so its result file stores exactly the
/// model it ran.
pub fn example_study(
    (name, path, text): (&str, &str, &str),
    integrators: &[&str],
    half_step: bool,
    time_scale: f64,
) -> Result<StudySpec, ReproduceError> {
    let fail = |message: String| ReproduceError::Run {
        model: name.to_string(),
        integrator: integrators.join(", "),
        message,
    };
    let base = parse_model(text, Path::new(path)).map_err(|e| fail(e.to_string()))?;
    let Analysis::Dynamic { dt, t_end, .. } = base.solver.analysis else {
        return Err(fail("the paper's examples are dynamic analyses".into()));
    };
    let mut grid = vec![(
        "solver.integrator".to_string(),
        integrators.iter().map(|&i| Value::from(i)).collect(),
    )];
    if time_scale != 1.0 {
        grid.push(("solver.t_end".into(), vec![Value::from(t_end * time_scale)]));
    }
    if half_step {
        grid.push(("solver.dt".into(), vec![Value::from(dt * 0.5)]));
    }
    let study = if half_step {
        format!("{name}-half-dt")
    } else {
        name.to_string()
    };
    StudySpec::over_model(&study, Path::new(path), text, grid, Figure::ALL.to_vec())
        .map_err(|e| fail(e.to_string()))
}

/// One run of a reproduction: the example, its study and the run's plan.
struct Job {
    model: &'static str,
    study: usize,
    plan: RunPlan,
    half_step: bool,
}

/// Runs every model of `models` with every integrator, and the consistency
/// study's half-step runs, in parallel. Returns `(runs, half_step)`.
pub fn run_all(
    models: &[(&'static str, &'static str, &'static str)],
    out: &Path,
    time_scale: f64,
) -> Result<(Vec<RunRecord>, Vec<RunRecord>), ReproduceError> {
    let mut studies = Vec::new();
    let mut jobs = Vec::new();
    let mut add = |model: (&'static str, &'static str, &'static str),
                   integrators: &[&str],
                   half_step: bool|
     -> Result<(), ReproduceError> {
        let spec = example_study(model, integrators, half_step, time_scale)?;
        jobs.extend(plans(&spec).into_iter().map(|plan| Job {
            model: model.0,
            study: studies.len(),
            plan,
            half_step,
        }));
        studies.push(spec);
        Ok(())
    };
    for &model in models {
        add(model, &INTEGRATORS, false)?;
    }
    for &model in models.iter().filter(|m| m.0 == CONSISTENCY_MODEL) {
        add(model, &CONSISTENCY_INTEGRATORS, true)?;
    }
    let mut all: Vec<RunRecord> = jobs
        .par_iter()
        .map(|job| one_thread_each(|| run_one(job, &studies[job.study], out)))
        .collect::<Result<_, _>>()?;
    let half = all.split_off(all.len() - jobs.iter().filter(|j| j.half_step).count());
    Ok((all, half))
}

fn run_one(job: &Job, spec: &StudySpec, out: &Path) -> Result<RunRecord, ReproduceError> {
    let integrator = job.plan.values[0].as_str().unwrap_or_default();
    let fail = |message: String| ReproduceError::Run {
        model: job.model.to_string(),
        integrator: integrator.to_string(),
        message,
    };
    let model = model_for(spec, &job.plan).map_err(|e| fail(e.to_string()))?;
    let Analysis::Dynamic { dt: nominal_dt, .. } = model.solver.analysis else {
        return Err(fail("the paper's examples are dynamic analyses".into()));
    };
    let file = result_path(out, job.model, integrator, job.half_step);
    match run_model_to(&model, &file) {
        Ok(_) | Err(RunError::Solve { .. }) => {}
        Err(e) => return Err(fail(e.to_string())),
    }
    read_back(job.model, integrator, &file, nominal_dt)
}

/// Reads a run's series back from its result file.
fn read_back(
    model: &str,
    integrator: &str,
    file: &Path,
    nominal_dt: f64,
) -> Result<RunRecord, ReproduceError> {
    let err = |e: ReadError| ReproduceError::Read {
        file: file.to_path_buf(),
        message: e.to_string(),
    };
    let r = ResultReader::open(file).map_err(err)?;
    let time = r.time().map_err(err)?;
    let status = r.status().map_err(err)?;
    let failure_time = r
        .failed()
        .map_err(err)?
        .then(|| time.last().copied().unwrap_or(0.0));
    let record = RunRecord {
        model: model.to_string(),
        integrator: integrator.to_string(),
        file: file.to_path_buf(),
        status,
        failure_time,
        nominal_dt,
        dt: r.values("/solver/dt").map_err(err)?,
        iterations: r
            .counts("/solver/iterations")
            .map_err(err)?
            .into_iter()
            .map(|i| i as f64)
            .collect(),
        beta: r.values("/solver/beta").map_err(err)?,
        time,
        balance: r.energy_balance().map_err(err)?,
        wall_time_s: r.wall_time_s(),
        energy_scale: r.energy_scale().map_err(err)?.max(f64::MIN_POSITIVE),
    };
    Ok(record)
}
