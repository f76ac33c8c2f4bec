//! A beam's initial geometry as a parameter of exact sensitivities: one
//! coordinate of a straight beam's end ([`crate::sensitivity::Parameter::Geometry`]).
//!
//! Moving an end of a straight beam moves its nodes along their places on
//! it (`dX/dp`), lengthens its elements (`dL/dp = s L`) and turns its initial
//! triads (`dλ₀/dp = ω̂ λ₀`). At a fixed configuration `(x, R)` the internal
//! forces change by
//!
//! ```text
//! ∂f/∂p = s ∂f/∂σ + K · (0, R₀ω, 0, R₁ω, …),
//! ```
//!
//! the first the stretch's (the gradient of `∂Π/∂σ`,
//! [`flexmech_core::BeamElement::stretch_rate`], by dual numbers), the second
//! the triads' turn: the energy sees `Λ = R λ₀`, so turning `λ₀` by `ω` is
//! turning each node by the spatial spin `Rω`, and `K` is the element's
//! exact tangent. The weight `ρA L g` grows with `s`; the masses and
//! inertias by [`flexmech_core::Inertia::geometry_derivative`]. The model
//! starts unstrained whatever the geometry, so at t = 0 only the weight and
//! the inertia change. A moved node's supported or prescribed translations
//! are held at `X + u(t)`, so they move with `dX/dp` at every step
//! ([`held_shifts`]): the free equations see them through the elements'
//! tangent (and, in dynamics, the inertia) like a prescribed motion.

use nalgebra::Vector3;

use crate::mechanism::{nodal_weights, Mechanism};
use flexmech_core::Configuration;

/// `∂g/∂p` of the beam's internal forces and weight at `config` and load
/// factor `lambda`, into `out` (added); returns `∂E/∂p` at fixed
/// configuration (strain energy and the weight's potential).
pub(crate) fn forces(
    mech: &Mechanism,
    config: &Configuration,
    lambda: f64,
    (stretch, spin): (&[(usize, f64)], &Vector3<f64>),
    out: &mut [f64],
) -> f64 {
    let mut energy = weight(mech, config, lambda, stretch, out);
    for &(e, s) in stretch {
        let el = &mech.mesh.elements[e];
        let nodes = el.nodes();
        let n = 6 * nodes.len();
        let (dpi, df) = el.stretch_force(&config.x, &config.rot);
        let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
        el.residual_tangent(&config.x, &config.rot, &mut r, &mut k);
        let mut spins = vec![0.0; n];
        for (a, &nd) in nodes.iter().enumerate() {
            let w = config.rot[nd] * spin;
            spins[6 * a + 3..6 * a + 6].copy_from_slice(w.as_slice());
        }
        for (a, &nd) in nodes.iter().enumerate() {
            for c in 0..6 {
                let row = 6 * a + c;
                let turn: f64 = (0..n).map(|col| k[col * n + row] * spins[col]).sum();
                out[6 * nd + c] += df[row] * s + turn;
            }
        }
        energy += dpi * s + r.iter().zip(&spins).map(|(a, b)| a * b).sum::<f64>();
    }
    energy
}

/// The weight's derivative `−ρA g w s L` at the beam's nodes into `out`;
/// returns its potential's `−Σ ∂f·u`.
pub(crate) fn weight(
    mech: &Mechanism,
    config: &Configuration,
    lambda: f64,
    stretch: &[(usize, f64)],
    out: &mut [f64],
) -> f64 {
    let g = mech.gravity * mech.gravity_scale.at(lambda);
    if g == Vector3::zeros() {
        return 0.0;
    }
    let mut energy = 0.0;
    for &(e, s) in stretch {
        let el = &mech.mesh.elements[e];
        let nodes = el.nodes();
        for (&nd, w) in nodes.iter().zip(nodal_weights(nodes.len())) {
            let f = g * (el.section().rho_a * w * el.length() * s);
            for c in 0..3 {
                out[6 * nd + c] -= f[c];
            }
            energy -= f.dot(&(config.x[nd] - mech.mesh.positions[nd]));
        }
    }
    energy
}

/// [`weight`] and [`line_loads`] alone: the residual's derivative at t = 0,
/// where the model starts unstrained whatever its geometry.
pub(crate) fn initial_forces(
    mech: &Mechanism,
    config: &Configuration,
    (stretch, loads): (&[(usize, f64)], &[usize]),
    out: &mut [f64],
) {
    out.iter_mut().for_each(|v| *v = 0.0);
    weight(mech, config, 0.0, stretch, out);
    line_loads(mech, config, 0.0, (stretch, loads), out);
}

/// Refuses moved nodes that a joint ties (a master, a slave, a rigid
/// body's link): relation (1) would no longer place the slave.
pub(crate) fn check_joints(
    mech: &Mechanism,
    shifts: &[(usize, Vector3<f64>)],
) -> Result<(), crate::error::SolveError> {
    let moved = |n: usize| {
        shifts
            .iter()
            .any(|(m, d)| *m == n && *d != Vector3::zeros())
    };
    match (mech.joints.iter()).find(|j| moved(j.master) || moved(j.slave)) {
        None => Ok(()),
        Some(j) => Err(crate::error::SolveError::InvalidMechanism(format!(
            "moving the beam's end moves a node joint `{}` ties, which would no longer be \
             placed by the joint: differentiate by the end of a beam whose moved nodes carry \
             no joint",
            j.name
        ))),
    }
}

/// The moved nodes' held translations — fixed or prescribed DOFs, where
/// `x = X + u(t)` — follow `dX/dp` rather than the unknowns: per moved node,
/// `dX/dp` on those components (zero elsewhere; nodes with none left out).
pub(crate) fn held_shifts(
    mech: &Mechanism,
    shifts: &[(usize, Vector3<f64>)],
) -> Vec<(usize, Vector3<f64>)> {
    (shifts.iter())
        .filter_map(|&(n, d)| {
            let held = |c: usize| {
                mech.fixed[n][c] || mech.prescribed.iter().any(|p| p.node == n && p.dof == c)
            };
            let h = Vector3::from_fn(|c, _| if held(c) { d[c] } else { 0.0 });
            (h != Vector3::zeros()).then_some((n, h))
        })
        .collect()
}

/// The beam's line loads' derivative: the dead nodal loads `loads` a
/// distributed load on it became scale with its elements' lengths, which all
/// stretch by `s` (`dF/dp = s F(λ)`), into `out` as `−dF`; returns their
/// potential's `−Σ dF·u`.
pub(crate) fn line_loads(
    mech: &Mechanism,
    config: &Configuration,
    lambda: f64,
    (stretch, loads): (&[(usize, f64)], &[usize]),
    out: &mut [f64],
) -> f64 {
    let Some(&(_, s)) = stretch.first() else {
        return 0.0;
    };
    let mut energy = 0.0;
    for &l in loads {
        let load = &mech.loads[l];
        let k = load.scale.at(lambda) * s;
        let (f, m) = (load.force * k, load.moment * k);
        for c in 0..3 {
            out[6 * load.node + c] -= f[c];
            out[6 * load.node + 3 + c] -= m[c];
        }
        energy -= f.dot(&(config.x[load.node] - mech.mesh.positions[load.node]));
    }
    energy
}
