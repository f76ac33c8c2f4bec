//! What a time-integration scheme adds to the reduced system
//! ([`StepTerms`]) to be driven step by step by
//! [`Simulation`](super::simulation::Simulation): its step size, when it
//! takes the loads, the velocities its predictor uses, its Newton solve and
//! what it updates when a step is accepted.

use super::checkpoint::{CheckpointMismatch, Tape};
use crate::error::NewtonFailure;
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonReport, NewtonSettings};
use crate::record::Sensitivity;
use crate::sensitivity::Parameter;
use crate::system::{ReducedSystem, StepTerms};
use flexmech_core::Inertia;
use nalgebra::Vector3;

/// A scheme's exact sensitivities while a run steps.
pub(crate) enum SchemeSensitivities {
    /// The Newmark family's ([`super::newmark_sensitivity`]).
    Newmark(super::newmark_sensitivity::NewmarkSensitivities),
    /// The midpoint schemes' ([`super::midpoint_sensitivity`]).
    Midpoint(super::midpoint_sensitivity::MidpointSensitivities),
}

impl SchemeSensitivities {
    /// The sensitivities of the state at t = 0.
    pub(crate) fn initial(&self) -> Vec<Sensitivity> {
        match self {
            SchemeSensitivities::Newmark(s) => s.initial.clone(),
            SchemeSensitivities::Midpoint(s) => s.initial.clone(),
        }
    }
}

/// A time-integration scheme over the shared reduced system.
pub(crate) trait TimeScheme: StepTerms + Sized {
    /// Sets the size of the coming step.
    fn set_step(&mut self, dt: f64);

    /// The time at which the step `t → t + dt` takes its external loads.
    fn load_time(&self, t: f64, dt: f64) -> f64;

    /// Nodal velocities at the start of the coming step: spatial
    /// translational `v` and body angular `W`.
    fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]);

    /// The velocities the predictor carries on (default: [`Self::velocities`]).
    fn predictor_velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        self.velocities()
    }

    /// Rates of each joint's released coordinates, for the predictor
    /// (empty: the joints' coordinates start from their last values).
    fn joint_rates(&self) -> &[Vec<f64>] {
        &[]
    }

    /// The mechanism's mass.
    fn mass(&self) -> &Inertia;

    /// Energy dissipated by structural damping since t = 0 (schemes that
    /// take damping).
    fn dissipated(&self) -> f64 {
        0.0
    }

    /// Solves the step from the predicted iterate `sys.end`; returns the
    /// Newton report and the record's `beta` (NaN: none). `r` and `dq` are
    /// scratch of length `n_eq`.
    fn solve(
        sys: &mut ReducedSystem<'_, Self>,
        lu: &mut SparseLu,
        settings: &NewtonSettings,
        r: &mut [f64],
        dq: &mut [f64],
    ) -> Result<(NewtonReport, f64), NewtonFailure> {
        newton::solve(sys, lu, settings, r, dq).map(|report| (report, f64::NAN))
    }

    /// The step `sys.start → sys.end` of size `dt` converged and was
    /// accepted: updates the velocities (and whatever else the scheme
    /// carries) and returns the drivers' work over the step.
    fn finish(sys: &mut ReducedSystem<'_, Self>, dt: f64) -> f64;

    /// Writes what the scheme carries between steps (for a restart).
    fn save(&self, tape: &mut Tape);

    /// Reads back what [`TimeScheme::save`] wrote, checking its shapes
    /// against `mech`.
    fn restore(&mut self, mech: &Mechanism, tape: &mut Tape) -> Result<(), CheckpointMismatch>;

    /// Sets up the exact sensitivities to `params` at t = 0 (`mass`: the
    /// run's mass matrix). Default: the scheme has none yet.
    fn sensitivities(
        _sys: &mut ReducedSystem<'_, Self>,
        _params: &[Parameter],
        _mass: flexmech_core::MassKind,
    ) -> Result<SchemeSensitivities, SolveError> {
        Err(SolveError::InvalidMechanism(
            "sensitivities are computed with integrator \"newmark\" or \"generalized-alpha\" \
             so far"
                .into(),
        ))
    }

    /// The sensitivities of the step `sys.start → sys.end` just converged,
    /// before [`TimeScheme::finish`]; `fext_end` the external forces at its
    /// end.
    fn sensitivity_step(
        _sys: &mut ReducedSystem<'_, Self>,
        _sens: &mut SchemeSensitivities,
        _fext_end: &[f64],
    ) -> Result<Vec<Sensitivity>, SolveError> {
        Err(SolveError::InvalidMechanism(
            "this integrator computes no sensitivities".into(),
        ))
    }
}
