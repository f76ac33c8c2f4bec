//! Running one model: build it, solve it, stream every kept step into its
//! HDF5 result file. A run that fails part-way still leaves a valid file with
//! `status = "failed: …"` and every step computed before the failure.

use crate::build::{build, Built};
use crate::checks::{Balance, Stability};
use crate::model::{Analysis, IntegratorKind, MassKind, Model, ModelError};
use crate::results::{layout, ResultError, ResultWriter, RunMeta};
use flexmech_integrators::dynamics::{
    energy_momentum, energy_momentum_paper, momentum, newmark, DynamicSettings,
};
use flexmech_integrators::{
    solve_static, Mechanism, NewtonSettings, SolveError, StaticSettings, StepRecord,
};
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// Why a run did not complete.
#[derive(Debug, Error)]
pub enum RunError {
    /// The model could not be loaded or built.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The output directory could not be created.
    #[error("cannot create the output directory {dir}: {source}")]
    OutputDir {
        dir: PathBuf,
        source: std::io::Error,
    },
    /// Writing the result file failed.
    #[error(transparent)]
    Result(#[from] ResultError),
    /// Two models of one `flexmech run` have the same `name`: the second
    /// would overwrite the first's result file, so it is refused.
    #[error(
        "{}: key `name`: \"{name}\" is also the name of {} in this run; their results would \
         overwrite each other ({name}.h5): give one of them another name",
        file.display(),
        first.display()
    )]
    DuplicateName {
        name: String,
        file: PathBuf,
        first: PathBuf,
    },
    /// The solver stopped; `file` holds the steps computed before.
    #[error(
        "{}: model \"{model}\": {error} (steps computed so far are in {})",
        path.display(),
        file.display()
    )]
    Solve {
        model: String,
        /// The model file.
        path: PathBuf,
        error: Box<SolveError>,
        file: PathBuf,
    },
}

/// What a completed run reports.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// The result file.
    pub file: PathBuf,
    /// Converged steps.
    pub steps: usize,
    /// Steps written (every `output.every`-th and the last).
    pub written: usize,
    /// Total Newton iterations.
    pub iterations: usize,
    /// Wall time of the solve, seconds.
    pub wall_time_s: f64,
    /// What the run's checks found doubtful in the completed result (also in
    /// the file's root attribute `warnings`).
    pub warnings: Vec<String>,
}

pub use crate::checks::ENERGY_BALANCE_WARNING;

/// Keeps every `every`-th step and always the last one.
struct Sink<'a> {
    writer: ResultWriter,
    mech: &'a Mechanism,
    /// The energy balance, for dynamic runs.
    balance: Option<Balance>,
    /// The stability of the load path, for static runs.
    stability: Option<Stability>,
    every: usize,
    count: usize,
    iterations: usize,
    pending: Option<StepRecord>,
    error: Option<ResultError>,
}

impl Sink<'_> {
    fn push(&mut self, step: &StepRecord) {
        if let Some(b) = &mut self.balance {
            b.push(self.mech, step);
        }
        if let Some(s) = &mut self.stability {
            s.push(step);
        }
        self.count += 1;
        self.iterations += step.iterations;
        if self.error.is_some() {
            return;
        }
        if self.count.is_multiple_of(self.every) {
            self.pending = None;
            if let Err(e) = self.writer.append(step) {
                self.error = Some(e);
            }
        } else {
            self.pending = Some(step.clone());
        }
    }

    fn flush_last(&mut self) {
        if let (Some(step), None) = (self.pending.take(), &self.error) {
            if let Err(e) = self.writer.append(&step) {
                self.error = Some(e);
            }
        }
    }
}

/// Whether the stability count of a static `model` is a stability
/// statement (see [`Stability`]): no applied nodal moment, no prescribed
/// nodal rotation.
fn conservative(model: &Model) -> bool {
    model.loads.iter().all(|l| l.moment == [0.0; 3])
        && model.prescribed.iter().all(|p| match p {
            crate::model::PrescribedSpec::NodeDof { dof, .. } => *dof < 3,
            crate::model::PrescribedSpec::JointAngle { .. } => true,
        })
}

/// Runs `model` and writes `out_dir/<name>.h5`.
pub fn run_model(model: &Model, out_dir: &Path) -> Result<RunSummary, RunError> {
    run_model_to(model, &out_dir.join(format!("{}.h5", model.name)))
}

/// Runs `model` and writes its results to `file` (parent directories are
/// created).
pub fn run_model_to(model: &Model, file: &Path) -> Result<RunSummary, RunError> {
    let built: Built = build(model)?;
    let out_dir = file
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(out_dir).map_err(|source| RunError::OutputDir {
        dir: out_dir.to_path_buf(),
        source,
    })?;
    let file = file.to_path_buf();
    let mech = &built.mechanism;
    let meta = RunMeta {
        model_text: model.source_text.clone(),
        integrator: match model.solver.analysis {
            Analysis::Static { .. } => "static".to_string(),
            Analysis::Dynamic { integrator, .. } => integrator.name().to_string(),
        },
        initial_positions: mech
            .mesh
            .positions
            .iter()
            .map(|x| [x.x, x.y, x.z])
            .collect(),
        tracked: model
            .output
            .track
            .iter()
            .map(|(label, r)| (label.clone(), built.node(*r)))
            .collect(),
        joint_names: model.joints.iter().map(|j| j.name.clone()).collect(),
    };
    let writer = ResultWriter::create(&file, &meta)?;
    let dynamic = matches!(model.solver.analysis, Analysis::Dynamic { .. });
    let mut sink = Sink {
        writer,
        mech,
        balance: dynamic.then(Balance::default),
        stability: (!dynamic).then(|| Stability::new(conservative(model))),
        every: model.output.every.max(1),
        count: 0,
        iterations: 0,
        pending: None,
        error: None,
    };
    let start = Instant::now();
    let outcome = match model.solver.analysis {
        Analysis::Static { load_steps } => {
            let settings = StaticSettings {
                load_steps,
                newton: NewtonSettings {
                    tolerance: model.solver.tolerance,
                    max_iterations: model.solver.max_iterations,
                    modified: false,
                },
                max_halvings: model.solver.max_halvings,
            };
            solve_static(mech, &settings, |s| sink.push(s)).map(|_| ())
        }
        Analysis::Dynamic {
            integrator,
            dt,
            t_end,
        } => {
            let settings = DynamicSettings {
                dt,
                t_end,
                newton: NewtonSettings {
                    tolerance: model.solver.tolerance,
                    max_iterations: model.solver.max_iterations,
                    modified: model.solver.modified_newton,
                },
                max_halvings: model.solver.max_halvings,
                mass: match model.solver.mass {
                    MassKind::Consistent => flexmech_core::MassKind::Consistent,
                    MassKind::Lumped => flexmech_core::MassKind::Lumped,
                },
            };
            let push = |s: &StepRecord| sink.push(s);
            match integrator {
                IntegratorKind::Newmark => newmark::solve(mech, &settings, &built.motion, push),
                IntegratorKind::Momentum => momentum::solve(mech, &settings, &built.motion, push),
                IntegratorKind::EnergyMomentum => {
                    energy_momentum::solve(mech, &settings, &built.motion, push)
                }
                IntegratorKind::EnergyMomentumPaper => {
                    energy_momentum_paper::solve(mech, &settings, &built.motion, push)
                }
            }
            .map(|_| ())
        }
    };
    let wall = start.elapsed().as_secs_f64();
    sink.flush_last();
    if let Some(e) = sink.error.take() {
        // The file is as valid as HDF5 left it; report the write failure.
        let _ = sink
            .writer
            .finish(&layout::failed_status(&e.to_string()), wall);
        return Err(e.into());
    }
    let written = sink.writer.steps_written();
    match outcome {
        Ok(()) => {
            let warnings: Vec<String> = sink
                .balance
                .as_ref()
                .and_then(Balance::warning)
                .into_iter()
                .chain(sink.stability.as_ref().and_then(Stability::warning))
                .collect();
            if !warnings.is_empty() {
                sink.writer.warn(&warnings.join("; "))?;
            }
            let file = sink.writer.finish(layout::STATUS_COMPLETED, wall)?;
            Ok(RunSummary {
                file,
                steps: sink.count,
                written,
                iterations: sink.iterations,
                wall_time_s: wall,
                warnings,
            })
        }
        Err(mut error) => {
            name_the_beam(model, &built, &mut error);
            let file = sink
                .writer
                .finish(&layout::failed_status(&error.to_string()), wall)?;
            Err(RunError::Solve {
                model: model.name.clone(),
                path: model.path.clone(),
                error: Box::new(error),
                file,
            })
        }
    }
}

/// Names the model's own entries in an error: the beam (and the element
/// within it) of an element — elements are numbered beam after beam, in the
/// model's order — and the `[[prescribed]]` entry of a prescribed nodal DOF
/// (the mechanism numbers only the nodal ones), and the nodes of a free
/// motion.
fn name_the_beam(model: &Model, built: &Built, error: &mut SolveError) {
    if let SolveError::Unrestrained { motion, .. } = error {
        motion.labels = motion
            .nodes
            .iter()
            .map(|&n| {
                built
                    .beam_nodes
                    .iter()
                    .enumerate()
                    .find_map(|(b, nodes)| {
                        nodes
                            .iter()
                            .position(|&m| m == n)
                            .map(|k| model.node_label(crate::model::NodeRef { beam: b, node: k }))
                    })
                    .unwrap_or_else(|| format!("node {n}"))
            })
            .collect();
    }
    if let SolveError::PrescribedRotationStep { index, .. } = error {
        if let Some(i) = model
            .prescribed
            .iter()
            .enumerate()
            .filter(|(_, p)| matches!(p, crate::model::PrescribedSpec::NodeDof { .. }))
            .nth(*index)
            .map(|(i, _)| i)
        {
            *index = i;
        }
    }
    if let SolveError::ElementRotation { element, beam, .. } = error {
        let mut first = 0;
        for b in &model.beams {
            if *element < first + b.elements {
                *beam = format!(
                    " (element {} of beam \"{}\", which has {})",
                    *element - first,
                    b.name,
                    b.elements
                );
                return;
            }
            first += b.elements;
        }
    }
}
