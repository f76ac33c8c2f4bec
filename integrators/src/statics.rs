//! Static equilibrium under proportional (or scheduled) loading: the load
//! factor λ runs from 0 to 1; each step (for driven mechanisms: from the
//! secant prediction of the previous one) is solved by Newton with the exact
//! tangent; a step that fails is retried with half the increment, never
//! below `nominal/2^max_halvings` ([`StepControl`]: the halving level is kept
//! across successes), and the increment grows back to nominal after three
//! easy steps. Every planned level `k/load_steps` is reached
//! exactly; halvings only insert levels between them.

use crate::assembly::Assembler;
use crate::constraints::{initial_state, joint_records, MechanismState, Topology};
use crate::error::{NewtonFailure, SolveError};
use crate::free_motion::FreeMotion;
use crate::linsolve::{SparseLu, TangentRef};
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonSettings, NewtonSystem};
use crate::record::{Energies, StepRecord};
use crate::rotation_guard::{as_step_failure, RotationGuard};
use crate::stability::InertiaCount;
use crate::step_control::StepControl;
use flexmech_core::Configuration;
use nalgebra::Vector3;
use rayon::prelude::*;

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

/// The static problem at one load factor: the [`NewtonSystem`] Newton solves.
struct StaticProblem<'a> {
    mech: &'a Mechanism,
    topo: Topology,
    asm: Assembler,
    state: MechanismState,
    fext: Vec<f64>,
    nodal_r: Vec<f64>,
    scratch: Vec<f64>,
    /// Round-off floor of the residual norm.
    floor: f64,
}

impl NewtonSystem for StaticProblem<'_> {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        self.topo.refresh(self.mech, &self.state);
        self.asm
            .assemble(&self.mech.mesh, &self.topo.dofs, &self.state.config);
        for ((g, fi), fe) in self.nodal_r.iter_mut().zip(&self.asm.nodal).zip(&self.fext) {
            *g = fi - fe;
        }
        self.topo.dofs.reduce(&self.nodal_r, r);
        for (b, block) in self
            .topo
            .geometric_blocks(self.mech, &self.state, &self.nodal_r)
            .iter()
            .enumerate()
        {
            self.asm.add_block(b, block);
        }
        let dofs = &self.topo.dofs;
        let f_ext = dofs.reduced_norm(&self.fext, &mut self.scratch);
        f_ext.max(dofs.reduced_norm(&self.asm.nodal_abs, &mut self.scratch))
    }

    fn tangent_values(&self) -> &[f64] {
        &self.asm.values
    }

    fn apply(&mut self, dq: &[f64]) {
        self.topo.apply(self.mech, &mut self.state, dq);
    }

    fn floor(&self) -> f64 {
        self.floor
    }

    fn free_motion(&self, mode: &[f64], tangent: TangentRef) -> FreeMotion {
        let topo = &self.topo;
        FreeMotion::of(
            self.mech,
            &topo.dofs,
            &topo.released_eqs,
            &self.state.config.x,
            mode,
            tangent,
        )
    }
}

/// Strain energy of the whole mesh (element energies summed in element order).
pub fn strain_energy(mech: &Mechanism, config: &Configuration) -> f64 {
    let per: Vec<f64> = mech
        .mesh
        .elements
        .par_iter()
        .map(|e| e.energy(&config.x, &config.rot))
        .collect();
    per.iter().sum()
}

/// A record of the configuration with energies (statics: no kinetic energy,
/// no momenta; the potential is that of the dead forces, `−Σ f·u`; moments,
/// which are not conservative in 3D, are left out of it).
fn record(
    mech: &Mechanism,
    state: &MechanismState,
    fext: &[f64],
    time: f64,
    dt: f64,
    report: &newton::NewtonReport,
) -> StepRecord {
    let config = &state.config;
    let strain = strain_energy(mech, config);
    let potential: f64 = -(0..config.x.len())
        .map(|n| {
            let u: Vector3<f64> = config.x[n] - mech.mesh.positions[n];
            u.dot(&Vector3::new(fext[6 * n], fext[6 * n + 1], fext[6 * n + 2]))
        })
        .sum::<f64>();
    StepRecord {
        time,
        dt,
        iterations: report.iterations,
        factorizations: report.factorizations,
        residual: report.residual,
        residual_history: report.history.clone(),
        beta: f64::NAN,
        energy: Energies {
            kinetic: 0.0,
            strain,
            potential,
            total: strain + potential,
            driver_work: 0.0,
        },
        negative_pivots: None,
        momentum_linear: [0.0; 3],
        momentum_angular: [0.0; 3],
        positions: config.x.iter().map(|x| [x.x, x.y, x.z]).collect(),
        quaternions: (0..config.x.len())
            .map(|i| {
                let q = config.quaternion(i);
                [q.x, q.y, q.z, q.w]
            })
            .collect(),
        joints: joint_records(mech, state),
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
    let nodes = mech.mesh.node_count();
    let mut prob = StaticProblem {
        mech,
        topo,
        asm,
        state,
        fext: vec![0.0; 6 * nodes],
        nodal_r: vec![0.0; 6 * nodes],
        scratch: vec![0.0; n],
        floor: mech.round_off_floor(),
    };
    let (mut r, mut dq) = (vec![0.0; n], vec![0.0; n]);
    let nominal = 1.0 / settings.load_steps as f64;
    let mut control = StepControl::with(nominal, settings.max_halvings, GROW_AFTER);
    let mut guard = RotationGuard::new(mech, &prob.state);
    let (mut lambda, mut steps) = (0.0f64, 0usize);
    // Kinematically driven mechanisms start each step from the secant
    // prediction, which carries the rigid motion downstream of a driven joint;
    // under load control the last equilibrium is the better start (Newton's
    // first iteration is the tangent predictor, and extrapolating positions and
    // rotations separately would break their compatibility in slender beams).
    let driven = !mech.prescribed.is_empty()
        || mech
            .joints
            .iter()
            .any(|j| j.driven.iter().any(Option::is_some));
    // The state before the last converged step and that step's size.
    let mut previous: Option<(MechanismState, f64)> = None;
    while lambda < 1.0 - 1e-12 {
        // Never step over a planned level k/load_steps: results are reported
        // at the load factors the user asked for; halvings only add levels.
        let next_planned = ((lambda / nominal + 1e-9).floor() + 1.0) * nominal;
        let target = (lambda + control.step()).min(next_planned);
        let target = if target > 1.0 - 1e-12 { 1.0 } else { target };
        let saved = prob.state.clone();
        prob.floor = mech.round_off_floor_at(&prob.state.config.x);
        if let (true, Some((before, before_step))) = (driven, &previous) {
            prob.topo.extrapolate(
                mech,
                &mut prob.state,
                before,
                (target - lambda) / before_step,
            );
        }
        prob.topo.impose(mech, &mut prob.state, target);
        mech.external_forces(target, &mut prob.fext);
        match newton::solve(&mut prob, &mut lu, &settings.newton, &mut r, &mut dq) {
            Ok(report) => {
                if let Err(objection) = guard.accept(mech, &prob.state, target) {
                    prob.state = saved;
                    control.failed(target, as_step_failure(objection)?)?;
                    continue;
                }
                let dt = target - lambda;
                previous = Some((saved, dt));
                lambda = target;
                steps += 1;
                let mut step = record(mech, &prob.state, &prob.fext, lambda, dt, &report);
                step.negative_pivots = inertia.negative_eigenvalues(&prob.asm.values);
                on_step(&step);
                control.succeeded();
            }
            Err(reason) => {
                prob.state = saved;
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
        config: prob.state.config.clone(),
        state: prob.state,
        steps,
    })
}
