//! The momentum-conserving scheme (paper §5.1's "momentum conserving
//! algorithm"): the midpoint scheme of [`super::midpoint`] with the geodesic
//! mid rotation `Λ̃ = exp(½ω̂_r)Λ_r,ₙ`. Its internal force is self-equilibrated
//! about the mid-step configuration and its inertial terms are exact, so
//! linear and angular momentum of an unsupported system are conserved to the
//! Newton tolerance; energy is not conserved exactly (it is in the
//! energy–momentum scheme).

use super::simulation::{self, Integrator};
use super::{DynamicSettings, Motion};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use flexmech_core::Configuration;

/// Integrates `mech` from `initial` with the momentum-conserving scheme.
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    simulation::solve(mech, Integrator::Momentum, settings, initial, on_step)
}
