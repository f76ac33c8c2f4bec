//! The runs of a reproduction: every (model, integrator) pair in parallel,
//! and what each left in its result file.

use super::{result_path, ReproduceError, CONSISTENCY_INTEGRATORS, CONSISTENCY_MODEL, INTEGRATORS};
use crate::model::parse_model;
use crate::results::reader::drift_of;
use crate::results::{ReadError, ResultReader};
use crate::run::{run_model_to, RunError};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

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
    /// The run's energy drift ([`crate::results::reader::energy_drift`]).
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

/// Runs every model of `models` with every integrator, and the consistency
/// study's half-step runs, in parallel. Returns `(runs, half_step)`.
pub fn run_all(
    models: &[(&str, &str, &str)],
    out: &Path,
    time_scale: f64,
) -> Result<(Vec<RunRecord>, Vec<RunRecord>), ReproduceError> {
    let mut jobs: Vec<(&str, &str, &str, &str, bool)> = models
        .iter()
        .flat_map(|&(name, path, text)| {
            INTEGRATORS
                .iter()
                .map(move |&i| (name, path, text, i, false))
        })
        .collect();
    for &(name, path, text) in models.iter().filter(|m| m.0 == CONSISTENCY_MODEL) {
        jobs.extend(
            CONSISTENCY_INTEGRATORS
                .iter()
                .map(|&i| (name, path, text, i, true)),
        );
    }
    let mut all: Vec<RunRecord> = jobs
        .par_iter()
        .map(|&(name, path, text, integrator, half)| {
            run_one(name, path, text, integrator, half, out, time_scale)
        })
        .collect::<Result<_, _>>()?;
    let half = all.split_off(all.len() - (jobs.iter().filter(|j| j.4).count()));
    Ok((all, half))
}

/// The number on a `key = value  # comment` line.
fn value_of(line: &str) -> f64 {
    line.split('=')
        .nth(1)
        .and_then(|v| v.split('#').next())
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0.0)
}

/// The model text with the integrator (and `t_end`, scaled, and `dt`,
/// halved for a half-step run) replaced, so the result file's stored model
/// reproduces exactly this run.
fn adapted_text(text: &str, integrator: &str, half_step: bool, time_scale: f64) -> String {
    text.lines()
        .map(|line| {
            let key = line.split('=').next().unwrap_or("").trim();
            if key == "integrator" {
                format!("integrator = \"{integrator}\"")
            } else if key == "t_end" && time_scale != 1.0 {
                format!("t_end = {}", value_of(line) * time_scale)
            } else if key == "dt" && half_step {
                format!("dt = {}", value_of(line) * 0.5)
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn run_one(
    name: &str,
    path: &str,
    text: &str,
    integrator: &str,
    half_step: bool,
    out: &Path,
    time_scale: f64,
) -> Result<RunRecord, ReproduceError> {
    let fail = |message: String| ReproduceError::Run {
        model: name.to_string(),
        integrator: integrator.to_string(),
        message,
    };
    let model = parse_model(
        &adapted_text(text, integrator, half_step, time_scale),
        Path::new(path),
    )
    .map_err(|e| fail(e.to_string()))?;
    let nominal_dt = match model.solver.analysis {
        crate::model::Analysis::Dynamic { dt, .. } => dt,
        crate::model::Analysis::Static { .. } => {
            return Err(fail("the paper's examples are dynamic analyses".into()))
        }
    };
    let file = result_path(out, name, integrator, half_step);
    match run_model_to(&model, &file) {
        Ok(_) | Err(RunError::Solve { .. }) => {}
        Err(e) => return Err(fail(e.to_string())),
    }
    read_back(name, integrator, &file, nominal_dt)
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
