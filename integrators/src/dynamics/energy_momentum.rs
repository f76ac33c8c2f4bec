//! The energy–momentum scheme: the midpoint scheme of [`super::midpoint`]
//! with the energy-consistent element force
//! ([`flexmech_core::discrete_gradient`], FORMULATION §4.3) — a discrete
//! gradient of the element's strain energy whose work on the step's
//! increments is the strain energy change exactly and which is
//! self-equilibrated about the mid-step configuration. Total energy of a
//! conservative system and linear and angular momentum of an unsupported one
//! are conserved to the Newton tolerance, joints included (through the exact
//! incremental map `Ñ`). Unlike the paper's scheme
//! ([`super::energy_momentum_paper`]) no scalar β is solved for: Newton is
//! plain, and the force tends to the static element's exact gradient as
//! `Δt → 0`. The record's `beta` carries the relative size of the
//! discrete gradient's rank-one corrections, `O(Δt²)`.

use super::simulation::{self, Integrator};
use super::{DynamicSettings, Motion};
use crate::error::SolveError;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use flexmech_core::Configuration;

/// Integrates `mech` from `initial` with the energy–momentum scheme.
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    simulation::solve(mech, Integrator::EnergyMomentum, settings, initial, on_step)
}
