//! Newmark's trapezoidal rule (β = ¼, γ = ½) on SO(3) (Simo & Vu-Quoc):
//! equilibrium at `tₙ₊₁` with the internal force of the beam (the exact
//! gradient of the strain energy), translations by the standard Newmark
//! relations and rotations through the material incremental rotation
//! `Ω = Rₙᵀ log(Rₙ₊₁Rₙᵀ)`:
//!
//! ```text
//! Aₙ₊₁ = (Ω − Δt Wₙ − Δt²(½ − β) Aₙ)/(β Δt²),   Wₙ₊₁ = Wₙ + Δt((1 − γ)Aₙ + γ Aₙ₊₁)
//! ```
//!
//! with the spatial inertial moment `Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)`. It
//! conserves neither energy nor angular momentum in general; the paper's
//! screw example shows its energy growing until it fails.

use super::simulation::{self, Integrator};
use super::{DynamicSettings, Motion};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use flexmech_core::Configuration;

/// Integrates `mech` from `initial` with Newmark's trapezoidal rule. Joints
/// enter through `N` (as in statics); driven coordinates and prescribed DOFs
/// follow their schedules. Reports a record at t = 0 and after every
/// converged step.
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    simulation::solve(mech, Integrator::Newmark, settings, initial, on_step)
}
