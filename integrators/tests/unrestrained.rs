//! A mechanism that is not held has no unique answer: every solver refuses
//! it with a description of what is free, whether Newton happens to reach a
//! small residual or not. The free motions are known exactly here (rigid-body
//! motions of a straight beam), so the description is checked against them.

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::{momentum, newmark, DynamicSettings, Motion};
use flexmech_integrators::free_motion::FreeMotion;
use flexmech_integrators::{
    solve_static, Mechanism, NewtonSettings, NodalLoad, PrescribedDof, Schedule, SolveError,
    StaticSettings,
};
use nalgebra::Vector3;

/// Agreement of a reported axis or direction with the exact one: the
/// description is built from a null direction found to round-off.
const DIRECTION: f64 = 1e-6;

fn strip(rho_a: f64, rho_j: f64) -> Mechanism {
    let sec = Section::new(
        [1.0e5, 5.0e4, 5.0e4],
        [80.0, 100.0, 100.0],
        rho_a,
        [rho_j; 3],
    );
    let mut mesh = Mesh::default();
    mesh.add_straight_beam(
        Vector3::zeros(),
        Vector3::new(10.0, 0.0, 0.0),
        Vector3::y(),
        10,
        2,
        sec,
    )
    .unwrap();
    Mechanism::new(mesh)
}

fn statics(mech: &Mechanism) -> Result<usize, SolveError> {
    let settings = StaticSettings {
        load_steps: 4,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 4,
    };
    let mut steps = 0;
    solve_static(mech, &settings, |_| steps += 1).map(|_| steps)
}

fn unrestrained(res: Result<usize, SolveError>) -> FreeMotion {
    match res {
        Err(SolveError::Unrestrained {
            condition, motion, ..
        }) => {
            assert!(condition > 1e13, "condition {condition:e}");
            *motion
        }
        other => panic!("expected an unrestrained mechanism, got {other:?}"),
    }
}

#[test]
fn a_free_strip_turned_at_one_end_is_refused_naming_its_rigid_motions() {
    // Before: "completed", the strip drifting by whatever the singular LU
    // made of round-off. The end's rz is driven, so the three translations
    // are free whatever state Newton stops in (the rotations about x and y
    // only at a stress-free one).
    let mut mech = strip(0.0, 0.0);
    mech.prescribed.push(PrescribedDof {
        node: 10,
        dof: 5,
        value: Schedule::ramp(),
    });
    let motion = unrestrained(statics(&mech));
    assert_eq!(motion.translations.len(), 3, "{motion:?}");
    for (axis, _) in &motion.rotations {
        assert!(axis.z.abs() < DIRECTION, "{axis}");
    }
    let text = motion.to_string();
    assert!(text.contains("translation in any direction"), "{text}");
    assert!(text.contains("[[support]]"), "{text}");
}

#[test]
fn a_pinned_strip_is_refused_naming_the_axis_and_its_point() {
    // Held at the start in every DOF but rz: a free rotation about z
    // through the origin. No load: Newton converges at once, so the check
    // factorises the tangent itself.
    let mut mech = strip(0.0, 0.0);
    mech.fixed[0] = [true, true, true, true, true, false];
    let motion = unrestrained(statics(&mech));
    assert!(motion.translations.is_empty(), "{motion:?}");
    assert_eq!(motion.rotations.len(), 1, "{motion:?}");
    let (axis, point) = motion.rotations[0];
    assert!((axis - Vector3::z()).norm() < DIRECTION, "{axis}");
    // The point is on the axis: its x and y are the pin's.
    assert!(point.xy().norm() < DIRECTION * 10.0, "{point}");
}

#[test]
fn a_loaded_unsupported_strip_fails_as_unrestrained() {
    // A load on a free body has no static equilibrium: Newton fails on the
    // singular tangent, and the failure says why.
    let mut mech = strip(0.0, 0.0);
    mech.loads.push(NodalLoad {
        node: 10,
        force: Vector3::new(0.0, 1.0, 0.0),
        moment: Vector3::zeros(),
        scale: Schedule::ramp(),
    });
    let motion = unrestrained(statics(&mech));
    assert_eq!(motion.translations.len(), 3, "{motion:?}");
    assert_eq!(motion.rotations.len(), 3, "{motion:?}");
}

#[test]
fn a_well_held_strip_is_accepted() {
    let mut mech = strip(0.0, 0.0);
    mech.fixed[0] = [true; 6];
    mech.loads.push(NodalLoad {
        node: 10,
        force: Vector3::new(0.0, 1.0, 0.0),
        moment: Vector3::zeros(),
        scale: Schedule::ramp(),
    });
    assert_eq!(statics(&mech).unwrap(), 4);
}

fn dynamics(rho_a: f64, rho_j: f64) -> (Mechanism, Motion, DynamicSettings) {
    let mech = strip(rho_a, rho_j);
    let n = mech.mesh.node_count();
    let motion = Motion {
        v: vec![Vector3::new(0.0, 0.5, 0.0); n],
        w: vec![Vector3::new(0.0, 0.0, 0.1); n],
        joint_rates: Vec::new(),
    };
    let settings = crate::common::settings(0.01, 0.05, 1e-12, 30, 4, MassKind::Consistent);
    (mech, motion, settings)
}

#[test]
fn a_massless_free_strip_in_dynamics_is_refused() {
    // Before: every step "converged" at a scaled residual of about 1 (the
    // round-off floor of an all-zero force scale) and the schemes gave
    // different trajectories. With no mass the effective tangent is the
    // stiffness alone: the rigid motions are free.
    let (mech, motion, settings) = dynamics(0.0, 0.0);
    for res in [
        newmark::solve(&mech, &settings, &motion, |_| {}),
        momentum::solve(&mech, &settings, &motion, |_| {}),
    ] {
        match res {
            Err(SolveError::Unrestrained { motion, .. }) => {
                assert_eq!(motion.translations.len(), 3, "{motion:?}");
            }
            other => panic!("expected an unrestrained mechanism, got {other:?}"),
        }
    }
}

#[test]
fn the_same_strip_with_mass_moves_freely() {
    let (mech, motion, settings) = dynamics(1.0, 0.01);
    newmark::solve(&mech, &settings, &motion, |_| {}).unwrap();
    momentum::solve(&mech, &settings, &motion, |_| {}).unwrap();
}
