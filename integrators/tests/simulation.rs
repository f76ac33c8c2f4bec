//! The stepping driver: a [`Simulation`] stepped by hand gives the records
//! of a run to the end, bit for bit, for every integrator; it exposes the
//! state and velocities between steps; and a free beam in rigid translation
//! moves as the analytic solution says (`x = x₀ + v₀t`, `v = v₀`, `W = 0`)
//! in every scheme.

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::simulation::{self, Integrator, Simulation};
use flexmech_integrators::dynamics::{DynamicSettings, Motion};
use flexmech_integrators::{Mechanism, StepRecord};
use nalgebra::Vector3;

const ALL: [Integrator; 5] = [
    Integrator::Newmark,
    Integrator::GeneralizedAlpha { rho_inf: 0.8 },
    Integrator::Momentum,
    Integrator::EnergyMomentum,
    Integrator::EnergyMomentumPaper,
];

/// A free beam of length 10 (8 two-node elements) with the initial
/// velocity field `v = v₀ + ω × x`, `W = ω`.
fn free_beam(v0: Vector3<f64>, om: Vector3<f64>) -> (Mechanism, Motion, DynamicSettings) {
    let sec = Section::new(
        [1.0e4, 4.0e3, 4.0e3],
        [50.0, 80.0, 80.0],
        1.0,
        [0.2, 0.1, 0.1],
    );
    let mut mesh = Mesh::default();
    mesh.add_straight_beam(
        Vector3::zeros(),
        Vector3::new(10.0, 0.0, 0.0),
        Vector3::y(),
        8,
        2,
        sec,
    )
    .unwrap();
    let mech = Mechanism::new(mesh);
    let motion = crate::common::rigid_motion(&mech.mesh.positions, v0, om);
    let settings = crate::common::settings(0.05, 1.0, 1e-12, 30, 6, MassKind::Consistent);
    (mech, motion, settings)
}

/// Time, step, positions, quaternions, energies and angular momentum.
type Fingerprint = (f64, f64, Vec<[f64; 3]>, Vec<[f64; 4]>, [f64; 4], [f64; 3]);

/// The parts of a record a result file stores per step (β is NaN for most
/// schemes, so records are compared through these).
fn fingerprint(r: &StepRecord) -> Fingerprint {
    let e = r.energy;
    (
        r.time,
        r.dt,
        r.positions.clone(),
        r.quaternions.clone(),
        [e.kinetic, e.strain, e.potential, e.total],
        r.momentum_angular,
    )
}

#[test]
fn stepping_by_hand_equals_a_run_to_the_end() {
    let (mech, motion, settings) =
        free_beam(Vector3::new(0.5, -0.2, 0.3), Vector3::new(0.3, 0.2, 1.0));
    for integrator in ALL {
        let mut whole = Vec::new();
        simulation::solve(&mech, integrator, &settings, &motion, |r| {
            whole.push(fingerprint(r))
        })
        .unwrap();
        let mut sim = Simulation::new(&mech, integrator, &settings, &motion).unwrap();
        let mut stepped = vec![fingerprint(&sim.record())];
        // Pause half-way: look at the state, then go on.
        while sim.time() < 0.5 - 1e-12 {
            stepped.push(fingerprint(&sim.step().unwrap().expect("before t_end")));
        }
        assert_eq!(sim.time(), 0.5, "{integrator:?}: times are n·Δt");
        let (v, w) = sim.velocities();
        assert_eq!(
            (v.len(), w.len()),
            (mech.mesh.node_count(), mech.mesh.node_count())
        );
        assert_eq!(fingerprint(&sim.record()), *stepped.last().unwrap());
        sim.run(|r| stepped.push(fingerprint(r))).unwrap();
        assert!(sim.step().unwrap().is_none(), "{integrator:?}: past t_end");
        assert_eq!(whole.len(), 21, "{integrator:?}");
        assert_eq!(whole, stepped, "{integrator:?}");
    }
}

#[test]
fn a_free_beam_in_rigid_translation_moves_as_the_analytic_solution() {
    let v0 = Vector3::new(0.4, -0.3, 0.2);
    let (mech, motion, settings) = free_beam(v0, Vector3::zeros());
    for integrator in ALL {
        let mut sim = Simulation::new(&mech, integrator, &settings, &motion).unwrap();
        sim.run(|_| {}).unwrap();
        let t = sim.time();
        assert_eq!(t, settings.t_end);
        let state = sim.state();
        for (x, x0) in state.config.x.iter().zip(&mech.mesh.positions) {
            let err = (x - (x0 + v0 * t)).norm();
            assert!(err < 1e-12, "{integrator:?}: position off by {err:e}");
        }
        for r in &state.config.rot {
            assert!((r - nalgebra::Matrix3::identity()).norm() < 1e-12);
        }
        let (v, w) = sim.velocities();
        for (vi, wi) in v.iter().zip(w) {
            assert!((vi - v0).norm() < 1e-12, "{integrator:?}: v = {vi:?}");
            assert!(wi.norm() < 1e-12, "{integrator:?}: W = {wi:?}");
        }
        // Kinetic energy ½ m |v₀|² with m = ρA L = 10.
        let kinetic = sim.record().energy.kinetic;
        let exact = 0.5 * 10.0 * v0.norm_squared();
        assert!(
            (kinetic - exact).abs() < 1e-12 * exact,
            "{integrator:?}: {kinetic}"
        );
    }
}
