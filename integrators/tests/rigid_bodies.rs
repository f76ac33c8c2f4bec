//! Rigid bodies and point masses in the solvers: a point mass on a massless
//! bar oscillates at `√(k/m)`; a spinning free beam carrying an offset body
//! starts with the kinetic energy of mechanics (`½m|v + ω×c|² + ½ω·J_cω` for
//! the body) and the conserving schemes keep its momenta (and the
//! energy–momentum scheme its energy) with the body on board.

use flexmech_core::MassKind;
use flexmech_integrators::builder::{BeamDef, BeamShape, MechanismBuilder, SectionValues};
use flexmech_integrators::dynamics::simulation::{Integrator, Simulation};
use flexmech_integrators::dynamics::{DynamicSettings, Motion};
use flexmech_integrators::NewtonSettings;
use nalgebra::{Matrix3, Vector3};

fn settings(dt: f64, t_end: f64) -> DynamicSettings {
    DynamicSettings {
        dt,
        t_end,
        newton: NewtonSettings {
            tolerance: 1e-11,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 0,
        mass: MassKind::Consistent,
    }
}

#[test]
fn a_point_mass_on_a_massless_bar_oscillates_at_sqrt_k_over_m() {
    // EA = 400, L = 1, M = 4: ω = 10. ωΔt = 0.05: the trapezoidal rule's
    // phase error over ωt = 10 is ≈ 10 (ωΔt)²/12 = 2e-3 of the amplitude.
    let massless = SectionValues {
        ea: 400.0,
        ga: [300.0; 2],
        gj: 10.0,
        ei: [10.0; 2],
        rho_a: 0.0,
        rho_j: [0.0; 3],
    };
    let mut b = MechanismBuilder::new();
    let bar = b
        .beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::x(),
                e2: Vector3::y(),
            },
            elements: 1,
            nodes_per_element: 2,
            section: massless,
        })
        .unwrap();
    b.fix(bar.start(), &flexmech_integrators::builder::Dof::ALL)
        .unwrap();
    b.rigid_body(
        "m".into(),
        bar.end(),
        4.0,
        Matrix3::identity() * 0.01,
        Vector3::zeros(),
    )
    .unwrap();
    let mech = b.build();
    let mut motion = Motion::rest(2);
    let v0 = 0.5;
    motion.v[1] = Vector3::new(v0, 0.0, 0.0);
    for integrator in [
        Integrator::Newmark,
        Integrator::GeneralizedAlpha { rho_inf: 0.9 },
        Integrator::Momentum,
        Integrator::EnergyMomentum,
    ] {
        let mut sim = Simulation::new(&mech, integrator, &settings(0.005, 1.0), &motion).unwrap();
        let mut worst: f64 = 0.0;
        sim.run(|r| {
            let x = r.positions[1][0] - 1.0;
            worst = worst.max((x - v0 / 10.0 * (10.0 * r.time).sin()).abs());
        })
        .unwrap();
        assert!(worst < 3e-3 * v0 / 10.0, "{integrator:?}: {worst:e}");
    }
}

#[test]
fn a_spinning_beam_with_an_offset_body_keeps_its_momenta() {
    let rod = SectionValues {
        ea: 1e4,
        ga: [4e3; 2],
        gj: 50.0,
        ei: [80.0; 2],
        rho_a: 1.0,
        rho_j: [0.2, 0.1, 0.1],
    };
    let beam = |b: &mut MechanismBuilder| {
        b.beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::new(4.0, 0.0, 0.0),
                e2: Vector3::y(),
            },
            elements: 4,
            nodes_per_element: 2,
            section: rod,
        })
        .unwrap()
    };
    let (m, c) = (1.5, Vector3::new(0.3, -0.4, 0.2));
    let jc = Matrix3::new(0.2, 0.01, 0.0, 0.01, 0.15, 0.02, 0.0, 0.02, 0.1);
    let mut with = MechanismBuilder::new();
    let carrier = beam(&mut with).end();
    with.rigid_body("hub".into(), carrier, m, jc, c).unwrap();
    let with = with.build();
    let mut without = MechanismBuilder::new();
    beam(&mut without);
    let without = without.build();
    let om = Vector3::new(0.2, 0.5, 1.0);
    let v0 = Vector3::new(0.1, 0.0, -0.2);
    let motion = |nodes: usize, x: &[Vector3<f64>]| Motion {
        v: (0..nodes).map(|i| v0 + om.cross(&x[i])).collect(),
        w: vec![om; nodes],
        joint_rates: Vec::new(),
    };
    let energy0 = |mech: &flexmech_integrators::Mechanism| {
        let n = mech.mesh.node_count();
        let sim = Simulation::new(
            mech,
            Integrator::Momentum,
            &settings(0.02, 1.0),
            &motion(n, &mech.mesh.positions),
        )
        .unwrap();
        sim.record().energy.kinetic
    };
    // The body's own kinetic energy: its centre of mass moves with the
    // carrier's rigid velocity field, v_c = v₀ + ω × (x_tip + c).
    let v_c = v0 + om.cross(&(Vector3::new(4.0, 0.0, 0.0) + c));
    let body = 0.5 * m * v_c.norm_squared() + 0.5 * om.dot(&(jc * om));
    let (e_with, e_without) = (energy0(&with), energy0(&without));
    assert!(
        (e_with - e_without - body).abs() < 1e-12 * e_with,
        "{e_with} − {e_without} against {body}"
    );
    let n = with.mesh.node_count();
    assert_eq!(n, 6, "the body's centre of mass is a node of its own");
    for integrator in [Integrator::Momentum, Integrator::EnergyMomentum] {
        let mut sim = Simulation::new(
            &with,
            integrator,
            &settings(0.02, 2.0),
            &motion(n, &with.mesh.positions),
        )
        .unwrap();
        let r0 = sim.record();
        let (l0, j0) = (
            Vector3::from(r0.momentum_linear),
            Vector3::from(r0.momentum_angular),
        );
        let e0 = r0.energy.kinetic + r0.energy.strain;
        sim.run(|r| {
            let (l, j) = (
                Vector3::from(r.momentum_linear),
                Vector3::from(r.momentum_angular),
            );
            assert!(
                (l - l0).norm() < 1e-10 * l0.norm(),
                "{integrator:?}: L {l:?}"
            );
            assert!(
                (j - j0).norm() < 1e-10 * j0.norm(),
                "{integrator:?}: J {j:?}"
            );
            if integrator == Integrator::EnergyMomentum {
                let e = r.energy.kinetic + r.energy.strain;
                assert!((e - e0).abs() < 1e-9 * e0, "energy {e} vs {e0}");
            }
        })
        .unwrap();
    }
}

#[test]
fn unphysical_bodies_are_refused() {
    let mut b = MechanismBuilder::new();
    let beam = b
        .beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::x(),
                e2: Vector3::y(),
            },
            elements: 2,
            nodes_per_element: 2,
            section: SectionValues {
                ea: 1.0,
                ga: [1.0; 2],
                gj: 1.0,
                ei: [1.0; 2],
                rho_a: 1.0,
                rho_j: [0.0; 3],
            },
        })
        .unwrap();
    let z = Vector3::zeros();
    let cases = [
        (-1.0, Matrix3::zeros(), "mass must be >= 0"),
        (f64::NAN, Matrix3::zeros(), "mass"),
        (
            1.0,
            Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 3.0)),
            "J₁ ≤ J₂ + J₃",
        ),
        (
            1.0,
            Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)),
            ">= 0",
        ),
    ];
    for (m, j, words) in cases {
        let e = b.rigid_body("x".into(), beam.end(), m, j, z).unwrap_err();
        assert!(e.to_string().contains(words), "{e}");
    }
    // A refused offset body leaves no node behind.
    let nodes = b.clone().build().mesh.node_count();
    let bad = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 3.0));
    assert!(b
        .rigid_body("x".into(), beam.end(), 1.0, bad, Vector3::x())
        .is_err());
    assert_eq!(b.build().mesh.node_count(), nodes);
}
