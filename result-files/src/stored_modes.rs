//! Vibration modes about a stored step of a result file (`flexmech modes
//! RESULT.h5 --time T --modes N`): the mechanism held still in that pose,
//! with its stress state — the inertial forces of a motion left out.
//!
//! The state is found again by solving the stored model (its text is in
//! the file) up to the stored step: static paths and dynamic runs are
//! deterministic, so the state is the stored one to the last bit, including
//! what the file does not hold (every joint's released coordinates). The
//! tangent of a state off equilibrium (a dynamic step) is not symmetric; its
//! symmetric part is used and the asymmetry recorded (`/modes` attribute
//! `asymmetry`).

use crate::run::{run_meta, RunError};
use crate::sink::{FileSink, RunEnd, Sink};
use crate::{layout, Merit, ResultReader};
use flexmech_integrators::constraints::MechanismState;
use flexmech_integrators::dynamics::Simulation;
use flexmech_integrators::modal::{vibration_modes, ModeRequest, ModeSet};
use flexmech_integrators::{solve_static_to, StaticSettings, StepRecord};
use flexmech_model::{build, parse_model_with, Analysis, Built, JointRegistry, Model};
use std::path::{Path, PathBuf};

/// Distance (relative to `max(1, |t|)`) within which `--time` names a
/// stored step.
const SAME_TIME: f64 = 1e-9;

/// The modes of a stored step and the file they were written to.
#[derive(Debug)]
pub struct StoredModes {
    /// `<out>/<model name>_modes.h5`: the step's record and `/modes`.
    pub file: PathBuf,
    /// The stored time (load factor) the modes are about.
    pub time: f64,
    /// The modes.
    pub modes: ModeSet,
}

/// The `modes` lowest vibration modes about the step of `result` stored at
/// `time`, written with that step to `<out_dir>/<name>_modes.h5`;
/// `registry` holds the joint kinds the stored model names.
///
/// # Errors
/// A file without a model, a time that is no stored step, an analysis whose
/// steps cannot be found again (arc-length, modal, buckling), or a failed
/// solve or write.
pub fn modes_of_result(
    result: &Path,
    time: f64,
    modes: usize,
    registry: &JointRegistry,
    out_dir: &Path,
) -> Result<StoredModes, RunError> {
    let refuse = |why: String| RunError::StoredModes {
        result: result.to_path_buf(),
        why,
    };
    let reader = ResultReader::open(result).map_err(|e| refuse(e.to_string()))?;
    let text = reader
        .string_attr("model")
        .ok_or_else(|| refuse("the file holds no model text (root attribute `model`)".into()))?;
    let model = parse_model_with(&text, result, registry)?;
    let times = reader.time().map_err(|e| refuse(e.to_string()))?;
    let time = stored_time(&times, time).map_err(refuse)?;
    let built = build(&model)?;
    let (state, record) = state_at(&model, &built, time).map_err(refuse)?;
    let mech = &built.mechanism;
    let request = ModeRequest {
        modes,
        mass: model.solver.mass,
        solver: None,
    };
    let set =
        vibration_modes(mech, &state, time, &request, true).map_err(|e| refuse(e.to_string()))?;
    let file = out_dir.join(format!("{}_modes.h5", model.name));
    let mut sink = FileSink::new(&file);
    let meta = run_meta(&model, &built);
    let written = (|| {
        sink.begin(&meta)?;
        sink.step(&record)?;
        let joints: Vec<String> = mech.joints.iter().map(|j| j.name.clone()).collect();
        sink.modes(&set, &joints)?;
        let merit = Merit::new(Vec::new());
        sink.finish(&RunEnd::new(layout::STATUS_COMPLETED.into(), 0.0, &merit))
    })();
    written.map_err(RunError::from_sink)?;
    Ok(StoredModes {
        file,
        time,
        modes: set,
    })
}

/// The stored time `time` names, or why none.
fn stored_time(times: &[f64], time: f64) -> Result<f64, String> {
    let tol = SAME_TIME * time.abs().max(1.0);
    if let Some(t) = times.iter().find(|t| (*t - time).abs() <= tol) {
        return Ok(*t);
    }
    let nearest = times
        .iter()
        .min_by(|a, b| (*a - time).abs().total_cmp(&(*b - time).abs()))
        .map_or("none".to_string(), |t| format!("{t}"));
    Err(format!(
        "--time {time} is no stored step (the nearest is {nearest}; {} steps from {} to {}): \
         give a stored time (`/time`)",
        times.len(),
        times.first().unwrap_or(&f64::NAN),
        times.last().unwrap_or(&f64::NAN),
    ))
}

/// The state (and its record) of the run of `model` at the stored `time`,
/// solved again.
fn state_at(
    model: &Model,
    built: &Built,
    time: f64,
) -> Result<(MechanismState, StepRecord), String> {
    let mech = &built.mechanism;
    let s = &model.solver;
    match s.analysis {
        Analysis::Static { load_steps } => {
            let settings = StaticSettings {
                load_steps,
                newton: flexmech_integrators::NewtonSettings {
                    tolerance: s.tolerance,
                    max_iterations: s.max_iterations,
                    ..Default::default()
                },
                max_halvings: s.max_halvings,
            };
            let mut last = None;
            let outcome = solve_static_to(mech, &settings, time, |r| last = Some(r.clone()))
                .map_err(|e| format!("solving the stored model again: {e}"))?;
            let record = last.unwrap_or_else(|| initial_record(mech, &outcome.state));
            Ok((outcome.state, record))
        }
        Analysis::Dynamic { integrator, .. } => {
            let (_, settings) = s.dynamic_settings().ok_or("not a dynamic analysis")?;
            let mut sim = Simulation::new(mech, integrator, &settings, &built.motion)
                .map_err(|e| format!("solving the stored model again: {e}"))?;
            while sim.time() < time - SAME_TIME * time.abs().max(1.0) {
                match sim.step() {
                    Ok(Some(_)) => {}
                    Ok(None) => break,
                    Err(e) => return Err(format!("solving the stored model again: {e}")),
                }
            }
            Ok((sim.state().clone(), sim.record()))
        }
        _ => Err(format!(
            "modes are taken about stored steps of static (load control) and dynamic runs; \
             this file is of analysis = \"{}\"{}",
            s.analysis.name(),
            if matches!(s.analysis, Analysis::ArcLength { .. }) {
                " with arc-length control"
            } else {
                ""
            }
        )),
    }
}

/// The record of the unloaded initial state.
fn initial_record(mech: &flexmech_integrators::Mechanism, state: &MechanismState) -> StepRecord {
    let fext = vec![0.0; 6 * mech.mesh.node_count()];
    flexmech_integrators::measure::static_record(mech, state, &fext, 0.0, 0.0, None)
}
