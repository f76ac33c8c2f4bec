//! Time integration (FORMULATION §4). Every scheme solves, per step, for the
//! configuration at `tₙ₊₁` by Newton with the exact tangent (AD through the
//! generic kernels), halves the step on failure, and reports a
//! [`StepRecord`](crate::record::StepRecord) per converged step.
//!
//! * [`newmark`]: the trapezoidal rule on SO(3) (Simo & Vu-Quoc).
//! * [`momentum`]: the midpoint scheme with the geodesic mid rotation —
//!   conserves linear and angular momentum exactly.
//! * [`energy_momentum`]: the algebraic mid rotation and the β correction —
//!   conserves momenta and the total energy of conservative systems.

pub mod energy_momentum;
pub mod midpoint;
pub mod momentum;
pub mod newmark;

use crate::newton::NewtonSettings;
use flexmech_core::MassKind;
use nalgebra::Vector3;

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

/// Nodal velocities: spatial translational `v` and body angular `W`
/// (`Ṙ = R Ŵ`, `R` the nodal rotation from the initial configuration).
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    pub v: Vec<Vector3<f64>>,
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
