//! Follower loads (turning with their node): the load stiffness against
//! automatic differentiation, Newton as fast with it as with dead loads, and a
//! cantilever under a follower tip force against the elastica — integrated
//! here from its own equations — far from where the same force held dead
//! takes it.

use flexmech_core::rotation::{exp, skew};
use flexmech_integrators::builder::{BeamDef, BeamShape, Dof, MechanismBuilder, SectionValues};
use flexmech_integrators::{solve_static, NewtonSettings, Schedule, StaticSettings};
use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::DualSVec64;

#[test]
fn the_load_stiffness_is_the_ad_derivative_of_the_turning_load() {
    // −f(η) = −exp(η̂) R f₀ under a spatial spin η of R; its derivative at
    // η = 0 by three-lane forward AD against (R f₀)^, which the assembly adds.
    type D = DualSVec64<3>;
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    for (k, (axis, f0)) in [
        (Vector3::new(0.3, -1.2, 0.8), Vector3::new(1.0, 2.0, -0.5)),
        (Vector3::new(2.9, 0.1, -0.4), Vector3::new(-3.0, 0.2, 0.7)),
        (Vector3::new(-0.01, 0.02, 3.1), Vector3::new(0.0, 0.0, 1.0)),
    ]
    .into_iter()
    .enumerate()
    {
        let r: Matrix3<f64> = exp(&axis);
        let eta = Vector3::new(seed(0), seed(1), seed(2));
        let turned = exp(&eta) * r.map(D::from_re) * f0.map(D::from_re);
        let mut ad = Matrix3::zeros();
        for row in 0..3 {
            let eps = turned[row].eps.unwrap_generic(Const::<3>, U1);
            ad.set_row(row, &(-eps.transpose()));
        }
        let closed = skew(&(r * f0));
        assert!((ad - closed).amax() < 1e-14, "case {k}: {ad} vs {closed}");
    }
}

const EI: f64 = 1.0;
const L: f64 = 1.0;

fn cantilever(follower: bool, p: f64) -> (flexmech_integrators::Mechanism, usize) {
    let section = SectionValues {
        ea: 1e5,
        ga: [1e5; 2],
        gj: 1.0,
        ei: [EI; 2],
        rho_a: 0.0,
        rho_j: [0.0; 3],
    };
    let mut b = MechanismBuilder::new();
    let beam = b
        .beam(BeamDef {
            shape: BeamShape::Straight {
                start: Vector3::zeros(),
                end: Vector3::new(L, 0.0, 0.0),
                e2: Vector3::y(),
            },
            elements: 40,
            nodes_per_element: 2,
            section,
        })
        .unwrap();
    b.fix(beam.start(), &Dof::ALL).unwrap();
    let force = Vector3::new(0.0, p, 0.0);
    if follower {
        b.follower_load(beam.end(), force, Vector3::zeros(), Schedule::ramp())
    } else {
        b.load(beam.end(), force, Vector3::zeros(), Schedule::ramp())
    }
    .unwrap();
    (b.build(), beam.end().index())
}

/// The tip of the inextensible, unshearable elastica under a tip force `p`
/// that stays normal to the tip: with `φ = θ − θ_L`, `EI φ″ = −p cos φ`,
/// `φ(L) = φ′(L) = 0` — an initial value problem integrated backwards from
/// the tip (RK4), then `x′ = cos θ`, `y′ = sin θ` from the root.
fn elastica_tip(p: f64) -> (f64, f64) {
    let n = 20_000;
    let h = L / n as f64;
    let rhs = |phi: f64, dphi: f64| (dphi, -p / EI * phi.cos());
    // Backwards from s = L: store φ(s) on the grid.
    let mut phi = vec![0.0; n + 1];
    let (mut y, mut dy) = (0.0, 0.0);
    for k in (0..n).rev() {
        let (k1a, k1b) = rhs(y, dy);
        let (k2a, k2b) = rhs(y - 0.5 * h * k1a, dy - 0.5 * h * k1b);
        let (k3a, k3b) = rhs(y - 0.5 * h * k2a, dy - 0.5 * h * k2b);
        let (k4a, k4b) = rhs(y - h * k3a, dy - h * k3b);
        y -= h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a);
        dy -= h / 6.0 * (k1b + 2.0 * k2b + 2.0 * k3b + k4b);
        phi[k] = y;
    }
    let theta_l = -phi[0];
    // Simpson's rule for the position.
    let (mut x, mut yy) = (0.0, 0.0);
    for k in (0..n).step_by(2) {
        let th = |i: usize| phi[i] + theta_l;
        x += h / 3.0 * (th(k).cos() + 4.0 * th(k + 1).cos() + th(k + 2).cos());
        yy += h / 3.0 * (th(k).sin() + 4.0 * th(k + 1).sin() + th(k + 2).sin());
    }
    (x, yy)
}

#[test]
fn a_follower_tip_force_bends_the_cantilever_as_the_elastica_says() {
    let p = 3.0; // p L²/EI
    let settings = StaticSettings {
        load_steps: 6,
        newton: NewtonSettings {
            tolerance: 1e-10,
            max_iterations: 30,
            modified: false,
            exact_tangent: false,
        },
        max_halvings: 4,
    };
    let (expected_x, expected_y) = elastica_tip(p);
    let tip = |follower: bool| {
        let (mech, end) = cantilever(follower, p);
        let mut iterations = 0;
        let out = solve_static(&mech, &settings, |r| iterations += r.iterations).unwrap();
        (out.config.x[end], iterations)
    };
    let (follower, follower_iterations) = tip(true);
    let (dead, dead_iterations) = tip(false);
    let err = ((follower.x - expected_x).powi(2) + (follower.y - expected_y).powi(2)).sqrt();
    eprintln!(
        "follower tip ({:.5}, {:.5}), elastica ({expected_x:.5}, {expected_y:.5}), error {err:.2e}; \
         dead-force tip ({:.5}, {:.5})",
        follower.x, follower.y, dead.x, dead.y
    );
    // 40 two-node elements: the discretisation error of the tip, O(h²)
    // ≈ (1/40)² ≈ 6e-4 times the curvature's size; extension and shear
    // p/EA ≈ 3e-5.
    assert!(err < 1e-3 * L, "follower tip off the elastica by {err:e}");
    // Newton with the exact load stiffness needs no more iterations than
    // with the dead force (without it, it would converge only linearly).
    eprintln!("Newton iterations: follower {follower_iterations}, dead {dead_iterations}");
    assert!(
        follower_iterations as f64 <= 1.25 * dead_iterations as f64,
        "follower {follower_iterations} iterations, dead {dead_iterations}"
    );
    let apart = ((follower.x - dead.x).powi(2) + (follower.y - dead.y).powi(2)).sqrt();
    assert!(
        apart > 0.05 * L,
        "follower and dead tips only {apart} apart"
    );
}
