//! Static equilibrium under proportional (or scheduled) loading: the load
//! factor λ runs from 0 to 1; each step (for driven mechanisms: from the
//! secant prediction of the previous one) is solved by Newton with the exact
//! tangent; a step that fails is retried with half the increment, never
//! below `nominal/2^max_halvings` (the shared step control: the halving level is kept
//! across successes), and the increment grows back to nominal after three
//! easy steps. Every planned level `k/load_steps` is reached
//! exactly; halvings only insert levels between them.

use crate::assembly::Assembler;
use crate::constraints::{initial_state, MechanismState, Topology};
use crate::error::{NewtonFailure, SolveError};
use crate::linsolve::SparseLu;
use crate::measure::{follower_work, static_record};
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonReport, NewtonSettings, NewtonSystem};
use crate::record::StepRecord;
use crate::rotation_guard::{as_step_failure, RotationGuard};
use crate::sensitivity::{Parameter, StaticSensitivities};
use crate::stability::InertiaCount;
use crate::step_control::StepControl;
use crate::system::{ReducedSystem, Reduction, StepTerms};
use crate::tolerances::TOLERANCES;
use flexmech_core::Configuration;

/// Settings of a static analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSettings {
    /// Number of equal load-factor steps from 0 to 1.
    pub load_steps: usize,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// Consecutive halvings allowed for one step.
    pub max_halvings: usize,
}

/// Result of a completed static analysis.
#[derive(Debug, Clone)]
pub struct StaticOutcome {
    /// Final configuration.
    pub config: Configuration,
    /// Final state including the joints' released coordinates.
    pub state: MechanismState,
    /// Converged steps (including those after halvings).
    pub steps: usize,
    /// Why the path ended.
    pub end: PathEnd,
}

/// Why a static path ended (all of them complete runs; a path that could
/// not go on is an error instead).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathEnd {
    /// The path reached its last load factor (1, or an arc-length run's
    /// `stop.load_factor`).
    Reached {
        /// The load factor reached.
        load_factor: f64,
    },
    /// An arc-length path used its step budget (`max_arc_steps`).
    Budget {
        /// Steps taken.
        steps: usize,
        /// The load factor of the last step.
        load_factor: f64,
    },
    /// A node's displacement reached the arc-length run's
    /// `stop.displacement`.
    Displacement {
        /// The node (mesh index).
        node: usize,
        /// Its displacement `|x − X|` at the last step.
        displacement: f64,
        /// The load factor of the last step.
        load_factor: f64,
    },
}

/// The static terms: the beams' internal forces at the iterate; no inertia;
/// joints through `N`.
pub(crate) struct StaticTerms;

impl StepTerms for StaticTerms {
    fn reduction(&self) -> Reduction {
        Reduction::Variation
    }
}

/// Easy load steps in a row before a halved step doubles again.
const GROW_AFTER: usize = 3;

/// Solves the static problem, calling `on_step` after every converged step.
/// On failure the steps already reported stay valid; the error says where.
pub fn solve_static(
    mech: &Mechanism,
    settings: &StaticSettings,
    on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    solve_static_with(mech, settings, &[], on_step)
}

/// [`solve_static`] with the exact sensitivities of every converged step to
/// `params` in its record ([`StepRecord::sensitivities`], see
/// [`crate::sensitivity`]): one more factorisation of the converged tangent
/// per step and one solve per parameter.
pub fn solve_static_with(
    mech: &Mechanism,
    settings: &StaticSettings,
    params: &[Parameter],
    on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    static_path(mech, settings, params, 1.0, on_step)
}

/// [`solve_static`] stopped at the load factor `end` (≤ 1): the same steps
/// as the whole path up to there — every planned level and every halving
/// the same — so a state a run stored is found again exactly (the modes
/// about a stored step).
pub fn solve_static_to(
    mech: &Mechanism,
    settings: &StaticSettings,
    end: f64,
    on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    static_path(mech, settings, &[], end.min(1.0), on_step)
}

/// The static path from 0 to the load factor `end`.
fn static_path(
    mech: &Mechanism,
    settings: &StaticSettings,
    params: &[Parameter],
    end: f64,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    if settings.load_steps == 0 {
        return Err(SolveError::InvalidMechanism(
            "load_steps must be at least 1".into(),
        ));
    }
    let (mut prob, mut lu, mut inertia) = static_system(mech)?;
    let mut sensitivities = StaticSensitivities::new(&prob, params)?;
    let n = prob.topo.dofs.n_eq;
    let (mut r, mut dq) = (vec![0.0; n], vec![0.0; n]);
    let nominal = 1.0 / settings.load_steps as f64;
    let mut control = StepControl::with(nominal, settings.max_halvings, GROW_AFTER);
    let mut guard = RotationGuard::new(mech, &prob.end);
    let (mut lambda, mut steps) = (0.0f64, 0usize);
    // The follower loads' work along the load path.
    let mut follower = 0.0;
    // Kinematically driven mechanisms start each step from the secant
    // prediction, which carries the rigid motion downstream of a driven joint;
    // under load control the last equilibrium is the better start (Newton's
    // first iteration is the tangent predictor, and extrapolating positions and
    // rotations separately would break their compatibility in slender beams).
    let driven = mech.has_drivers();
    // The state before the last converged step and that step's size.
    let mut previous: Option<(MechanismState, f64)> = None;
    let mut count = initial_count(&mut prob, &mut inertia, &mut r);
    while lambda < end - TOLERANCES.end_of_run {
        let target = next_level(lambda, nominal, control.step());
        begin_step(&mut prob);
        if let (true, Some((before, before_step))) = (driven, &previous) {
            prob.topo
                .extrapolate(mech, &mut prob.end, before, (target - lambda) / before_step);
        }
        prob.topo.impose(mech, &mut prob.end, target);
        mech.external_forces(target, &mut prob.fext);
        prob.load_time = target;
        match newton::solve(&mut prob, &mut lu, &settings.newton, &mut r, &mut dq) {
            Ok(report) => {
                if let Err(objection) = guard.accept(mech, &prob.end, target) {
                    control.failed(target, step_rejected(&mut prob, objection)?)?;
                    continue;
                }
                let dt = target - lambda;
                previous = Some((prob.start.clone(), dt));
                follower += follower_work(
                    mech,
                    (lambda, &prob.start.config),
                    (target, &prob.end.config),
                );
                lambda = target;
                steps += 1;
                let mut step = converged_record(
                    &mut prob,
                    &mut inertia,
                    &mut r,
                    (lambda, dt),
                    &report,
                    Some(follower),
                );
                step.sensitivities = sensitivities.at(&prob, lambda)?;
                step.critical = locate_on_load_path(
                    &mut prob,
                    (&mut lu, &mut inertia),
                    (lambda - dt, count),
                    &step,
                    &settings.newton,
                );
                count = step.negative_pivots;
                on_step(&step);
                control.succeeded();
            }
            Err(reason) => {
                prob.end.clone_from(&prob.start);
                refuse_if_unsupported(&reason, lambda, control.level())?;
                // Halve, never below nominal/2^max_halvings (the level is
                // kept across successes, so the load path cannot creep on
                // with ever smaller steps).
                control.failed(target, reason)?;
            }
        }
    }
    let end = PathEnd::Reached {
        load_factor: lambda,
    };
    Ok(StaticOutcome::reached(prob, steps, end))
}

/// The stability count of the state now in `sys` (its loads at λ = 0):
/// the count the path starts from.
pub(crate) fn initial_count(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    inertia: &mut InertiaCount,
    scratch: &mut [f64],
) -> Option<usize> {
    sys.fext.iter_mut().for_each(|f| *f = 0.0);
    sys.mech.external_forces(0.0, &mut sys.fext);
    sys.load_time = 0.0;
    sys.update_tangent(scratch);
    inertia.negative_eigenvalues(&sys.asm.values)
}

/// The critical point a load step from `sys.start` (load factor `lambda0`,
/// `count` negative eigenvalues) to `step` crossed, when the count changed:
/// bisection on the load factor, each point solved by Newton from the
/// step's start (a bifurcation: load control cannot pass a limit point).
fn locate_on_load_path(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    (lu, inertia): (&mut SparseLu, &mut InertiaCount),
    (lambda0, count): (f64, Option<usize>),
    step: &StepRecord,
    newton: &NewtonSettings,
) -> Option<crate::critical::CriticalPoint> {
    let (Some(before), Some(after)) = (count, step.negative_pivots) else {
        return None;
    };
    if before == after {
        return None;
    }
    let (mech, start) = (sys.mech, sys.start.clone());
    let n = sys.topo.dofs.n_eq;
    let (mut r, mut dq, mut scratch) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut f_ref = vec![0.0; 6 * mech.mesh.node_count()];
    mech.external_forces(1.0, &mut f_ref);
    let set_load = |sys: &mut ReducedSystem<'_, StaticTerms>, lambda: f64| {
        mech.external_forces(lambda, &mut sys.fext);
        sys.load_time = lambda;
    };
    crate::critical::locate(
        sys,
        (inertia, lu, &mut scratch),
        (&start, lambda0, before),
        (step.time, after),
        &f_ref,
        |sys, lu, s| {
            let lambda = lambda0 + s * (step.time - lambda0);
            sys.topo.impose(mech, &mut sys.end, lambda);
            set_load(sys, lambda);
            newton::solve(sys, lu, newton, &mut r, &mut dq).map(|_| lambda)
        },
        set_load,
    )
    .map(|(point, _)| point)
}

/// The load factor the step from `lambda` aims at, with the step control's
/// size `step`: at most the next planned level `k·nominal`, and exactly 1
/// within `end_of_run` of the end.
fn next_level(lambda: f64, nominal: f64, step: f64) -> f64 {
    // Never step over a planned level k/load_steps: results are reported
    // at the load factors the user asked for; halvings only add levels.
    let next_planned = ((lambda / nominal + TOLERANCES.level_snap).floor() + 1.0) * nominal;
    let target = (lambda + step).min(next_planned);
    if target > 1.0 - TOLERANCES.end_of_run {
        1.0
    } else {
        target
    }
}

/// The error that ends the run when the first step from the undeformed
/// state, at full size, failed on a singular tangent; any other failure is
/// left to the step control.
fn refuse_if_unsupported(
    reason: &NewtonFailure,
    lambda: f64,
    level: usize,
) -> Result<(), SolveError> {
    if let NewtonFailure::LinearSolve(msg) = reason {
        if lambda == 0.0 && level == 0 {
            // A singular tangent at the undeformed state will not be
            // cured by a smaller load: the mechanism is under-supported.
            return Err(SolveError::Singular(msg.clone()));
        }
    }
    Ok(())
}

impl StaticOutcome {
    /// The outcome at the last converged state of `sys`, after `steps` steps.
    pub(crate) fn reached(sys: ReducedSystem<'_, StaticTerms>, steps: usize, end: PathEnd) -> Self {
        Self {
            config: sys.end.config.clone(),
            state: sys.end,
            steps,
            end,
        }
    }
}

/// The static system of `mech` at its initial state (the joints' driven
/// coordinates imposed at λ = 0), with the sparse LU of its tangent and the
/// stability count, both over the tangent's pattern. Shared by load control
/// ([`solve_static`]) and arc-length control
/// ([`crate::arc_length::solve_arc_length`]).
pub(crate) fn static_system(
    mech: &Mechanism,
) -> Result<(ReducedSystem<'_, StaticTerms>, SparseLu, InertiaCount), SolveError> {
    let mut state = initial_state(mech);
    let topo = Topology::new(mech, &state)?;
    topo.impose(mech, &mut state, 0.0);
    let asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
    let lu = SparseLu::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let inertia = InertiaCount::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let sys = ReducedSystem::new(mech, topo, asm, state, StaticTerms);
    Ok((sys, lu, inertia))
}

/// Starts a step from the last converged state: the step's start is the
/// current end, and the round-off floor of the residual is that state's.
pub(crate) fn begin_step(sys: &mut ReducedSystem<'_, StaticTerms>) {
    sys.start.clone_from(&sys.end);
    sys.floor = sys.mech.round_off_floor_at(&sys.end.config.x);
}

/// Undoes a step the rotation guard objected to (back to the step's start)
/// and returns the objection as a step failure when smaller steps cure it,
/// or else the error that ends the run.
pub(crate) fn step_rejected(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    objection: SolveError,
) -> Result<NewtonFailure, SolveError> {
    sys.end.clone_from(&sys.start);
    as_step_failure(objection)
}

/// The record of a converged static step to the load factor `lambda` (step
/// `dl`; the loads set at `lambda`): its energies, the stability count of the
/// converged iterate's tangent and the reactions. `follower`, the follower
/// loads' work along the load path, is taken off the potential and total
/// energies where given. `scratch` is a residual-sized buffer.
pub(crate) fn converged_record(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    inertia: &mut InertiaCount,
    scratch: &mut [f64],
    (lambda, dl): (f64, f64),
    report: &NewtonReport,
    follower: Option<f64>,
) -> StepRecord {
    let mut step = static_record(sys.mech, &sys.end, &sys.fext, lambda, dl, Some(report));
    if let Some(follower) = follower {
        // Follower loads have no potential: minus their work along
        // the load path stands for it.
        step.energy.potential -= follower;
        step.energy.total -= follower;
    }
    // The stability count is of the converged iterate's tangent.
    sys.update_tangent(scratch);
    step.negative_pivots = inertia.negative_eigenvalues(&sys.asm.values);
    sys.record_reactions(&mut step);
    step
}
