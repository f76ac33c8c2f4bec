//! The mechanism builder: typed handles, and every refusal of its
//! validating constructors; a mechanism it builds solves like one built by
//! hand.

use std::sync::Arc;

use flexmech_core::MeshError;
use flexmech_integrators::builder::{
    BeamDef, BeamShape, BuildError, Dof, JointDef, MechanismBuilder, SectionValues,
};
use flexmech_integrators::{solve_static, NewtonSettings, Schedule, StaticSettings};
use flexmech_joints::{JointMap, Prismatic, Screw};
use nalgebra::Vector3;

const ROD: SectionValues = SectionValues {
    ea: 1.0e6,
    ga: [4.0e5, 4.0e5],
    gj: 800.0,
    ei: [1000.0, 1000.0],
    rho_a: 0.0,
    rho_j: [0.0; 3],
};

fn straight(start: [f64; 3], end: [f64; 3], e2: Vector3<f64>) -> BeamDef {
    BeamDef {
        shape: BeamShape::Straight {
            start: Vector3::from(start),
            end: Vector3::from(end),
            e2,
        },
        elements: 4,
        nodes_per_element: 2,
        section: ROD,
    }
}

fn screw(pitch: f64) -> Arc<dyn JointMap> {
    Arc::new(Screw {
        axis: Vector3::z(),
        pitch,
    })
}

/// A clamped post and an arm whose start sits at `arm_z` above the origin.
fn post_and_arm(arm_z: f64) -> (MechanismBuilder, Vec<flexmech_integrators::builder::NodeId>) {
    let mut b = MechanismBuilder::new();
    let post = b
        .beam(straight([0.0; 3], [0.0, 0.0, 2.0], Vector3::x()))
        .unwrap();
    let arm = b
        .beam(straight([0.0, 0.0, arm_z], [1.0, 0.0, arm_z], Vector3::y()))
        .unwrap();
    b.fix(post.start(), &Dof::ALL).unwrap();
    (b, vec![post.start(), post.end(), arm.start(), arm.end()])
}

/// The screw `drive` (pitch 0.05) from the post's top to the arm's start.
fn drive_screw(
    b: &mut MechanismBuilder,
    n: &[flexmech_integrators::builder::NodeId],
) -> flexmech_integrators::builder::JointId {
    b.joint(JointDef {
        name: "drive".into(),
        map: screw(0.05),
        master: n[1],
        slave: n[2],
        angle: 0.0,
    })
    .unwrap()
}

#[test]
fn handles_number_nodes_and_joints_in_order() {
    let (mut b, n) = post_and_arm(2.0);
    assert_eq!(
        n.iter().map(|x| x.index()).collect::<Vec<_>>(),
        [0, 4, 5, 9]
    );
    let j = drive_screw(&mut b, &n);
    assert_eq!(j.index(), 0);
    b.drive(j, Schedule::new(|t| 2.0 * t)).unwrap();
    b.prescribe(n[3], Dof::Rz, Schedule::constant(0.0)).unwrap();
    let mech = b.build();
    assert_eq!(mech.fixed[0], [true; 6]);
    assert_eq!(mech.joints[0].driven.len(), 1);
    assert!(mech.joints[0].driven[0].is_some());
    assert_eq!((mech.prescribed[0].node, mech.prescribed[0].dof), (9, 5));
    assert_eq!(Dof::from_index(5), Some(Dof::Rz));
    assert_eq!(Dof::from_index(6), None);
}

/// The screw of the statics benchmarks, built through the builder: turning
/// it by ψ raises the arm by c ψ exactly (relation (1)), whatever the load.
#[test]
fn a_driven_screw_built_here_raises_its_arm_by_the_pitch() {
    let (mut b, n) = post_and_arm(2.0);
    let j = drive_screw(&mut b, &n);
    let turns = 0.5;
    b.drive(j, Schedule::new(move |t| t * turns * std::f64::consts::TAU))
        .unwrap();
    b.load(
        n[3],
        Vector3::new(0.0, 0.0, -10.0),
        Vector3::zeros(),
        Schedule::constant(1.0),
    )
    .unwrap();
    let mech = b.build();
    let settings = StaticSettings {
        load_steps: 8,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 8,
    };
    let out = solve_static(&mech, &settings, |_| {}).unwrap();
    let x = &out.state.config.x;
    let psi = turns * std::f64::consts::TAU;
    assert!((out.state.released[0].q[0] - psi).abs() < 1e-12);
    // In the master's frame the slave sits at c ψ along the axis: its
    // distance from the post's top is c ψ to round-off.
    let d = x[n[2].index()] - x[n[1].index()];
    assert!((d.norm() - 0.05 * psi).abs() < 1e-12, "{d:?}");
}

#[test]
fn every_constructor_refuses_what_the_solvers_cannot_use() {
    let mut b = MechanismBuilder::new();
    let mut bad = straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::y());
    bad.section.ei[1] = 0.0;
    assert!(matches!(
        b.beam(bad),
        Err(BuildError::Section {
            beam: 0,
            what: "EI3",
            ..
        })
    ));
    let mut bad = straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::y());
    bad.section.rho_a = f64::NAN;
    assert!(matches!(
        b.beam(bad),
        Err(BuildError::Section { what: "rhoA", .. })
    ));
    assert!(matches!(
        b.beam(straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::x())),
        Err(BuildError::Mesh {
            source: MeshError::ParallelE2,
            ..
        })
    ));
    assert!(matches!(
        b.beam(straight([0.0; 3], [f64::INFINITY, 0.0, 0.0], Vector3::y())),
        Err(BuildError::NotFinite { .. })
    ));
    let mut zero = straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::y());
    zero.elements = 0;
    assert!(matches!(
        b.beam(zero),
        Err(BuildError::Mesh {
            source: MeshError::BadElementCount { .. },
            ..
        })
    ));

    // A handle of another, larger mechanism is not a node of this one.
    let (_, other) = post_and_arm(2.0);
    let beam = b
        .beam(straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::y()))
        .unwrap();
    assert!(matches!(
        b.fix(other[3], &[Dof::Ux]),
        Err(BuildError::UnknownNode { node: 9, count: 5 })
    ));
    assert!(matches!(
        b.load(
            beam.end(),
            Vector3::new(f64::NAN, 0.0, 0.0),
            Vector3::zeros(),
            Schedule::ramp()
        ),
        Err(BuildError::NotFinite { .. })
    ));

    let (mut b, n) = post_and_arm(2.0);
    let joint = |map: Arc<dyn JointMap>, master, slave, angle: f64| JointDef {
        name: "j".into(),
        map,
        master,
        slave,
        angle,
    };
    assert!(matches!(
        b.joint(joint(screw(0.05), n[1], n[1], 0.0)),
        Err(BuildError::SameNode { .. })
    ));
    let slide: Arc<dyn JointMap> = Arc::new(Prismatic {
        slide: Vector3::z(),
    });
    assert!(matches!(
        b.joint(joint(slide.clone(), n[1], n[2], 0.3)),
        Err(BuildError::NoAngle { .. })
    ));
    let p = b.joint(joint(slide, n[1], n[2], 0.0)).unwrap();
    assert!(matches!(
        b.drive(p, Schedule::ramp()),
        Err(BuildError::NoAngle { .. })
    ));
    // Relation (1) at ψ₀ = 2 puts the slave 0.1 above the post's top.
    match b.joint(joint(screw(0.05), n[1], n[2], 2.0)) {
        Err(BuildError::SlaveOff { gap, .. }) => assert!((gap - 0.1).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        b.joint(joint(screw(f64::MAX), n[1], n[2], 2.0)),
        Err(BuildError::NonFiniteRelease { .. })
    ));
    let (mut b, n) = post_and_arm(2.1);
    b.joint(joint(screw(0.05), n[1], n[2], 2.0)).unwrap();
    // Within the placement tolerance of the mechanism's size, not beyond.
    let (mut b2, n2) = post_and_arm(2.1 + 1e-8);
    assert!(matches!(
        b2.joint(joint(screw(0.05), n2[1], n2[2], 2.0)),
        Err(BuildError::SlaveOff { .. })
    ));
    // A joint handle of another mechanism with more joints.
    let (mut c, m) = post_and_arm(2.0);
    let mut third = None;
    for _ in 0..3 {
        third = Some(c.joint(joint(screw(0.0), m[1], m[2], 0.0)).unwrap());
    }
    assert!(matches!(
        b.drive(third.unwrap(), Schedule::ramp()),
        Err(BuildError::UnknownJoint { joint: 2, count: 1 })
    ));
}

/// A clamped 1 m cantilever of `n` two-node elements along x.
fn cantilever(n: usize, rho_a: f64) -> (MechanismBuilder, flexmech_integrators::builder::Beam) {
    let mut b = MechanismBuilder::new();
    let mut def = straight([0.0; 3], [1.0, 0.0, 0.0], Vector3::y());
    def.elements = n;
    def.section.rho_a = rho_a;
    def.section.rho_j = [1e-4 * rho_a; 3];
    let beam = b.beam(def).unwrap();
    b.fix(beam.start(), &Dof::ALL).unwrap();
    (b, beam)
}

fn static_settings() -> StaticSettings {
    StaticSettings {
        load_steps: 1,
        newton: NewtonSettings {
            tolerance: 1e-12,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 4,
    }
}

/// A uniform line load written as a user's load field (consistent nodal
/// forces `q h/2` at each element end) bends the cantilever as linear
/// theory says, `w(x) = q/(24 EI)(x⁴ − 4Lx³ + 6L²x²) + q/GA (Lx − x²/2)`:
/// the tip to round-off (the element's two quadrature errors, the midpoint
/// rule of `M/EI` and the trapezoidal rule of `θ`, cancel there for a
/// uniform load), the other nodes with an error falling as h².
#[test]
fn a_load_field_is_a_line_load_with_the_beam_theorys_deflection() {
    let q = 1e-3; // N/m: w/L ≈ 1.25e-7, geometric nonlinearity (w/L)² ≈ 1e-14
    let (ei, ga) = (ROD.ei[1], ROD.ga[1]);
    let w = |x: f64| {
        q / (24.0 * ei) * (x.powi(4) - 4.0 * x.powi(3) + 6.0 * x * x) + q / ga * (x - x * x / 2.0)
    };
    let tip = w(1.0);
    let worst = |n: usize| {
        let (mut b, beam) = cantilever(n, 0.0);
        let nodes: Vec<usize> = beam.nodes().iter().map(|x| x.index()).collect();
        let h = 1.0 / n as f64;
        let loaded = nodes.clone();
        b.load_field(move |t, out| {
            for pair in loaded.windows(2) {
                for &node in pair {
                    out[6 * node + 2] -= t * q * h / 2.0;
                }
            }
        });
        let mech = b.build();
        let out = solve_static(&mech, &static_settings(), |_| {}).unwrap();
        let deflection = |k: usize| -out.state.config.x[nodes[k]].z;
        assert!(
            (deflection(n) - tip).abs() <= 1e-9 * tip,
            "n = {n}: tip {} against {tip}",
            deflection(n)
        );
        (1..n)
            .map(|k| (deflection(k) - w(k as f64 * h)).abs() / tip)
            .fold(0.0, f64::max)
    };
    let e: Vec<f64> = [4, 8, 16, 32].iter().map(|&n| worst(n)).collect();
    for pair in e.windows(2) {
        let rate = (pair[0] / pair[1]).log2();
        assert!((rate - 2.0).abs() < 0.15, "errors {e:?}: rate {rate}");
    }
}

/// A load field that equals a nodal load gives the same run, bit for bit, in
/// every scheme; `run_until` stops after the step its observer breaks on.
#[test]
fn load_fields_enter_every_scheme_like_nodal_loads() {
    use flexmech_core::MassKind;
    use flexmech_integrators::dynamics::{Integrator, Motion, Simulation};
    use std::ops::ControlFlow;

    let settings = crate::common::settings(1e-3, 0.02, 1e-10, 20, 4, MassKind::Consistent);
    let force = |t: f64| 5.0 * (40.0 * t).sin();
    for integrator in [
        Integrator::Newmark,
        Integrator::GeneralizedAlpha { rho_inf: 0.8 },
        Integrator::Momentum,
        Integrator::EnergyMomentum,
        Integrator::EnergyMomentumPaper,
    ] {
        let run = |field: bool| {
            let (mut b, beam) = cantilever(6, 1.0);
            let tip = beam.end();
            if field {
                let n = tip.index();
                b.load_field(move |t, out| out[6 * n + 2] += force(t));
            } else {
                b.load(tip, Vector3::z(), Vector3::zeros(), Schedule::new(force))
                    .unwrap();
            }
            let mech = b.build();
            let rest = Motion::rest(mech.mesh.node_count());
            let mut sim = Simulation::new(&mech, integrator, &settings, &rest).unwrap();
            let mut records = Vec::new();
            let stopped = sim
                .run_until(|r, s| {
                    records.push(r.positions.clone());
                    if r.positions[tip.index()][2] > 1e-5 {
                        ControlFlow::Break(s.time())
                    } else {
                        ControlFlow::Continue(())
                    }
                })
                .unwrap();
            (records, stopped)
        };
        let (a, stop_a) = run(false);
        let (b, stop_b) = run(true);
        assert_eq!(a, b, "{integrator:?}");
        // The tip rises past 1e-5 m before t_end; the run stops there.
        let t = stop_a.expect("the observer breaks");
        assert_eq!(stop_a, stop_b);
        assert!(t < settings.t_end && a.len() == (t / settings.dt).round() as usize);
    }
}
