//! Kelvin–Voigt structural damping (resultants `C(ε + η ε̇)`) against the
//! damped oscillator: a point mass on a massless bar, `m ẍ + η k ẋ + k x = 0`,
//! so `x = (v₀/ω_d) e^{−ζωt} sin ω_d t` with `ζ = η ω/2`. The step's strain
//! rate `Δε/Δt` makes the scheme first order in the damping; the energy
//! the damping takes is reported and closes the balance.

use flexmech_core::MassKind;
use flexmech_integrators::builder::{BeamDef, BeamShape, Dof, MechanismBuilder, SectionValues};
use flexmech_integrators::dynamics::simulation::{Integrator, Simulation};
use flexmech_integrators::dynamics::{DynamicSettings, Motion};
use flexmech_integrators::{Mechanism, NewtonSettings, Schedule};
use nalgebra::{Matrix3, Vector3};

/// EA = 400, L = 1, M = 4: ω = 10.
const OMEGA: f64 = 10.0;
const ETA: f64 = 0.01;
const V0: f64 = 0.5;

fn oscillator(eta: f64) -> Mechanism {
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
    b.fix(bar.start(), &Dof::ALL).unwrap();
    b.rigid_body(
        "m".into(),
        bar.end(),
        4.0,
        Matrix3::identity() * 0.01,
        Vector3::zeros(),
    )
    .unwrap();
    b.damping(&bar, eta).unwrap();
    b.build()
}

fn settings(dt: f64) -> DynamicSettings {
    DynamicSettings {
        dt,
        t_end: 1.0,
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

/// Largest deviation from the damped oscillation over 1 s, and the largest
/// change of the total energy (kinetic + strain + dissipated) relative to
/// the initial energy.
fn run(integrator: Integrator, dt: f64) -> (f64, f64) {
    let mech = oscillator(ETA);
    let mut motion = Motion::rest(2);
    motion.v[1] = Vector3::new(V0, 0.0, 0.0);
    let mut sim = Simulation::new(&mech, integrator, &settings(dt), &motion).unwrap();
    let zeta = ETA * OMEGA / 2.0;
    let wd = OMEGA * (1.0 - zeta * zeta).sqrt();
    let e0 = sim.record().energy.total;
    let (mut worst, mut drift, mut dissipated) = (0.0f64, 0.0f64, 0.0);
    sim.run(|r| {
        let x = r.positions[1][0] - 1.0;
        let exact = V0 / wd * (-zeta * OMEGA * r.time).exp() * (wd * r.time).sin();
        worst = worst.max((x - exact).abs());
        drift = drift.max((r.energy.total - e0).abs() / e0);
        dissipated = r.energy.dissipated;
    })
    .unwrap();
    // Most of the energy is gone after 1 s (e^{−2ζωt} = e^{−1}).
    assert!(
        dissipated > 0.6 * e0,
        "{integrator:?}: dissipated {dissipated}"
    );
    (worst, drift)
}

#[test]
fn a_damped_bar_decays_as_the_damped_oscillator_at_first_order() {
    for integrator in [
        Integrator::Newmark,
        Integrator::GeneralizedAlpha { rho_inf: 0.8 },
    ] {
        let errors: Vec<(f64, f64)> = [0.004, 0.002, 0.001]
            .iter()
            .map(|&dt| run(integrator, dt))
            .collect();
        eprintln!("{integrator:?}: (error, energy drift) {errors:?}");
        for w in errors.windows(2) {
            let order = (w[0].0 / w[1].0).log2();
            assert!(order > 0.8, "{integrator:?}: order {order} ({errors:?})");
        }
        let amplitude = V0 / OMEGA;
        assert!(errors[2].0 < 5e-3 * amplitude, "{errors:?}");
        // Kinetic + strain + dissipated energy: kept to the scheme's O(Δt).
        assert!(errors[2].1 < 5e-3, "{errors:?}");
    }
}

#[test]
fn the_midpoint_schemes_refuse_damping_and_zero_damping_changes_nothing() {
    let mech = oscillator(ETA);
    let motion = Motion::rest(2);
    for integrator in [Integrator::Momentum, Integrator::EnergyMomentum] {
        let e = Simulation::new(&mech, integrator, &settings(0.01), &motion)
            .err()
            .expect("refused");
        assert!(e.to_string().contains("damping"), "{e}");
    }
    // η = 0 is the undamped run, bit for bit.
    let mut motion = Motion::rest(2);
    motion.v[1] = Vector3::new(V0, 0.0, 0.0);
    let end = |mech: &Mechanism| {
        let mut sim = Simulation::new(mech, Integrator::Newmark, &settings(0.01), &motion).unwrap();
        sim.run(|_| {}).unwrap();
        sim.state().config.x[1]
    };
    let mut undamped = oscillator(0.0);
    assert_eq!(end(&undamped), {
        undamped.damping.clear();
        end(&undamped)
    });
}

/// A 2 m cantilever of `elements` elements of `nodes` nodes (16 nodes'
/// worth), damped with `η = 0.01`, under a sudden tip force where `loaded`
/// (the yardstick of `flexmech bench`).
fn damped_cantilever(nodes: usize, loaded: bool) -> Mechanism {
    let section = SectionValues {
        ea: 1e6,
        ga: [1e6; 2],
        gj: 1e3,
        ei: [1e3; 2],
        rho_a: 1.0,
        rho_j: [1e-3, 5e-4, 5e-4],
    };
    let mut b = MechanismBuilder::new();
    let beam = b
        .beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::new(2.0, 0.0, 0.0),
                e2: Vector3::y(),
            },
            elements: 16 / (nodes - 1),
            nodes_per_element: nodes,
            section,
        })
        .unwrap();
    b.fix(beam.start(), &Dof::ALL).unwrap();
    if loaded {
        let force = Vector3::new(0.0, 0.0, 50.0);
        b.load(beam.end(), force, Vector3::zeros(), Schedule::constant(1.0))
            .unwrap();
    }
    b.damping(&beam, 0.01).unwrap();
    b.build()
}

/// The damping forces' rounding is `η/Δt` times the elastic forces' (the
/// strains' own, not their change's): counted in the round-off floor, every
/// step of the damped 3-node cantilever converges at its size. (Without it,
/// Newton circled between two iterates at twice the undamped floor and the
/// first step failed after 25 iterations.)
#[test]
fn damped_three_node_elements_converge_at_every_step() {
    let mech = damped_cantilever(3, true);
    assert!(mech.damping_round_off_floor_at(&mech.mesh.positions, 1e-3) > mech.round_off_floor());
    let settings = DynamicSettings {
        t_end: 0.06,
        ..settings(1e-3)
    };
    for integrator in [
        Integrator::Newmark,
        Integrator::GeneralizedAlpha { rho_inf: 0.8 },
    ] {
        let mut sim = Simulation::new(&mech, integrator, &settings, &Motion::rest(17)).unwrap();
        let mut steps = 0;
        sim.run(|_| steps += 1)
            .unwrap_or_else(|e| panic!("{integrator:?}: {e}"));
        assert_eq!(steps, 60, "{integrator:?}");
    }
}

/// The energy the damping takes is the work of its forces in the scheme's
/// own balance (the trapezoidal rule on their values at both ends of the
/// step): a cantilever started by a tip velocity of 1 m/s, all of whose
/// modes ring (the stiffest at `ω Δt ≈ 80`), loses exactly what the record
/// says it dissipated. (`2ψ` of the step's pseudo-potential counted the
/// ringing modes, whose alternating damping forces do no work, as
/// dissipating at every step: 80 times the initial energy in 1 s.)
#[test]
fn the_dissipated_energy_is_what_the_motion_loses() {
    for nodes in [2, 3] {
        let mech = damped_cantilever(nodes, false);
        let mut motion = Motion::rest(17);
        motion.v[16] = Vector3::new(0.0, 0.0, 1.0);
        let settings = DynamicSettings {
            t_end: 0.5,
            newton: NewtonSettings::default(),
            ..settings(5e-3)
        };
        let mut sim = Simulation::new(&mech, Integrator::Newmark, &settings, &motion).unwrap();
        let e0 = sim.record().energy.total;
        let mut last = None;
        sim.run(|r| last = Some(r.energy)).unwrap();
        let e = last.unwrap();
        let lost = e0 - e.kinetic - e.strain;
        assert!(lost > 0.5 * e0, "{nodes}-node: lost {lost} of {e0}");
        assert!(
            (e.dissipated - lost).abs() < 1e-3 * e0,
            "{nodes}-node: dissipated {} where the motion lost {lost} of {e0}",
            e.dissipated
        );
    }
}
