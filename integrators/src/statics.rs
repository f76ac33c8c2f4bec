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
use crate::newton::{self, NewtonSettings, NewtonSystem};
use crate::record::StepRecord;
use crate::rotation_guard::{as_step_failure, RotationGuard};
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
    mut on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    if settings.load_steps == 0 {
        return Err(SolveError::InvalidMechanism(
            "load_steps must be at least 1".into(),
        ));
    }
    let mut state = initial_state(mech);
    let topo = Topology::new(mech, &state)?;
    topo.impose(mech, &mut state, 0.0);
    let n = topo.dofs.n_eq;
    let asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
    let mut lu = SparseLu::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let mut inertia = InertiaCount::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let mut prob = ReducedSystem::new(mech, topo, asm, state, StaticTerms);
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
    while lambda < 1.0 - TOLERANCES.end_of_run {
        // Never step over a planned level k/load_steps: results are reported
        // at the load factors the user asked for; halvings only add levels.
        let next_planned = ((lambda / nominal + TOLERANCES.level_snap).floor() + 1.0) * nominal;
        let target = (lambda + control.step()).min(next_planned);
        let target = if target > 1.0 - TOLERANCES.end_of_run {
            1.0
        } else {
            target
        };
        prob.start.clone_from(&prob.end);
        prob.floor = mech.round_off_floor_at(&prob.end.config.x);
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
                    prob.end.clone_from(&prob.start);
                    control.failed(target, as_step_failure(objection)?)?;
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
                let mut step =
                    static_record(mech, &prob.end, &prob.fext, lambda, dt, Some(&report));
                // Follower loads have no potential: minus their work along
                // the load path stands for it.
                step.energy.potential -= follower;
                step.energy.total -= follower;
                // The stability count is of the converged iterate's tangent.
                prob.update_tangent(&mut r);
                step.negative_pivots = inertia.negative_eigenvalues(&prob.asm.values);
                prob.record_reactions(&mut step);
                on_step(&step);
                control.succeeded();
            }
            Err(reason) => {
                prob.end.clone_from(&prob.start);
                if let NewtonFailure::LinearSolve(msg) = &reason {
                    if lambda == 0.0 && control.level() == 0 {
                        // A singular tangent at the undeformed state will not be
                        // cured by a smaller load: the mechanism is under-supported.
                        return Err(SolveError::Singular(msg.clone()));
                    }
                }
                // Halve, never below nominal/2^max_halvings (the level is
                // kept across successes, so the load path cannot creep on
                // with ever smaller steps).
                control.failed(target, reason)?;
            }
        }
    }
    Ok(StaticOutcome {
        config: prob.end.config.clone(),
        state: prob.end,
        steps,
    })
}
