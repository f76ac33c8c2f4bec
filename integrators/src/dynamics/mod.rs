//! Time integration (FORMULATION §4). Every scheme solves, per step, for the
//! configuration at `tₙ₊₁` by Newton with the exact tangent on the shared
//! reduced system ([`crate::system`]); one driver ([`simulation`]) predicts,
//! halves the step on failure, and reports a
//! [`StepRecord`](crate::record::StepRecord) per converged step.
//!
//! * [`newmark`]: the trapezoidal rule on SO(3) (Simo & Vu-Quoc).
//! * [`generalized_alpha`]: the generalized-α scheme on the Lie group
//!   (Arnold & Brüls) — second order, high frequencies damped to `ρ∞`.
//! * [`momentum`]: the midpoint scheme with the geodesic mid rotation —
//!   conserves linear and angular momentum exactly.
//! * [`energy_momentum`]: the energy-consistent discrete gradient of the
//!   element energy — conserves momenta and the total energy of
//!   conservative systems, and is consistent (no correction that grows as
//!   the step shrinks).
//! * [`energy_momentum_paper`]: the paper's energy–momentum scheme, the
//!   algebraic mid rotation and the scalar correction `β q_k(N_d, 0)`, kept
//!   to reproduce the paper.

mod bordered;
pub mod checkpoint;
pub mod energy_momentum;
pub mod energy_momentum_paper;
pub mod generalized_alpha;
mod inertia_pairs;
mod joint_start;
mod mass_slots;
pub mod midpoint;
mod midpoint_geometry;
mod midpoint_history;
mod midpoint_joint;
pub mod midpoint_kernels;
mod midpoint_predictor;
mod midpoint_sensitivity;
pub mod momentum;
pub mod newmark;
pub mod newmark_sensitivity;
mod newmark_terms;
pub mod simulation;
mod time_scheme;

pub use checkpoint::{Checkpoint, CheckpointMismatch};
pub use simulation::{Integrator, Simulation};

use crate::constraints::{MechanismState, Topology};

/// Easy time steps in a row before a halved step doubles again.
pub(crate) const GROW_AFTER: usize = 4;
use crate::mechanism::Mechanism;
use crate::newton::NewtonSettings;
use flexmech_core::MassKind;
use flexmech_joints::LOCAL;
use nalgebra::Vector3;
use nalgebra::{SVector, Vector6};

/// The midpoint (conserving) schemes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// Geodesic mid rotation, paper eq. 17: momenta conserved.
    Momentum,
    /// Discrete gradient of the element energy: momenta and energy conserved.
    EnergyMomentum,
    /// The paper's eqs 17–20 (algebraic mid rotation and β): momenta and
    /// energy conserved, β growing as `Δt → 0`.
    EnergyMomentumPaper,
}

impl Scheme {
    /// The mid rotation of the paper's force `q_k` in this scheme.
    pub fn mid_rotation(self) -> flexmech_core::conserving::MidRotation {
        use flexmech_core::conserving::MidRotation;
        match self {
            Scheme::Momentum => MidRotation::Geodesic,
            Scheme::EnergyMomentum | Scheme::EnergyMomentumPaper => MidRotation::Algebraic,
        }
    }
}

/// Settings of a dynamic analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicSettings {
    /// Nominal step.
    pub dt: f64,
    /// End time.
    pub t_end: f64,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// Consecutive halvings allowed for one step.
    pub max_halvings: usize,
    /// Translational mass.
    pub mass: MassKind,
}

/// Consecutive halvings of one step allowed by default
/// (`solver.max_halvings`).
pub const DEFAULT_MAX_HALVINGS: usize = 10;

impl DynamicSettings {
    /// Steps of `dt` to `t_end` with default Newton settings
    /// ([`NewtonSettings::default`]), [`DEFAULT_MAX_HALVINGS`] and the
    /// consistent mass.
    pub fn new(dt: f64, t_end: f64) -> Self {
        Self {
            dt,
            t_end,
            newton: NewtonSettings::default(),
            max_halvings: DEFAULT_MAX_HALVINGS,
            mass: MassKind::Consistent,
        }
    }
}

/// Nodal velocities: spatial translational `v` and body angular `W`
/// (`Ṙ = R Ŵ`, `R` the nodal rotation from the initial configuration).
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Translational velocity of every node (spatial).
    pub v: Vec<Vector3<f64>>,
    /// Body angular velocity `W` of every node.
    pub w: Vec<Vector3<f64>>,
    /// Initial rate of each joint's first released coordinate (missing
    /// entries are zero). Slave velocities follow from their master's and
    /// these rates through `N`; the `v`, `w` given for slave nodes are ignored.
    pub joint_rates: Vec<f64>,
}

impl Motion {
    /// At rest.
    pub fn rest(nodes: usize) -> Self {
        Self {
            v: vec![Vector3::zeros(); nodes],
            w: vec![Vector3::zeros(); nodes],
            joint_rates: Vec::new(),
        }
    }
}

/// The round-off floor of the inertial forces of a step of size `dt` from
/// `positions` (added to the beams' floor,
/// [`Mechanism::round_off_floor_at`]): every scheme's inertial force is a
/// mass times a position or rotation difference over at most `Δt²/4`
/// (`β Δt²` with `β ≥ ¼`, the midpoint rule's `Δt²/4`), and a difference of
/// positions of size `x` carries a round-off of `ε x`. Without it, a run whose
/// forces all pass through zero at once (an oscillator crossing its rest
/// position with a small step) could not reach the tolerance.
pub(crate) fn inertia_round_off_floor(
    mech: &Mechanism,
    inertia: &flexmech_core::Inertia,
    positions: &[Vector3<f64>],
    dt: f64,
) -> f64 {
    let radius = mech.size_at(positions);
    let translational: f64 =
        inertia.mass.iter().map(|&(_, _, m)| m * m).sum::<f64>() * radius * radius;
    let rotational: f64 = inertia.rotational.iter().map(|j| j.norm_squared()).sum();
    4.0 * f64::EPSILON * (translational + rotational).sqrt() * 4.0 / (dt * dt)
}

/// Initial velocities, every slave's derived from its master's and the
/// joint's released rate through `N` (spatial spin `w = R W`).
pub(crate) fn slave_velocities(
    mech: &Mechanism,
    topo: &Topology,
    state: &MechanismState,
    initial: &Motion,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let (mut v, mut w) = (initial.v.clone(), initial.w.clone());
    for &j in &topo.order {
        let joint = &mech.joints[j];
        let (m, s) = (joint.master, joint.slave);
        let n = joint
            .map
            .variation(&state.config.x[m], &state.config.rot[m], &state.released[j]);
        let mut p = SVector::<f64, LOCAL>::zeros();
        p.fixed_rows_mut::<3>(0).copy_from(&v[m]);
        p.fixed_rows_mut::<3>(3)
            .copy_from(&(state.config.rot[m] * w[m]));
        if joint.map.released_count() > 0 {
            p[6] = initial.joint_rates.get(j).copied().unwrap_or(0.0);
        }
        let ps: Vector6<f64> = n * p;
        v[s] = ps.fixed_rows::<3>(0).into_owned();
        w[s] = state.config.rot[s].transpose() * ps.fixed_rows::<3>(3);
    }
    (v, w)
}

/// `Σᵢ pᵢ·gᵢ` over all nodes for the step `start → end`: displacement
/// increments and rotation increments (`cayley`: the tangent-scaled `θ` of
/// `Rₙ₊₁ = cay(θ)Rₙ`, else the spatial rotation vector `log(Rₙ₊₁Rₙᵀ)`) against
/// the nodal residuals `g`. At a converged step the free equations vanish, so
/// this is the work of the drivers' reactions (driven joint coordinates,
/// prescribed DOFs).
pub(crate) fn increment_work(
    start: &flexmech_core::Configuration,
    end: &flexmech_core::Configuration,
    g: &[f64],
    cayley: bool,
) -> f64 {
    use flexmech_core::rotation::{cayley_inverse, log};
    (0..start.x.len())
        .map(|i| {
            let u = end.x[i] - start.x[i];
            let rel = end.rot[i] * start.rot[i].transpose();
            let th = if cayley {
                cayley_inverse(&rel)
            } else {
                log(&rel)
            };
            let gi = Vector6::from_column_slice(&g[6 * i..6 * i + 6]);
            u.dot(&gi.fixed_rows::<3>(0)) + th.dot(&gi.fixed_rows::<3>(3))
        })
        .sum()
}
