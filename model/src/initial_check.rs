//! The derived quantities of a built model at t = 0 must be finite numbers.
//!
//! Every value in a model file is checked to be finite where it is read, but
//! products of finite values can overflow: a density of 1e308 times a
//! length, a velocity of 1e308 squared in the kinetic energy, a screw pitch
//! of 1e308 in the joint's map `N`, a stiffness of 1e308 squared in the
//! round-off floor. Such a model would fail at its first step with "residual
//! is not finite", or write `inf` in its first record; it is refused here
//! instead, naming the key whose value overflows and the quantity.

use crate::{Analysis, Model, ModelError, NodeRef};
use flexmech_integrators::dynamics::Motion;
use flexmech_integrators::Mechanism;
use nalgebra::{Matrix3, Vector3};

/// Checks the derived quantities of `mech` (built from `model`, node numbers
/// `beam_nodes`, initial motion `motion`) at t = 0.
pub(crate) fn check(
    model: &Model,
    mech: &Mechanism,
    beam_nodes: &[Vec<usize>],
    motion: &Motion,
) -> Result<(), ModelError> {
    let radius = mech
        .mesh
        .positions
        .iter()
        .map(|x| x.norm())
        .fold(1.0, f64::max);
    let dt = match model.solver.analysis {
        Analysis::Dynamic { dt, .. } => Some(dt),
        _ => None,
    };
    check_elements(model, mech, radius, dt)?;
    check_rigid_bodies(model, radius, dt)?;
    check_loads(model, radius)?;
    check_initial_velocities(model, beam_nodes, motion, radius)?;
    check_kinetic_energy(model, mech, motion)?;
    check_joints(model, mech, radius)
}

/// The refusal of `model`: `what` (about key `key`) is not a finite number.
fn fail(model: &Model, key: String, what: String) -> Result<(), ModelError> {
    Err(ModelError::new(
        &model.path,
        key,
        None,
        format!(
            "{what} is not a finite number in double precision; use smaller values (or \
             other units)"
        ),
    ))
}

/// Every element's squared force scale, mass and rotary inertia (times
/// size² and 1/dt², `dt` in a dynamic analysis) and gravity's work on it
/// (mechanism size `radius`), beam by beam.
fn check_elements(
    model: &Model,
    mech: &Mechanism,
    radius: f64,
    dt: Option<f64>,
) -> Result<(), ModelError> {
    // Elements, beam by beam (elements are numbered in the beams' order).
    let mut first = 0;
    for beam in &model.beams {
        let key = format!("section[{}]", beam.section);
        for e in &mech.mesh.elements[first..first + beam.elements] {
            let s = e.section();
            let (l, scale) = (e.length(), e.force_scale(radius));
            if !(scale * scale * beam.elements as f64).is_finite() {
                return fail(
                    model,
                    key,
                    format!(
                        "beam `{}`: the squared force scale of its elements (stiffness × size \
                         / element length)",
                        beam.name
                    ),
                );
            }
            let mass = s.rho_a * l * (1.0 + radius * radius);
            let spin = s.rho_j.iter().fold(0.0f64, |m, j| m.max(j.abs())) * l;
            let stepped = dt.map_or(1.0, |dt| 1.0 / (dt * dt));
            if !(mass * stepped).is_finite() || !(spin * stepped).is_finite() {
                return fail(
                    model,
                    key,
                    format!(
                        "beam `{}`: the mass or rotary inertia of its elements (times size² and \
                         1/dt²)",
                        beam.name
                    ),
                );
            }
            let weight =
                model.gravity.iter().fold(0.0f64, |m, g| m.max(g.abs())) * s.rho_a * l * radius;
            if !weight.is_finite() {
                return fail(
                    model,
                    "gravity".into(),
                    format!("beam `{}`: gravity's work", beam.name),
                );
            }
        }
        first += beam.elements;
    }
    Ok(())
}

/// Every rigid body's mass and inertia times size² (mechanism size
/// `radius`), 1/dt² (`dt` in a dynamic analysis) and gravity.
fn check_rigid_bodies(model: &Model, radius: f64, dt: Option<f64>) -> Result<(), ModelError> {
    for (k, body) in model.rigid_bodies.iter().enumerate() {
        let stepped = dt.map_or(1.0, |dt| 1.0 / (dt * dt));
        let spin = body
            .inertia
            .as_flattened()
            .iter()
            .fold(0.0f64, |m, j| m.max(j.abs()));
        let g = model.gravity.iter().fold(0.0f64, |m, g| m.max(g.abs()));
        let products = [
            body.mass * (1.0 + radius * radius) * stepped,
            spin * stepped,
            g * body.mass * radius,
        ];
        if products.iter().any(|p| !p.is_finite()) {
            return fail(
                model,
                format!("rigid_body[{k}]"),
                format!(
                    "rigid body `{}`: its mass or inertia (times size², 1/dt² and gravity)",
                    body.name
                ),
            );
        }
    }
    Ok(())
}

/// Every concentrated load's work at t = 0 (mechanism size `radius`).
fn check_loads(model: &Model, radius: f64) -> Result<(), ModelError> {
    for (k, load) in model.loads.iter().enumerate() {
        let f = Vector3::from(load.force).norm() * radius;
        let m = Vector3::from(load.moment).norm();
        let scale = load
            .time
            .as_ref()
            .map_or(1.0, |f| f.eval(0.0))
            .abs()
            .max(1.0);
        if !(f * scale).is_finite() || !(m * scale).is_finite() {
            return fail(model, format!("load[{k}]"), "the load's work".into());
        }
    }
    Ok(())
}

/// The squared initial velocity of every node of every `[[initial_velocity]]`
/// field (mechanism size `radius`).
fn check_initial_velocities(
    model: &Model,
    beam_nodes: &[Vec<usize>],
    motion: &Motion,
    radius: f64,
) -> Result<(), ModelError> {
    for (k, field) in model.initial_velocities.iter().enumerate() {
        for r in &field.nodes {
            let n = node(beam_nodes, *r);
            let (v, w) = (motion.v[n], motion.w[n]);
            let squares = v.norm_squared() * (1.0 + radius * radius) + w.norm_squared();
            if !squares.is_finite() {
                return fail(
                    model,
                    format!("initial_velocity[{k}]"),
                    format!("the initial velocity of `{}` squared", model.node_label(*r)),
                );
            }
        }
    }
    Ok(())
}

/// The initial kinetic energy of the elements of `mech` in `motion`.
fn check_kinetic_energy(
    model: &Model,
    mech: &Mechanism,
    motion: &Motion,
) -> Result<(), ModelError> {
    let kinetic: f64 = mech
        .mesh
        .elements
        .iter()
        .map(|e| {
            let s = e.section();
            let j = s.rho_j.iter().fold(0.0f64, |m, j| m.max(j.abs()));
            e.nodes()
                .iter()
                .map(|&n| {
                    e.length()
                        * (s.rho_a * motion.v[n].norm_squared() + j * motion.w[n].norm_squared())
                })
                .sum::<f64>()
        })
        .sum();
    if !kinetic.is_finite() {
        return fail(
            model,
            "initial_velocity".into(),
            "the initial kinetic energy (mass × velocity²)".into(),
        );
    }
    Ok(())
}

/// The mechanism's mass and rotary inertia, with the moment arm of its
/// size `radius`: a joint's rate moves the slave side at most that much.
fn mechanism_inertia(model: &Model, mech: &Mechanism, radius: f64) -> f64 {
    mech.mesh
        .elements
        .iter()
        .map(|e| {
            let s = e.section();
            let j = s.rho_j.iter().fold(0.0f64, |m, j| m.max(j.abs()));
            e.length() * (s.rho_a * (1.0 + radius * radius) + j)
        })
        .chain(model.rigid_bodies.iter().map(|b| {
            let spin = b
                .inertia
                .as_flattened()
                .iter()
                .fold(0.0f64, |m, j| m.max(j.abs()));
            b.mass * (1.0 + radius * radius) + spin
        }))
        .sum()
}

/// Every joint's map N at the initial angle times its rate, and the kinetic
/// energy its rate gives the mechanism (mechanism size `radius`).
fn check_joints(model: &Model, mech: &Mechanism, radius: f64) -> Result<(), ModelError> {
    let inertia = mechanism_inertia(model, mech, radius);
    for (j, joint) in mech.joints.iter().enumerate() {
        let x = &mech.mesh.positions[joint.master];
        let n = joint.map.variation(x, &Matrix3::identity(), &joint.initial);
        let given = model.joints.get(j).map_or(0.0, |s| s.rate);
        let rate = given.abs().max(1.0);
        if n.iter().any(|v| !(v * rate).is_finite()) {
            return fail(
                model,
                format!("joint[{j}]"),
                format!(
                    "joint `{}`: its map N at the initial angle (the derivative of the released \
                     translation, times the joint's rate)",
                    joint.name
                ),
            );
        }
        let energy = n.iter().fold(0.0f64, |m, v| m.max((v * given).powi(2))) * inertia;
        if !energy.is_finite() {
            return fail(
                model,
                format!("joint[{j}].rate"),
                format!(
                    "joint `{}`: the kinetic energy its rate gives the mechanism (mass × (N × \
                     rate)²)",
                    joint.name
                ),
            );
        }
    }
    Ok(())
}

/// The global node number of model node `r` (node numbers `beam_nodes`).
fn node(beam_nodes: &[Vec<usize>], r: NodeRef) -> usize {
    beam_nodes[r.beam][r.node]
}
