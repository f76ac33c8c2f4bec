//! The measures of a converged step — energies and momenta of the whole
//! mechanism — and the [`StepRecord`]s built from them, for statics and
//! for every time integrator alike.

use crate::constraints::{joint_records, MechanismState};
use crate::mechanism::Mechanism;
use crate::newton::NewtonReport;
use crate::record::{Energies, StepRecord};
use crate::threads::map_each;
use flexmech_core::mesh::RelativeRotations;
use flexmech_core::{Configuration, Inertia};
use nalgebra::Vector3;

/// Strain energy of the whole mesh (element energies summed in element
/// order, each [`flexmech_core::Element::recorded_energy`]).
pub fn strain_energy(mech: &Mechanism, config: &Configuration) -> f64 {
    strain_energy_with(mech, config, None)
}

/// [`strain_energy`] given each element's relative rotations in `config`
/// (`relative`, as the solvers' rotation guard keeps them for the state it
/// has accepted; [`flexmech_core::Element::recorded_energy_with`]): the same
/// sum to the bit, one logarithm per 2-node element fewer.
pub fn strain_energy_with(
    mech: &Mechanism,
    config: &Configuration,
    relative: Option<&[RelativeRotations]>,
) -> f64 {
    let elements = &mech.mesh.elements;
    let per = map_each(elements.len(), |e| match relative {
        Some(relative) => elements[e].recorded_energy_with(&relative[e], &config.x, &config.rot),
        None => elements[e].recorded_energy(&config.x, &config.rot),
    });
    per.iter().sum::<f64>()
}

/// Potential of the external nodal forces `fext` (6 per node), taken as
/// dead: `−Σ f·u` (gravity included; moments, which are not conservative
/// for finite 3D rotations, are left out).
pub fn load_potential(mech: &Mechanism, config: &Configuration, fext: &[f64]) -> f64 {
    -(0..config.x.len())
        .map(|n| {
            let u: Vector3<f64> = config.x[n] - mech.mesh.positions[n];
            u.dot(&Vector3::new(fext[6 * n], fext[6 * n + 1], fext[6 * n + 2]))
        })
        .sum::<f64>()
}

/// The work of the follower loads over a step from `(t₀, start)` to
/// `(t₁, end)` by the trapezoidal rule: `½(f₀ + f₁)·Δx + ½(m₀ + m₁)·Δθ` per
/// loaded node, `Δθ` the step's spatial rotation vector (exact for a
/// constant load and a rotation about a fixed axis). Follower loads have no
/// potential; the records count minus their work since t = 0 as their share
/// of the potential, so that the total energy stays a balance.
pub fn follower_work(
    mech: &Mechanism,
    (t0, start): (f64, &Configuration),
    (t1, end): (f64, &Configuration),
) -> f64 {
    if mech.follower_loads.is_empty() {
        return 0.0;
    }
    let n = start.x.len();
    let (mut f0, mut f1) = (vec![0.0; 6 * n], vec![0.0; 6 * n]);
    mech.add_follower_forces(t0, &start.rot, 1.0, &mut f0);
    mech.add_follower_forces(t1, &end.rot, 1.0, &mut f1);
    let mut nodes: Vec<usize> = mech.follower_loads.iter().map(|l| l.node).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let mut work = 0.0;
    for i in nodes {
        let dx = end.x[i] - start.x[i];
        let dth = flexmech_core::rotation::log(&(end.rot[i] * start.rot[i].transpose()));
        for c in 0..3 {
            work += 0.5 * (f0[6 * i + c] + f1[6 * i + c]) * dx[c];
            work += 0.5 * (f0[6 * i + 3 + c] + f1[6 * i + 3 + c]) * dth[c];
        }
    }
    work
}

/// A record of `state` with its strain energy and load potential (no
/// kinetic energy, no momenta: statics), after the Newton solve `report`
/// (`None`: the initial state).
pub fn static_record(
    mech: &Mechanism,
    state: &MechanismState,
    fext: &[f64],
    time: f64,
    dt: f64,
    report: Option<&NewtonReport>,
) -> StepRecord {
    let strain = strain_energy(mech, &state.config);
    record_with_strain(mech, state, strain, fext, (time, dt), report)
}

/// [`static_record`] with the strain energy given.
fn record_with_strain(
    mech: &Mechanism,
    state: &MechanismState,
    strain: f64,
    fext: &[f64],
    (time, dt): (f64, f64),
    report: Option<&NewtonReport>,
) -> StepRecord {
    let config = &state.config;
    let potential = load_potential(mech, config, fext);
    StepRecord {
        time,
        dt,
        iterations: report.map_or(0, |r| r.iterations),
        factorizations: report.map_or(0, |r| r.factorizations),
        residual: report.map_or(0.0, |r| r.residual),
        residual_history: report.map_or_else(Vec::new, |r| r.history.clone()),
        beta: f64::NAN,
        energy: Energies {
            kinetic: 0.0,
            strain,
            potential,
            total: strain + potential,
            driver_work: 0.0,
            dissipated: 0.0,
        },
        negative_pivots: None,
        momentum_linear: [0.0; 3],
        momentum_angular: [0.0; 3],
        positions: config.x.iter().map(|x| [x.x, x.y, x.z]).collect(),
        quaternions: quaternions(config),
        joints: joint_records(mech, state),
        support_reactions: vec![[f64::NAN; 6]; mech.supported_nodes().len()],
        velocities: Vec::new(),
        angular_velocities: Vec::new(),
        sensitivities: Vec::new(),
        critical: None,
    }
}

/// [`static_record`] with the kinetic energy and the linear and angular
/// momenta of nodal velocities `v` (spatial) and `w` (body angular), at
/// `(time, dt)`; `relative`: the elements' relative rotations in the
/// state where known ([`strain_energy_with`]).
#[allow(clippy::too_many_arguments)]
pub fn dynamic_record(
    mech: &Mechanism,
    inertia: &Inertia,
    state: &MechanismState,
    (v, w): (&[Vector3<f64>], &[Vector3<f64>]),
    fext: &[f64],
    (time, dt): (f64, f64),
    relative: Option<&[RelativeRotations]>,
    report: Option<&NewtonReport>,
) -> StepRecord {
    let strain = strain_energy_with(mech, &state.config, relative);
    let mut rec = record_with_strain(mech, state, strain, fext, (time, dt), report);
    let config = &state.config;
    let kinetic = inertia.kinetic_energy(v, w);
    rec.energy.kinetic = kinetic;
    rec.energy.total = kinetic + rec.energy.strain + rec.energy.potential;
    let lin = inertia.linear_momentum(v);
    let ang = inertia.angular_momentum(&config.x, &config.rot, v, w);
    rec.momentum_linear = [lin.x, lin.y, lin.z];
    rec.momentum_angular = [ang.x, ang.y, ang.z];
    rec.velocities = v.iter().map(|v| [v.x, v.y, v.z]).collect();
    rec.angular_velocities = w
        .iter()
        .zip(&config.rot)
        .map(|(w, r)| {
            let om = r * w;
            [om.x, om.y, om.z]
        })
        .collect();
    rec
}

/// Every node's unit quaternion `[x, y, z, w]` (on two threads for a large
/// mesh, [`crate::threads::map_nodes`]).
fn quaternions(config: &Configuration) -> Vec<[f64; 4]> {
    crate::threads::map_nodes(config.x.len(), |i| {
        let q = config.quaternion(i);
        [q.x, q.y, q.z, q.w]
    })
}
