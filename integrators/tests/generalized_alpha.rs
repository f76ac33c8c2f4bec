//! The generalized-α scheme against theory: on a linear oscillator (an
//! axially vibrating bar of one element, clamped at one end — the Reissner
//! axial strain is exactly linear in the tip displacement) its displacements
//! are Chung & Hulbert's recurrence (1993) to round-off, converge at order 2
//! to the analytic `x = (v₀/ω) sin ωt`, conserve the energy with `ρ∞ = 1` and
//! lose it period after period with `ρ∞ < 1` (monotonically in the scheme's
//! own norm, not step by step in `T + Π`); on a nonlinear spinning beam with
//! `ρ∞ = 1` it is the trapezoidal rule.

use flexmech_core::{MassKind, Mesh, Section};
use flexmech_integrators::dynamics::simulation::{Integrator, Simulation};
use flexmech_integrators::dynamics::{DynamicSettings, Motion};
use flexmech_integrators::{Mechanism, NewtonSettings};
use nalgebra::Vector3;

/// Bar of length 1, `EA = 100`, `ρA = 3`: with one consistent-mass element
/// the tip carries `m = ρA L/3 = 1` on `k = EA/L = 100`, so `ω = 10`.
const OMEGA: f64 = 10.0;
/// Initial tip velocity (axial): an amplitude of 1 % strain, large enough
/// for the residual to stand well above round-off of positions near 1.
const V0: f64 = 0.1;
/// Newton's tolerance: the scaled residual, far below the errors compared
/// and above the round-off floor of the smallest step.
const NEWTON_TOL: f64 = 1e-10;

fn oscillator(dt: f64, t_end: f64) -> (Mechanism, Motion, DynamicSettings) {
    let sec = Section::new([100.0, 80.0, 80.0], [5.0, 4.0, 4.0], 3.0, [0.2, 0.1, 0.1]);
    let mut mesh = Mesh::default();
    mesh.add_straight_beam(
        Vector3::zeros(),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::y(),
        1,
        2,
        sec,
    )
    .unwrap();
    let mut mech = Mechanism::new(mesh);
    mech.fixed[0] = [true; 6];
    let mut motion = Motion::rest(2);
    motion.v[1] = Vector3::new(V0, 0.0, 0.0);
    let settings = DynamicSettings {
        dt,
        t_end,
        newton: NewtonSettings {
            tolerance: NEWTON_TOL,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 0,
        mass: MassKind::Consistent,
    };
    (mech, motion, settings)
}

/// Tip displacements, times and total energies of a run.
fn run(integrator: Integrator, dt: f64, t_end: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mech, motion, settings) = oscillator(dt, t_end);
    let mut sim = Simulation::new(&mech, integrator, &settings, &motion).unwrap();
    let (mut x, mut t, mut e) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |r: &flexmech_integrators::StepRecord| {
        x.push(r.positions[1][0] - 1.0);
        t.push(r.time);
        e.push(r.energy.kinetic + r.energy.strain);
    };
    push(&sim.record());
    sim.run(&mut push).unwrap();
    (x, t, e)
}

/// Chung & Hulbert's generalized-α for `ẍ + ω²x = 0` in its published
/// form: `a_{n+1−αm} = −ω² d_{n+1−αf}` with Newmark's updates and the
/// coefficients of their eq. 25 (`αm = (2ρ∞−1)/(ρ∞+1)`, `αf = ρ∞/(ρ∞+1)`).
fn chung_hulbert(rho: f64, dt: f64, steps: usize) -> Vec<f64> {
    let am = (2.0 * rho - 1.0) / (rho + 1.0);
    let af = rho / (rho + 1.0);
    let gamma = 0.5 - am + af;
    let beta = 0.25 * (1.0 - am + af).powi(2);
    let w2 = OMEGA * OMEGA;
    let (mut d, mut v, mut a) = (0.0, V0, 0.0);
    let mut out = vec![d];
    for _ in 0..steps {
        // (1−αm)a₁ + αm a = −ω²((1−αf)d₁ + αf d), d₁ = d + Δt v + Δt²((½−β)a + β a₁)
        let pred = d + dt * v + dt * dt * (0.5 - beta) * a;
        let a1 = (-w2 * ((1.0 - af) * pred + af * d) - am * a)
            / ((1.0 - am) + w2 * (1.0 - af) * beta * dt * dt);
        let d1 = pred + dt * dt * beta * a1;
        v += dt * ((1.0 - gamma) * a + gamma * a1);
        a = a1;
        d = d1;
        out.push(d);
    }
    out
}

#[test]
fn displacements_are_chung_and_hulberts_recurrence() {
    for rho in [0.0, 0.5, 0.9, 1.0] {
        // ωΔt = 0.5 (resolved) and 20 (far beyond the mesh's resolution).
        for (dt, steps) in [(0.05, 60), (2.0, 12)] {
            let (x, _, _) = run(
                Integrator::GeneralizedAlpha { rho_inf: rho },
                dt,
                dt * steps as f64,
            );
            let reference = chung_hulbert(rho, dt, steps);
            assert_eq!(x.len(), reference.len());
            let amplitude = V0 / OMEGA;
            for (n, (a, b)) in x.iter().zip(&reference).enumerate() {
                assert!(
                    (a - b).abs() < 1e-8 * amplitude,
                    "rho_inf {rho}, dt {dt}, step {n}: {a:e} against {b:e}"
                );
            }
        }
    }
}

#[test]
fn converges_at_order_two_to_the_analytic_oscillation() {
    for rho in [0.0, 0.5, 0.9] {
        let errors: Vec<f64> = [0.02, 0.01, 0.005]
            .iter()
            .map(|&dt| {
                let (x, t, _) = run(Integrator::GeneralizedAlpha { rho_inf: rho }, dt, 1.0);
                x.iter()
                    .zip(&t)
                    .map(|(x, t)| (x - V0 / OMEGA * (OMEGA * t).sin()).abs())
                    .fold(0.0, f64::max)
            })
            .collect();
        for w in errors.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!(
                (order - 2.0).abs() < 0.15,
                "rho_inf {rho}: errors {errors:?}, order {order}"
            );
        }
    }
}

#[test]
fn energy_is_kept_with_rho_one_and_lost_period_by_period_below() {
    let (_, _, e) = run(Integrator::GeneralizedAlpha { rho_inf: 1.0 }, 0.1, 5.0);
    let e0 = e[0];
    assert!(e.iter().all(|v| (v - e0).abs() < 1e-9 * e0), "{e:?}");
    for rho in [0.0, 0.5, 0.9] {
        // ωΔt = 1: the largest energy of each period (2π/ω ≈ 6.3 steps,
        // windows of 7) falls from period to period.
        let (_, _, e) = run(Integrator::GeneralizedAlpha { rho_inf: rho }, 0.1, 20.0);
        let peaks: Vec<f64> = e
            .chunks(7)
            .map(|c| c.iter().cloned().fold(0.0, f64::max))
            .collect();
        for w in peaks.windows(2) {
            assert!(w[1] < w[0], "rho_inf {rho}: {peaks:?}");
        }
    }
}

#[test]
fn rho_one_is_the_trapezoidal_rule_on_a_spinning_beam() {
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
        6,
        2,
        sec,
    )
    .unwrap();
    let mech = Mechanism::new(mesh);
    let om = Vector3::new(0.3, 0.5, 1.0);
    let motion = Motion {
        v: mech.mesh.positions.iter().map(|x| om.cross(x)).collect(),
        w: vec![om; mech.mesh.node_count()],
        joint_rates: Vec::new(),
    };
    let (_, _, settings) = oscillator(0.05, 1.0);
    let positions = |integrator| {
        let mut sim = Simulation::new(&mech, integrator, &settings, &motion).unwrap();
        sim.run(|_| {}).unwrap();
        (sim.state().config.x.clone(), sim.velocities().1.to_vec())
    };
    let (x_n, w_n) = positions(Integrator::Newmark);
    let (x_g, w_g) = positions(Integrator::GeneralizedAlpha { rho_inf: 1.0 });
    for i in 0..x_n.len() {
        assert!((x_n[i] - x_g[i]).norm() < 1e-12, "node {i}");
        assert!((w_n[i] - w_g[i]).norm() < 1e-12, "node {i}");
    }
}

#[test]
fn rho_inf_outside_zero_one_is_refused() {
    let (mech, motion, settings) = oscillator(0.1, 1.0);
    for rho in [-0.1, 1.5, f64::NAN] {
        let err = Simulation::new(
            &mech,
            Integrator::GeneralizedAlpha { rho_inf: rho },
            &settings,
            &motion,
        )
        .err()
        .expect("refused");
        assert!(err.to_string().contains("rho_inf"), "{err}");
    }
}
