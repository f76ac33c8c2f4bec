//! The generalized-α scheme on the Lie group (Arnold & Brüls 2007; Brüls,
//! Cardona & Arnold 2012), Chung & Hulbert's coefficients from the spectral
//! radius `ρ∞` at infinite frequency: equilibrium at `tₙ₊₁` with the true
//! accelerations `q̈ₙ₊₁`, the configuration advanced with the
//! pseudo-acceleration `a` (body angular for rotations):
//!
//! ```text
//! Ωₙ = Δt Wₙ + Δt²(½ − β) Aₙ + Δt² β Aₙ₊₁,   Rₙ₊₁ = Rₙ exp(Ω̂ₙ)
//! Wₙ₊₁ = Wₙ + Δt((1 − γ)Aₙ + γ Aₙ₊₁)
//! (1 − α_m) Aₙ₊₁ + α_m Aₙ = (1 − α_f) Ȧₙ₊₁ + α_f Ȧₙ
//! ```
//!
//! and the same for translations. Second-order accurate, unconditionally
//! stable for linear problems, with high frequencies damped to `ρ∞` per
//! step (`ρ∞ = 1`: no damping; the trapezoidal rule when `a₀ = q̈₀`, as here).
//! Joints enter through `N`, as in [`super::newmark`]. The energy it
//! dissipates is numerical: the energy balance of a run may only decrease.
//! FORMULATION §4.5.

use super::simulation::{self, Integrator};
use super::{DynamicSettings, Motion};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use flexmech_core::Configuration;

pub use super::newmark_terms::Coefficients;

/// The default spectral radius at infinite frequency (model files'
/// `rho_inf`).
pub const DEFAULT_RHO_INF: f64 = 0.9;

/// Integrates `mech` from `initial` with the generalized-α scheme of
/// spectral radius `rho_inf` (in `[0, 1]`). Reports a record at t = 0 and
/// after every converged step.
pub fn solve(
    mech: &Mechanism,
    rho_inf: f64,
    settings: &DynamicSettings,
    initial: &Motion,
    on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    simulation::solve(
        mech,
        Integrator::GeneralizedAlpha { rho_inf },
        settings,
        initial,
        on_step,
    )
}
