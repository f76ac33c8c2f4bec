//! The paper's energy–momentum scheme (eqs 16–20), kept to reproduce the
//! paper (`integrator = "energy-momentum-paper"`): the midpoint scheme with the
//! algebraic mid rotation `Λ̃ = S(θ_r)⁻¹Λ_r,ₙ` and the correction
//! `β q_k(N_d, 0)`, `N_d = Nₙ₊₁ − Nₙ`, with one scalar `β` per step chosen so
//! that the discrete energy balance holds exactly (eq. 18):
//!
//! ```text
//! Σᵢ pᵢ·[q_k,i(Nₙ₊½, Mₙ₊½) + β q_k,i(N_d, 0)] = Πₙ₊₁ − Πₙ
//! ```
//!
//! (`pᵢ = (uᵢ, θᵢ)` the step's increments; the inertial terms contribute the
//! kinetic energy change exactly, and dead loads their work). `β` is solved
//! *with* the increments: Newton on `(q, β)` with the bordered tangent
//! `[K b; cᵀ d]`, `b = ∂g/∂β`, `c = ∂e/∂q`, `d = ∂e/∂β`, by two solves with
//! one factorisation. This keeps Newton quadratic, where eq. 20 inside the
//! iteration would make it a fixed point in β. If the border's pivot
//! `d − cᵀK⁻¹b` vanishes (no strain change in the step: β has no effect) the
//! step is solved without the correction and `β` is reported as NaN.
//!
//! Its force `q_k(N̄, M̄)` misses the strain energy change by `O(|φ|² Δt)`
//! per step (`φ` the elements' relative rotations; see
//! [`flexmech_core::discrete_gradient`]), so β grows like `|φ|²/Δt` as the
//! step is refined: the scheme conserves energy but is not consistent with
//! the beam's equations as `Δt → 0`. [`super::energy_momentum`] is.

use super::simulation::{self, Integrator};
use super::{DynamicSettings, Motion};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use flexmech_core::Configuration;

/// Integrates `mech` from `initial` with the paper's energy–momentum scheme
/// (bordered Newton on `(q, β)`).
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    simulation::solve(
        mech,
        Integrator::EnergyMomentumPaper,
        settings,
        initial,
        on_step,
    )
}
