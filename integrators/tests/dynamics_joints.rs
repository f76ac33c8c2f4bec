//! Joints in dynamics: a stiff arm descending a screw under gravity follows
//! the rigid-body acceleration with every integrator (Newmark through `N`,
//! the conserving schemes through `Ñ`), the constraint holds to round-off at
//! every step, and the energy–momentum scheme conserves the total energy
//! (kinetic + strain + gravity).

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::{energy_momentum, momentum, newmark, Motion};
use flexmech_integrators::{JointInstance, Mechanism, StepRecord};
use flexmech_joints::{ReleasedState, Screw, MAX_RELEASED};
use nalgebra::Vector3;
use std::sync::Arc;

const RHO_A: f64 = 2.0;
const RHO_I3: f64 = 0.01;
const PITCH: f64 = 0.1;
const G: f64 = 9.81;

/// A stiff clamped post and a stiff horizontal arm of length 1 on a screw
/// joint (axis z) at the post's top, under gravity.
fn screw_arm() -> Mechanism {
    let stiff = |rho_a: f64| {
        Section::new(
            [1.0e8, 4.0e7, 4.0e7],
            [1.0e5, 1.0e5, 1.0e5],
            rho_a,
            [0.02, 0.01, RHO_I3],
        )
    };
    let mut mesh = Mesh::default();
    let post = mesh
        .add_straight_beam(
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, 2.0),
            Vector3::x(),
            2,
            2,
            stiff(RHO_A),
        )
        .unwrap();
    let arm = mesh
        .add_straight_beam(
            Vector3::new(0.0, 0.0, 2.0),
            Vector3::new(1.0, 0.0, 2.0),
            Vector3::y(),
            4,
            2,
            stiff(RHO_A),
        )
        .unwrap();
    let mut mech = Mechanism::new(mesh);
    mech.fixed[post[0]] = [true; 6];
    mech.gravity = Vector3::new(0.0, 0.0, -G);
    mech.joints.push(JointInstance {
        name: "screw".into(),
        master: *post.last().unwrap(),
        slave: arm[0],
        map: Arc::new(Screw {
            axis: Vector3::z(),
            pitch: PITCH,
        }),
        initial: ReleasedState::new([0.0; MAX_RELEASED]),
        driven: vec![None],
    });
    mech
}

#[derive(Debug, Clone, Copy)]
enum Scheme {
    Newmark,
    Momentum,
    EnergyMomentum,
}

#[test]
fn arm_descends_the_screw_with_the_rigid_body_acceleration() {
    let mech = screw_arm();
    let settings = crate::common::settings(0.01, 1.0, 1e-10, 30, 6, MassKind::Consistent);
    // Rigid arm: mass m = ρA·L, moment of inertia about the screw axis
    // I = ρA L³/3 (consistent mass, exact for the linear velocity field) +
    // ρI₃·L (the sections' own rotational inertia about z).
    let m = RHO_A * 1.0;
    let i_z = RHO_A / 3.0 + RHO_I3 * 1.0;
    let a = G * m * PITCH * PITCH / (m * PITCH * PITCH + i_z);
    for scheme in [Scheme::Newmark, Scheme::Momentum, Scheme::EnergyMomentum] {
        let mut steps: Vec<StepRecord> = Vec::new();
        let rest = Motion::rest(mech.mesh.node_count());
        let push = |s: &StepRecord| steps.push(s.clone());
        match scheme {
            Scheme::Newmark => newmark::solve(&mech, &settings, &rest, push),
            Scheme::Momentum => momentum::solve(&mech, &settings, &rest, push),
            Scheme::EnergyMomentum => energy_momentum::solve(&mech, &settings, &rest, push),
        }
        .unwrap();
        let last = steps.last().unwrap();
        let slave = mech.joints[0].slave;
        let descent = 2.0 - last.positions[slave][2];
        let measured = 2.0 * descent / (last.time * last.time);
        assert!(
            (measured - a).abs() <= 0.01 * a,
            "{scheme:?}: acceleration {measured} vs rigid-body {a}"
        );
        // The joint angle follows: ψ = z/c (rigid screw), descending turns negative.
        let psi = last.joints[0].angle;
        assert!(
            (psi * PITCH + descent).abs() <= 1e-3 * descent,
            "{scheme:?}: ψ {psi}, descent {descent}"
        );
        // Relation (1) at every step.
        assert!(steps.iter().all(|s| s.joints[0].constraint_error <= 1e-12));
        // Energy (kinetic + strain + gravity) of this conservative system,
        // relative to the potential energy released, m·g·descent.
        let e0 = steps[0].energy.total;
        let scale = m * G * descent;
        let de = steps
            .iter()
            .map(|s| (s.energy.total - e0).abs())
            .fold(0.0, f64::max)
            / scale;
        let iters: usize = steps.iter().map(|s| s.iterations).sum();
        eprintln!(
            "screw descent, {scheme:?}: a = {measured:.5} (rigid {a:.5}), energy error {de:.2e} of m·g·descent, {:.1} iterations/step",
            iters as f64 / (steps.len() - 1) as f64
        );
        if let Scheme::EnergyMomentum = scheme {
            // Newton's relative tolerance 1e-10 per step, over 100 steps.
            assert!(de <= 1e-8, "EM energy error {de:e}");
        }
    }
}

/// The screw arm with its angle driven through a smooth start-up,
/// `ψ(t) = Ψ (t − sin(2πt)/(2π))` with Ψ = 4 rad/s: the drive does work
/// against gravity and inertia, and `total − driver_work` is the conserved
/// quantity. The energy–momentum scheme keeps it to the solver tolerance; the
/// momentum scheme and Newmark (trapezoidal estimate of the work) are
/// reported.
#[test]
fn driven_screw_balances_energy_with_the_drive_work() {
    use flexmech_integrators::Schedule;
    let mut mech = screw_arm();
    mech.joints[0].driven = vec![Some(Schedule::new(|t| {
        4.0 * (t - (2.0 * std::f64::consts::PI * t).sin() / (2.0 * std::f64::consts::PI))
    }))];
    let settings = crate::common::settings(0.01, 1.0, 1e-11, 30, 6, MassKind::Consistent);
    let rest = Motion::rest(mech.mesh.node_count());
    for scheme in [Scheme::Newmark, Scheme::Momentum, Scheme::EnergyMomentum] {
        let mut steps: Vec<StepRecord> = Vec::new();
        let push = |s: &StepRecord| steps.push(s.clone());
        match scheme {
            Scheme::Newmark => newmark::solve(&mech, &settings, &rest, push),
            Scheme::Momentum => momentum::solve(&mech, &settings, &rest, push),
            Scheme::EnergyMomentum => energy_momentum::solve(&mech, &settings, &rest, push),
        }
        .unwrap();
        let balance = |s: &StepRecord| s.energy.total - s.energy.driver_work;
        let b0 = balance(&steps[0]);
        let work = steps
            .iter()
            .map(|s| s.energy.driver_work.abs())
            .fold(0.0, f64::max);
        let err = steps
            .iter()
            .map(|s| (balance(s) - b0).abs())
            .fold(0.0, f64::max)
            / work;
        // At t = 1 the drive has turned ψ = 4 and is at rest again
        // (ψ̇ = Ψ(1 − cos 2πt) = 0): its work is the rigid arm's rise,
        // m g c ψ, up to the beams' flexibility (stiff here).
        let last = steps.last().unwrap();
        let rigid = RHO_A * G * PITCH * 4.0;
        eprintln!(
            "driven screw, {scheme:?}: drive work {:.5} (rigid-body {rigid:.5}), energy balance error {err:.2e} of the work",
            last.energy.driver_work
        );
        assert!(steps.iter().all(|s| s.joints[0].constraint_error <= 1e-12));
        assert!(
            (last.energy.driver_work - rigid).abs() <= 0.01 * rigid,
            "{scheme:?}: drive work {} vs rigid {rigid}",
            last.energy.driver_work
        );
        if let Scheme::EnergyMomentum = scheme {
            assert!(err <= 1e-9, "EM energy balance {err:e}");
        }
    }
}
