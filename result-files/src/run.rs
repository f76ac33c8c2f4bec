//! Running one model: build it, solve it, stream every kept step into a
//! [`Sink`] — its HDF5 result file ([`run_model`], [`FileSink`]), memory or
//! a closure ([`run`]). A run that fails part-way still leaves its sink
//! every step computed before the failure and `status = "failed: …"`.

use crate::checks::RunChecks;
use crate::sink::{FileSink, OutputDirError, RunEnd, Sink, SinkError};
use crate::{
    layout, read_checkpoint, Merit, MeshMeta, RestartError, ResultError, ResultantsMeta, RunMeta,
};
use flexmech_integrators::arc_length::{solve_arc_length_with, ArcLengthSettings, PathStop};
use flexmech_integrators::constraints::initial_state;
use flexmech_integrators::critical::CriticalPoint;
use flexmech_integrators::dynamics::{Checkpoint, DynamicSettings, Simulation};
use flexmech_integrators::measure::static_record;
use flexmech_integrators::modal::{
    buckling_modes, solve_modal, ModalSettings, ModeKind, ModeRequest, ModeSet,
};
use flexmech_integrators::PathEnd;
use flexmech_integrators::{
    solve_static_with, Mechanism, NewtonSettings, SolveError, StaticSettings, StepRecord,
};
use flexmech_model::build::{build, Built};
use flexmech_model::{Analysis, IntegratorKind, Model, ModelError};
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
        /// The directory.
        dir: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// Writing the result file failed.
    #[error(transparent)]
    Result(#[from] ResultError),
    /// Another sink refused a step or the end.
    #[error("the run's sink failed: {0}")]
    Sink(SinkError),
    /// Two models of one `flexmech run` have the same `name`: the second
    /// would overwrite the first's result file, so it is refused.
    #[error(
        "{}: key `name`: \"{name}\" is also the name of {} in this run; their results would \
         overwrite each other ({name}.h5): give one of them another name",
        file.display(),
        first.display()
    )]
    DuplicateName {
        /// The shared name.
        name: String,
        /// The second model file.
        file: PathBuf,
        /// The first model file with that name.
        first: PathBuf,
    },
    /// The result file to continue cannot be read.
    #[error(transparent)]
    Restart(#[from] RestartError),
    /// The ParaView series of `[output] vtk = true` could not be written
    /// (the result file is complete).
    #[error(transparent)]
    Export(#[from] crate::export::ExportError),
    /// The modes about a stored step cannot be taken.
    #[error("{}: cannot take modes: {why}", result.display())]
    StoredModes {
        /// The result file.
        result: PathBuf,
        /// Why, and what to do.
        why: String,
    },
    /// The result file to continue is not a run of this model.
    #[error(
        "{}: cannot continue {} with this model: {why}",
        model.display(),
        result.display()
    )]
    RestartMismatch {
        /// The model file.
        model: PathBuf,
        /// The result file.
        result: PathBuf,
        /// What differs, and what to do.
        why: String,
    },
    /// The solver stopped; `file` holds the steps computed before (empty
    /// for a run kept in memory, whose sink holds them).
    #[error(
        "{}: model \"{model}\": {error}{}",
        path.display(),
        kept_in(file)
    )]
    Solve {
        /// The model's name.
        model: String,
        /// The model file.
        path: PathBuf,
        /// The solver's error.
        error: Box<SolveError>,
        /// The result file holding the steps computed before.
        file: PathBuf,
    },
}

/// Where the steps computed before a failure are, for its message: the
/// result file, or nothing for a run kept in memory.
fn kept_in(file: &Path) -> String {
    if file.as_os_str().is_empty() {
        String::new()
    } else {
        format!(" (steps computed so far are in {})", file.display())
    }
}

/// What a completed run reports.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// The result file.
    pub file: PathBuf,
    /// The ParaView series (`.pvd`) written with `[output] vtk = true`.
    pub vtk: Option<PathBuf>,
    /// Converged steps.
    pub steps: usize,
    /// Steps written (every `output.every`-th and the last).
    pub written: usize,
    /// Total Newton iterations.
    pub iterations: usize,
    /// Wall time of the solve, seconds.
    pub wall_time_s: f64,
    /// The part of [`Self::wall_time_s`] before the first time step of a
    /// dynamic run: building the simulation (patterns, orderings), the
    /// initial accelerations and the first record; 0 for static and
    /// arc-length runs. `wall_time_s − setup_time_s` is the time steps'.
    pub setup_time_s: f64,
    /// What the run's checks found doubtful in the completed result (also in
    /// the file's root attribute `warnings`).
    pub warnings: Vec<String>,
    /// Why a static path ended (root attribute `end_reason`).
    pub end_reason: Option<String>,
    /// The critical points located on a static path (`/stability`).
    pub critical: Vec<CriticalPoint>,
    /// A modal or buckling run's values as written: the frequencies
    /// (`/modes/frequency`) or the load factors (`/buckling/load_factor`).
    pub modes: Option<(ModeKind, Vec<f64>)>,
}

impl RunSummary {
    /// The lines that follow the step count: why a static path ended, the
    /// lowest frequencies or buckling load factors, the critical points.
    pub fn details(&self) -> Vec<String> {
        let mut lines: Vec<String> = self
            .end_reason
            .iter()
            .map(|r| format!("ended: {r}"))
            .collect();
        if let Some((kind, values)) = &self.modes {
            lines.push(mode_line(*kind, values));
        }
        lines.extend(self.critical.iter().map(|p| {
            format!(
                "critical point: {} at load factor {:.6} (negative eigenvalues {} -> {}; \
                 /stability)",
                p.kind.name(),
                p.load_factor,
                p.negative_before,
                p.negative_after
            )
        }));
        lines
    }
}

impl std::fmt::Display for RunSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} steps ({} written, {} Newton iterations) in {:.2} s -> {}",
            self.steps,
            self.written,
            self.iterations,
            self.wall_time_s,
            self.file.display()
        )?;
        for line in self.details() {
            write!(f, "\n{line}")?;
        }
        for w in &self.warnings {
            write!(f, "\nwarning: {w}")?;
        }
        Ok(())
    }
}

pub use crate::checks::ENERGY_BALANCE_WARNING;

impl RunError {
    /// A sink's error as a run error: a result file's and an output
    /// directory's keep their own variants.
    pub(crate) fn from_sink(e: SinkError) -> Self {
        let e = match e.downcast::<ResultError>() {
            Ok(r) => return Self::Result(*r),
            Err(e) => e,
        };
        match e.downcast::<OutputDirError>() {
            Ok(d) => Self::OutputDir {
                dir: d.dir,
                source: d.source,
            },
            Err(e) => Self::Sink(e),
        }
    }
}

/// Whether a run keeps its `count`-th record (from 1) under `[output]
/// every`: the first (the initial state, or a restart's checkpoint) and
/// every `every`-th after it — times 0, every·Δt, 2·every·Δt, … (the last
/// is kept besides, at the end).
pub fn is_kept(count: usize, every: usize) -> bool {
    count.saturating_sub(1).is_multiple_of(every.max(1))
}

/// Between the solver and the sink: keeps the first record, every
/// `every`-th after it and always the last one, and watches every converged step (energy balance,
/// stability, figures of merit).
struct Keeper<'a> {
    sink: &'a mut dyn Sink,
    mech: &'a Mechanism,
    /// The energy balance (dynamics) or the load path's stability (statics).
    checks: RunChecks,
    /// The run's figures of merit over every converged step.
    merit: Merit,
    every: usize,
    count: usize,
    iterations: usize,
    written: usize,
    pending: Option<StepRecord>,
    error: Option<SinkError>,
    /// The critical points the static steps located.
    critical: Vec<CriticalPoint>,
    /// The values of the modes written, with their kind.
    modes: Option<(ModeKind, Vec<f64>)>,
    /// A step went to the sink without its restart state.
    unsaved: bool,
}

impl Keeper<'_> {
    /// Takes a step's record; returns whether it was handed to the sink now.
    fn push(&mut self, step: StepRecord) -> bool {
        self.checks.push(self.mech, &step);
        self.merit.push(&step);
        self.critical.extend(step.critical);
        self.count += 1;
        self.iterations += step.iterations;
        if self.error.is_some() {
            return false;
        }
        if is_kept(self.count, self.every) {
            self.pending = None;
            self.give(step)
        } else {
            self.pending = Some(step);
            false
        }
    }

    /// Hands `step` to the sink; returns whether it took it.
    fn give(&mut self, step: StepRecord) -> bool {
        match self.sink.take_step(step) {
            Ok(()) => {
                self.written += 1;
                true
            }
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    /// Hands the last record over if it is still pending; returns whether
    /// it did.
    fn flush_last(&mut self) -> bool {
        match (self.pending.take(), &self.error) {
            (Some(step), None) => self.give(step),
            _ => false,
        }
    }

    /// Hands the simulation's restart state to the sink.
    fn checkpoint(&mut self, sim: &Simulation<'_>) {
        self.unsaved = false;
        if self.error.is_none() {
            if let Err(e) = self.sink.checkpoint(&sim.checkpoint()) {
                self.error = Some(e);
            }
        }
    }

    /// After a step went to the sink: hands the restart state over if the
    /// sink wants it now; [`Self::finish_checkpoints`] hands the last one.
    fn offer_checkpoint(&mut self, sim: &Simulation<'_>) {
        self.unsaved = true;
        if self.sink.wants_checkpoint() {
            self.checkpoint(sim);
        }
    }

    /// At a dynamic run's end (also after a failure): hands over the last
    /// converged step if it is still pending, and the restart state at the
    /// last step handed over.
    fn finish_checkpoints(&mut self, sim: &Simulation<'_>) {
        if self.flush_last() || self.unsaved {
            self.checkpoint(sim);
        }
    }

    /// Hands the modes of a modal or buckling analysis to the sink, after
    /// the last step.
    fn modes(&mut self, set: &ModeSet) {
        self.modes = Some((set.kind, set.values()));
        self.flush_last();
        if self.error.is_none() {
            let joints: Vec<String> = self.mech.joints.iter().map(|j| j.name.clone()).collect();
            if let Err(e) = self.sink.modes(set, &joints) {
                self.error = Some(e);
            }
        }
    }

    /// The warnings of a completed run's checks.
    fn warnings(&self) -> Vec<String> {
        self.checks.warnings_with(self.mech, &self.critical)
    }
}

/// Full Newton with the model's tolerance and iteration limit (statics
/// checks the stability of every converged state with its exact tangent).
fn static_newton(model: &Model) -> NewtonSettings {
    NewtonSettings {
        tolerance: model.solver.tolerance,
        max_iterations: model.solver.max_iterations,
        modified: false,
        exact_tangent: false,
    }
}

/// Runs `model` and writes `out_dir/<name>.h5`.
pub fn run_model(model: &Model, out_dir: &Path) -> Result<RunSummary, RunError> {
    run_model_to(model, &out_dir.join(format!("{}.h5", model.name)))
}

/// Runs `model` and writes its results to `file` (parent directories are
/// created); with `[output] vtk = true`, its ParaView series beside it.
pub fn run_model_to(model: &Model, file: &Path) -> Result<RunSummary, RunError> {
    with_vtk(model, run_with(model, &mut FileSink::new(file), None))
}

/// Runs `model` into `sink` ([`crate::Memory`], [`crate::OnStep`],
/// [`FileSink`] or a sink of your own). [`RunSummary::file`] is the sink's
/// file, if it writes one.
pub fn run(model: &Model, sink: &mut dyn Sink) -> Result<RunSummary, RunError> {
    run_with(model, sink, None)
}

/// After a completed run into a file: the ParaView series the model asks
/// for (`[output] vtk = true`), written next to it.
fn with_vtk(model: &Model, summary: Result<RunSummary, RunError>) -> Result<RunSummary, RunError> {
    let mut summary = summary?;
    if model.output.vtk {
        let dir = summary
            .file
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf();
        summary.vtk = Some(crate::export::export_vtk(&summary.file, &dir, None)?);
    }
    Ok(summary)
}

/// Relative distance between a node's initial position in the model and in
/// the run to continue below which they are the same node (round-off of the
/// mesh generator on coordinates of the model's size).
const SAME_NODE: f64 = 1e-12;

/// Continues the dynamic run stored in the result file `result` (its
/// `/restart` state, the last stored step) to `model`'s `t_end`, writing
/// `out_dir/<name>.h5` from the restart time on. `model` must describe the
/// same mechanism (nodes, joints, prescribed DOFs) with the same integrator
/// and `dt`; with full Newton the continuation equals the uninterrupted run
/// bit for bit.
pub fn restart_model(model: &Model, result: &Path, out_dir: &Path) -> Result<RunSummary, RunError> {
    let file = out_dir.join(format!("{}.h5", model.name));
    let mismatch = |why: String| RunError::RestartMismatch {
        model: model.path.clone(),
        result: result.to_path_buf(),
        why,
    };
    let same_file = match (file.canonicalize(), result.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same_file {
        return Err(mismatch(format!(
            "the continuation would overwrite the file it continues ({}); give another --out",
            file.display()
        )));
    }
    if !model.output.sensitivity.is_empty() {
        return Err(mismatch(
            "a continued run cannot carry sensitivities (the restart state holds no \
             derivatives); remove `sensitivity` from [output] to continue it, or run the model \
             from t = 0"
                .into(),
        ));
    }
    let built = build(model)?;
    let checkpoint = restart_state(model, &built, result)?;
    let mut sink = FileSink::new(&file).restarted_from(result, checkpoint.time);
    with_vtk(model, run_with(model, &mut sink, Some(&checkpoint)))
}

/// The restart state stored in `result` (its `/restart` group), checked
/// against `model` built as `built`: a dynamic analysis whose `t_end` lies
/// beyond the stored time, and the same nodes where the stored run began
/// (to 1e-12 of the mechanism's size). What [`restart_model`] and
/// a stepped simulation (the Python package's) continue from.
///
/// # Errors
/// An unreadable restart state, or a model that is not the stored run's.
pub fn restart_state(model: &Model, built: &Built, result: &Path) -> Result<Checkpoint, RunError> {
    let mismatch = |why: String| RunError::RestartMismatch {
        model: model.path.clone(),
        result: result.to_path_buf(),
        why,
    };
    let (checkpoint, initial) = read_checkpoint(result)?;
    let Analysis::Dynamic { t_end, .. } = model.solver.analysis else {
        return Err(mismatch(
            "key `solver.analysis`: a static analysis cannot be continued; restarts continue \
             dynamic runs"
                .into(),
        ));
    };
    if checkpoint.time >= t_end {
        return Err(mismatch(format!(
            "key `solver.t_end`: the stored run already reaches t = {} >= t_end = {t_end}; set a \
             later t_end",
            checkpoint.time
        )));
    }
    let here = &built.mechanism.mesh.positions;
    if here.len() != initial.len() {
        return Err(mismatch(format!(
            "the stored run has {} nodes, the model {}",
            initial.len(),
            here.len()
        )));
    }
    let scale = here.iter().map(|x| x.norm()).fold(1.0, f64::max);
    if let Some(i) = here
        .iter()
        .zip(&initial)
        .position(|(a, b)| (a - nalgebra::Vector3::from(*b)).norm() > SAME_NODE * scale)
    {
        return Err(mismatch(format!(
            "node {i} starts at {:?} in the stored run and at {:?} in the model: not the same \
             mechanism",
            initial[i],
            [here[i].x, here[i].y, here[i].z]
        )));
    }
    Ok(checkpoint)
}

/// What a run of `model` is, for its sink: labels, nodes, joints, mesh.
pub(crate) fn run_meta(model: &Model, built: &Built) -> RunMeta {
    let mech = &built.mechanism;
    let mesh = mesh_meta(model, built);
    let supports = mech
        .supported_nodes()
        .into_iter()
        .map(|n| mesh.node_labels[n].clone())
        .collect();
    RunMeta {
        model_text: model.text(),
        integrator: match model.solver.analysis {
            Analysis::Dynamic { integrator, .. } => integrator.name().to_string(),
            // Their records are static states (the modes go to /modes or
            // /buckling).
            _ => "static".to_string(),
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
        // The model's joints, then the rigid bodies' joints (`body.<name>`).
        joint_names: mech.joints.iter().map(|j| j.name.clone()).collect(),
        joint_angles: mech
            .joints
            .iter()
            .map(|j| j.map.reported_angle(&j.initial).is_some())
            .collect(),
        joint_nodes: mech.joints.iter().map(|j| [j.master, j.slave]).collect(),
        command_line: command_line(),
        supports,
        mesh: Some(mesh),
        resultants: model.output.resultants.then(|| ResultantsMeta {
            mesh: mech.mesh.clone(),
            beams: model
                .beams
                .iter()
                .zip(&built.beam_elements)
                .map(|(b, e)| (b.name.clone(), e.clone()))
                .collect(),
        }),
        sensitivity: (model.output.sensitivity.iter())
            .map(|(key, _)| key.clone())
            .collect(),
    }
}

/// Builds `model`, hands its description to `sink`, solves it (from
/// `restart` when given) handing over the kept steps, and ends the sink.
fn run_with(
    model: &Model,
    sink: &mut dyn Sink,
    restart: Option<&Checkpoint>,
) -> Result<RunSummary, RunError> {
    let built: Built = build(model)?;
    let meta = run_meta(model, &built);
    sink.begin(&meta).map_err(RunError::from_sink)?;
    let mut keeper = Keeper {
        sink,
        mech: &built.mechanism,
        checks: RunChecks::new(model),
        merit: Merit::new(
            meta.tracked
                .iter()
                .map(|&(_, n)| (n, meta.initial_positions[n]))
                .collect(),
        ),
        every: model.output.every.max(1),
        count: 0,
        iterations: 0,
        written: 0,
        pending: None,
        error: None,
        critical: Vec::new(),
        modes: None,
        unsaved: false,
    };
    let start = Instant::now();
    let (outcome, setup) = solve(model, &built, restart, &mut keeper, start);
    let wall = start.elapsed().as_secs_f64();
    keeper.flush_last();
    end(model, keeper, outcome, wall, setup)
}

/// Solves `model` with its analysis, handing every converged step to
/// `keeper`; returns the outcome and the set-up time of a dynamic run.
fn solve(
    model: &Model,
    built: &Built,
    restart: Option<&Checkpoint>,
    keeper: &mut Keeper<'_>,
    start: Instant,
) -> (Result<Option<String>, SolveError>, f64) {
    let mech = &built.mechanism;
    let newton = static_newton(model);
    let max_halvings = model.solver.max_halvings;
    match model.solver.analysis {
        Analysis::Static { load_steps } => {
            let settings = StaticSettings {
                load_steps,
                newton,
                max_halvings,
            };
            let params = built.sensitivity_parameters(model);
            let outcome = solve_static_with(mech, &settings, &params, |s| {
                keeper.push(s.clone());
            });
            (outcome.map(|o| end_reason(model, o.end)), 0.0)
        }
        Analysis::ArcLength {
            load_steps,
            max_steps,
            branch_switch,
        } => {
            let settings = ArcLengthSettings {
                load_steps,
                newton,
                max_halvings,
                max_steps,
                branch_switch,
                stop: path_stop(model, built),
            };
            let params = built.sensitivity_parameters(model);
            let outcome = solve_arc_length_with(mech, &settings, &params, |s| {
                keeper.push(s.clone());
            });
            (outcome.map(|o| end_reason(model, o.end)), 0.0)
        }
        Analysis::Modal { modes, load_steps } => {
            let settings = ModalSettings {
                request: ModeRequest {
                    modes,
                    mass: model.solver.mass,
                    solver: model.solver.eigensolver,
                },
                preload: StaticSettings {
                    load_steps,
                    newton,
                    max_halvings,
                },
            };
            let outcome = solve_modal(mech, &settings, |s| {
                keeper.push(s.clone());
            });
            (outcome.map(|set| keeper.modes(&set)).map(|()| None), 0.0)
        }
        Analysis::Buckling { modes } => {
            let state = initial_state(mech);
            let fext = vec![0.0; 6 * mech.mesh.node_count()];
            keeper.push(static_record(mech, &state, &fext, 0.0, 0.0, None));
            let outcome = buckling_modes(mech, modes, model.solver.eigensolver);
            (outcome.map(|set| keeper.modes(&set)).map(|()| None), 0.0)
        }
        Analysis::Dynamic {
            integrator,
            dt,
            t_end,
        } => {
            let settings = model.solver.stepping(dt, t_end);
            let (outcome, setup) =
                solve_dynamic(model, built, restart, keeper, start, (integrator, settings));
            (outcome.map(|()| None), setup)
        }
    }
}

/// The arc-length path's stop of `model` (`[solver] stop`; λ = 1 without).
fn path_stop(model: &Model, built: &Built) -> PathStop {
    let stop = model.solver.stop.clone().unwrap_or_default();
    PathStop {
        load_factor: stop.load_factor.unwrap_or(1.0),
        displacement: stop.displacement.map(|d| (built.node(d.node), d.max)),
    }
}

/// The summary's line of a modal (`Vibration`) or buckling run's `values`:
/// the lowest few, with the dataset that holds them all.
pub fn mode_line(kind: ModeKind, values: &[f64]) -> String {
    const SHOWN: usize = 4;
    let shown: Vec<String> = values
        .iter()
        .take(SHOWN)
        .map(|v| format!("{v:.6}"))
        .collect();
    let more = if values.len() > SHOWN { ", …" } else { "" };
    match kind {
        ModeKind::Vibration => format!(
            "lowest frequencies: {}{more} (/modes/frequency)",
            shown.join(", ")
        ),
        ModeKind::Buckling => format!(
            "lowest buckling load factors: {}{more} (/buckling/load_factor)",
            shown.join(", ")
        ),
    }
}

/// The words of a static path's end, for the result's `end_reason`.
fn end_reason(model: &Model, end: PathEnd) -> Option<String> {
    Some(match end {
        PathEnd::Reached { load_factor } => format!("reached load factor {load_factor}"),
        PathEnd::Budget { steps, load_factor } => format!(
            "the step budget: {steps} steps (solver.max_arc_steps) taken at load factor \
             {load_factor:.6}"
        ),
        PathEnd::Displacement {
            displacement,
            load_factor,
            ..
        } => {
            let d = model.solver.stop.as_ref()?.displacement.as_ref()?;
            format!(
                "node {} displaced {displacement:.6} >= {} (solver.stop.displacement) at \
                 load factor {load_factor:.6}",
                d.label, d.max
            )
        }
    })
}

/// The time steps of a dynamic run, each kept one followed by its restart
/// state; returns the outcome and the set-up time (before the first step).
fn solve_dynamic(
    model: &Model,
    built: &Built,
    restart: Option<&Checkpoint>,
    keeper: &mut Keeper<'_>,
    start: Instant,
    (integrator, settings): (IntegratorKind, DynamicSettings),
) -> (Result<(), SolveError>, f64) {
    let mech = &built.mechanism;
    let sim = match restart {
        Some(c) => Simulation::resume(mech, integrator, &settings, c),
        None => Simulation::new(mech, integrator, &settings, &built.motion),
    };
    let params = built.sensitivity_parameters(model);
    let mut sim = match sim {
        Ok(mut sim) if restart.is_none() && !params.is_empty() => {
            match sim.differentiate(&params) {
                Ok(()) => sim,
                Err(e) => return (Err(e), 0.0),
            }
        }
        Ok(sim) => sim,
        Err(e) => return (Err(e), 0.0),
    };
    if keeper.push(sim.record()) {
        keeper.offer_checkpoint(&sim);
    }
    let setup = start.elapsed().as_secs_f64();
    let outcome = loop {
        match sim.step() {
            Ok(Some(record)) => {
                if keeper.push(record) {
                    keeper.offer_checkpoint(&sim);
                }
            }
            Ok(None) => break Ok(()),
            Err(e) => break Err(e),
        }
    };
    // The last converged state, also after a failure.
    keeper.finish_checkpoints(&sim);
    (outcome, setup)
}

/// Ends the run in its sink: a sink's own failure first, then the solve's
/// outcome (its errors are born in the model's words: the mechanism
/// carries its names).
fn end(
    model: &Model,
    keeper: Keeper<'_>,
    outcome: Result<Option<String>, SolveError>,
    wall: f64,
    setup: f64,
) -> Result<RunSummary, RunError> {
    let warnings = keeper.warnings();
    let Keeper {
        sink,
        merit,
        error,
        count,
        iterations,
        written,
        critical,
        modes,
        ..
    } = keeper;
    if let Some(e) = error {
        // The sink's record is as complete as it could be made; report it.
        let status = layout::failed_status(&e.to_string());
        let _ = sink.finish(&RunEnd::new(status, wall, &merit));
        return Err(RunError::from_sink(e));
    }
    let file = sink.file().map(Path::to_path_buf).unwrap_or_default();
    match outcome {
        Ok(end_reason) => {
            let mut end = RunEnd::new(layout::STATUS_COMPLETED.into(), wall, &merit);
            end.warnings = warnings;
            end.end_reason = end_reason;
            end.critical = critical;
            sink.finish(&end).map_err(RunError::from_sink)?;
            Ok(RunSummary {
                file,
                vtk: None,
                steps: count,
                written,
                iterations,
                wall_time_s: wall,
                setup_time_s: setup,
                warnings: end.warnings,
                end_reason: end.end_reason,
                critical: end.critical,
                modes,
            })
        }
        Err(error) => {
            let status = layout::failed_status(&error.to_string());
            let mut end = RunEnd::new(status, wall, &merit);
            end.critical = critical;
            sink.finish(&end).map_err(RunError::from_sink)?;
            Err(RunError::Solve {
                model: model.name.clone(),
                path: model.path.clone(),
                error: Box::new(error),
                file,
            })
        }
    }
}

/// This process's command line, arguments with spaces quoted.
fn command_line() -> String {
    std::env::args()
        .map(|a| {
            if a.contains(char::is_whitespace) {
                format!("{a:?}")
            } else {
                a
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Labels, elements and beams of the built mechanism, for `/mesh`.
fn mesh_meta(model: &Model, built: &Built) -> MeshMeta {
    let mesh = &built.mechanism.mesh;
    let mut node_directors = vec![[[0.0; 3]; 3]; mesh.node_count()];
    for e in &mesh.elements {
        for (&n, l0) in e.nodes().iter().zip(e.initial_triads()) {
            node_directors[n] = std::array::from_fn(|k| [l0[(0, k)], l0[(1, k)], l0[(2, k)]]);
        }
    }
    MeshMeta {
        node_labels: built.mechanism.names.nodes.clone(),
        node_directors,
        elements: mesh.elements.iter().map(|e| e.nodes().to_vec()).collect(),
        beams: model
            .beams
            .iter()
            .zip(&built.beam_nodes)
            .map(|(b, nodes)| (b.name.clone(), nodes.clone()))
            .collect(),
    }
}
