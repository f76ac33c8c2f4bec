//! A joint's value as a parameter of the midpoint schemes' sensitivities
//! ([`super::midpoint_sensitivity`]).
//!
//! At fixed unknowns a change of the value `p` moves the slave's end pose by
//! `δ = R_m,ₙ₊₁ ∂f/∂p(ψₙ₊₁)` and changes the step's incremental map `Ñ`
//! (through the mid-step offset and the secant of `B`,
//! [`flexmech_joints::JointMap::incremental_transfer_by`]); the slave's start
//! pose moves with the history, which carries `δ` from step to step. So
//!
//! ```text
//! ∂r/∂p = Ñᵀ(∂q/∂x₁ · δ + (2/Δt²) M δ) + (∂Ñ/∂p)ᵀ g,
//! ```
//!
//! the scheme's element tangent with respect to the end pose applied to
//! the shift. At t = 0 the body the joint carries is re-placed with the
//! slave ([`crate::start_shift::StartShift`]) and the slave's velocity
//! `N q̇` changes by `ω_m × δ + s ψ̇₀`. A slave that carries further joints
//! is not differentiated yet.

use nalgebra::Vector3;

use super::midpoint::MidpointTerms;
use super::midpoint_kernels::element_kernel;
use super::midpoint_sensitivity::History;
use crate::error::SolveError;
use crate::joint_parameter::JointShift;
use crate::start_shift::StartShift;
use crate::system::ReducedSystem;

/// The direct effect of value `name` of joint `joint` at the end of the
/// step of `sys`, refused for a slave that carries further joints.
pub(super) fn shift(
    sys: &ReducedSystem<'_, MidpointTerms>,
    joint: usize,
    name: &str,
) -> Result<JointShift, SolveError> {
    let shift = JointShift::at(sys.mech, &sys.topo, &sys.end, joint, name)?;
    if shift.nodes.len() > 1 {
        return Err(SolveError::InvalidMechanism(format!(
            "joint `{}`: sensitivities by its `{name}` with the momentum and energy-momentum \
             schemes are not available for a slave that carries further joints: use \
             \"newmark\" or \"generalized-alpha\"",
            sys.mech.joints[joint].name
        )));
    }
    Ok(shift)
}

/// The history at t = 0: the carried body's positions `dX/dp` and the
/// slave's velocity; a carried body given an initial spin is refused (its
/// velocity field depends on where it is).
pub(super) fn start_history(
    sys: &ReducedSystem<'_, MidpointTerms>,
    (joint, name): (usize, &str),
    start: &StartShift,
    h: &mut History,
) -> Result<(), SolveError> {
    let shift = shift(sys, joint, name)?;
    let spinning =
        (start.nodes()).find(|n| !shift.nodes.contains(n) && sys.terms.w_n[*n] != Vector3::zeros());
    if let Some(n) = spinning {
        return Err(SolveError::InvalidMechanism(format!(
            "the body joint `{}`'s `{name}` re-places at t = 0 (with node {n}) starts with an \
             angular velocity, whose velocity field depends on the body's position: \
             differentiate by this value from a start without spin",
            sys.mech.joints[joint].name
        )));
    }
    for (n, x) in h.x.iter_mut().enumerate() {
        *x = start.of(n);
    }
    let m = shift.master();
    let omega = sys.end.config.rot[m] * sys.terms.w_n[m];
    let rate = sys.terms.rates[joint].first().copied().unwrap_or(0.0);
    for &n in &shift.nodes {
        h.v[n] += shift.velocity(&omega, rate);
    }
    Ok(())
}

/// Adds `∂q/∂x₁ · δ + (2/Δt²) M δ` and the master's part of `(∂Ñ/∂p)ᵀ g`
/// to the nodal `g_out`; returns the released equation's share.
pub(super) fn forces(
    sys: &ReducedSystem<'_, MidpointTerms>,
    (joint, name): (usize, &str),
    shift: &JointShift,
    g_out: &mut [f64],
) -> Result<Option<(usize, f64)>, SolveError> {
    let (start, end, terms) = (&sys.start, &sys.end, &sys.terms);
    let tangent = |e: &flexmech_core::Element, r: &mut [f64], k: &mut [f64]| {
        element_kernel(
            e,
            &start.config,
            &end.config,
            terms.scheme,
            terms.beta,
            true,
            r,
            k,
        )
    };
    let inertia = Some((&terms.inertia, 2.0 / (terms.dt * terms.dt)));
    shift.add_stiffness_with(sys.mech, tangent, inertia, g_out);
    let j = &sys.mech.joints[joint];
    let (m, s) = (j.master, j.slave);
    let g_s = nalgebra::Vector6::from_column_slice(&sys.nodal[6 * s..6 * s + 6]);
    let t = j
        .map
        .incremental_transfer_by(
            name,
            [
                (&start.config.x[m], &start.config.rot[m]),
                (&end.config.x[m], &end.config.rot[m]),
            ],
            [&start.released[joint], &end.released[joint]],
            &g_s,
        )
        .ok_or_else(|| {
            SolveError::InvalidMechanism(format!(
                "joint `{}`: its kind gives no derivative of the incremental map by `{name}`",
                j.name
            ))
        })?;
    for c in 0..6 {
        g_out[6 * m + c] += t[c];
    }
    Ok(sys.topo.released_eqs[joint]
        .first()
        .copied()
        .flatten()
        .map(|eq| (eq, t[6])))
}
