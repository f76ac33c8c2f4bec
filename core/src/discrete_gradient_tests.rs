//! Checks of the energy-consistent force (FORMULATION §4.3): exact energy
//! change for large steps, self-equilibrium about the mid-step
//! configuration, the static exact gradient as the zero-step limit, the
//! rank-one corrections vanishing as `Δt²`, and an AD Jacobian that matches
//! central differences.

use super::*;
use crate::conserving::tests::element;
use crate::rotation::{cayley, exp};
use num_dual::DualSVec64;
use proptest::prelude::*;

/// Energy equality to within round-off of the energies involved.
const ENERGY_TOL: f64 = 1e-11;
/// Self-equilibrium to within round-off of the force's size.
const EQUILIBRIUM_TOL: f64 = 1e-13;

/// A strongly deformed start pose (relative rotation ≈ 0.6 rad) and an end pose
/// `h` times a large step away; also the step's Cayley increments.
fn step(x0: &[Vector3<f64>; 2], h: f64, seed: [f64; 6]) -> (Pose<f64>, Pose<f64>) {
    let start = (
        [
            x0[0] + Vector3::new(0.05, -0.02, 0.1),
            x0[1] + Vector3::new(-0.1, 0.2, 0.05),
        ],
        [
            exp(&Vector3::new(0.3, -0.2, 0.5)),
            exp(&Vector3::new(-0.1, 0.6, 0.2)),
        ],
    );
    let theta = [
        Vector3::new(0.2 + seed[0], 0.1, -0.3 + seed[1]) * h,
        Vector3::new(-0.1, 0.4 + seed[2], 0.2) * h,
    ];
    let end = (
        [
            start.0[0] + Vector3::new(0.1, 0.05 + seed[3], -0.02) * h,
            start.0[1] + Vector3::new(-0.03 + seed[4], 0.1, 0.08 + seed[5]) * h,
        ],
        [
            cayley(&theta[0]) * start.1[0],
            cayley(&theta[1]) * start.1[1],
        ],
    );
    (start, end)
}

fn averaged(e: &BeamElement<2>, s: &Pose<f64>, t: &Pose<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let (n0, m0) = e.resultants(&s.0, &s.1);
    let (n1, m1) = e.resultants(&t.0, &t.1);
    ((n0 + n1) * 0.5, (m0 + m1) * 0.5)
}

fn work(s: &Pose<f64>, t: &Pose<f64>, q: &SVector<f64, 12>) -> f64 {
    (0..2)
        .map(|i| {
            (t.0[i] - s.0[i]).dot(&q.fixed_rows::<3>(6 * i))
                + cayley_inverse(&(t.1[i] * s.1[i].transpose())).dot(&q.fixed_rows::<3>(6 * i + 3))
        })
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]

    /// Σ p·q = Πₙ₊₁ − Πₙ for steps up to ~0.8 rad, and the force is
    /// self-equilibrated about x̄ (momentum conservation).
    #[test]
    fn exact_energy_change_and_equilibrium(
        h in 0.01f64..2.0,
        seed in proptest::array::uniform6(-0.3f64..0.3),
    ) {
        let (e, x0) = element();
        let (s, t) = step(&x0, h, seed);
        let (nb, mb) = averaged(&e, &s, &t);
        let q = e.discrete_gradient_force(&s, &t, &nb, &mb);
        let de = e.energy(&t.0, &t.1) - e.energy(&s.0, &s.1);
        let scale = e.energy(&t.0, &t.1).abs() + e.energy(&s.0, &s.1).abs();
        prop_assert!((work(&s, &t, &q) - de).abs() <= ENERGY_TOL * scale,
            "work {} vs ΔΠ {de}", work(&s, &t, &q));
        let xm = [(s.0[0] + t.0[0]) * 0.5, (s.0[1] + t.0[1]) * 0.5];
        let f = q.fixed_rows::<3>(0) + q.fixed_rows::<3>(6);
        let m = xm[0].cross(&q.fixed_rows::<3>(0).into_owned())
            + q.fixed_rows::<3>(3)
            + xm[1].cross(&q.fixed_rows::<3>(6).into_owned())
            + q.fixed_rows::<3>(9);
        prop_assert!(f.norm() <= EQUILIBRIUM_TOL * q.norm() && m.norm() <= EQUILIBRIUM_TOL * q.norm() * 10.0,
            "f {f}, m {m}");
    }
}

#[test]
fn the_zero_step_limit_is_the_static_exact_gradient() {
    let (e, x0) = element();
    let (s, _) = step(&x0, 1.0, [0.0; 6]);
    let (n, m) = e.resultants(&s.0, &s.1);
    let q = e.discrete_gradient_force(&s, &s, &n, &m);
    let r = e.internal_force(&s.0, &s.1);
    assert!(
        (q - r).norm() <= 1e-12 * r.norm(),
        "difference {} of {}",
        (q - r).norm(),
        r.norm()
    );
}

#[test]
fn the_corrections_vanish_as_the_step_squared() {
    // ‖correction‖/‖q‖ for steps h, h/2, h/4, …: the ratio of successive
    // values tends to 4 (second order).
    let (e, x0) = element();
    let sizes: Vec<f64> = (0..6)
        .map(|k| {
            let h = 0.4 / f64::powi(2.0, k);
            let (s, t) = step(&x0, h, [0.05, -0.1, 0.08, 0.02, -0.03, 0.01]);
            let (nb, mb) = averaged(&e, &s, &t);
            let (q, corr) = e.discrete_gradient_parts(&s, &t, &nb, &mb);
            corr.norm() / q.norm()
        })
        .collect();
    for w in sizes.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "sizes {sizes:?}");
    }
}

#[test]
fn the_corrections_do_not_see_the_rigid_rotation() {
    // A large rigid rotation of the element (0.9 rad in one step) plus a
    // deformation increment of size h: the rank-one corrections stay
    // O(h²) of the force, whatever the rigid part.
    let (e, x0) = element();
    let (s, _) = step(&x0, 1.0, [0.0; 6]);
    let rigid = cayley(&Vector3::new(0.5, -0.6, 0.4));
    let sizes: Vec<f64> = (0..5)
        .map(|k| {
            let h = 0.05 / f64::powi(2.0, k);
            let t = (
                [
                    rigid * s.0[0] + Vector3::new(0.3, 0.1, -0.2) * h,
                    rigid * s.0[1] + Vector3::new(-0.1, 0.2, 0.1) * h,
                ],
                [
                    cayley(&(Vector3::new(0.2, 0.1, -0.3) * h)) * rigid * s.1[0],
                    cayley(&(Vector3::new(-0.1, 0.4, 0.2) * h)) * rigid * s.1[1],
                ],
            );
            let (nb, mb) = averaged(&e, &s, &t);
            let (q, corr) = e.discrete_gradient_parts(&s, &t, &nb, &mb);
            corr.norm() / q.norm()
        })
        .collect();
    assert!(sizes[0] < 1e-3, "sizes {sizes:?}");
    for w in sizes.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "sizes {sizes:?}");
    }
}

#[test]
fn the_force_converges_to_the_static_gradient_at_second_order() {
    // q over a symmetric step about a pose vs the exact gradient there.
    let (e, x0) = element();
    let (mid, _) = step(&x0, 1.0, [0.0; 6]);
    let r = e.internal_force(&mid.0, &mid.1);
    let errors: Vec<f64> = (0..5)
        .map(|k| {
            let h = 0.2 / f64::powi(2.0, k);
            let du = [
                Vector3::new(0.1, -0.2, 0.05) * h,
                Vector3::new(-0.1, 0.1, 0.2) * h,
            ];
            let th = [
                Vector3::new(0.3, 0.1, -0.2) * h,
                Vector3::new(-0.2, 0.4, 0.1) * h,
            ];
            let s = (
                [mid.0[0] - du[0], mid.0[1] - du[1]],
                [exp(&(-th[0])) * mid.1[0], exp(&(-th[1])) * mid.1[1]],
            );
            let t = (
                [mid.0[0] + du[0], mid.0[1] + du[1]],
                [exp(&th[0]) * mid.1[0], exp(&th[1]) * mid.1[1]],
            );
            let (nb, mb) = averaged(&e, &s, &t);
            (e.discrete_gradient_force(&s, &t, &nb, &mb) - r).norm() / r.norm()
        })
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "errors {errors:?}");
    }
}

#[test]
fn differentiable_with_automatic_differentiation() {
    type D = DualSVec64<12>;
    let (e, x0) = element();
    let (s, t) = step(&x0, 0.3, [0.1, 0.0, -0.1, 0.05, 0.0, 0.02]);
    let f = |eta: &SVector<f64, 12>| {
        let tt = (
            [
                t.0[0] + eta.fixed_rows::<3>(0),
                t.0[1] + eta.fixed_rows::<3>(6),
            ],
            [
                exp(&eta.fixed_rows::<3>(3).into_owned()) * t.1[0],
                exp(&eta.fixed_rows::<3>(9).into_owned()) * t.1[1],
            ],
        );
        let (nb, mb) = averaged(&e, &s, &tt);
        e.discrete_gradient_force(&s, &tt, &nb, &mb)
    };
    let seed = |k: usize| D::from_re(0.0).derivative(k);
    let v = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
    let sd = (
        s.0.map(|x| x.map(D::from_re)),
        s.1.map(|r| r.map(D::from_re)),
    );
    let td = (
        [t.0[0].map(D::from_re) + v(0), t.0[1].map(D::from_re) + v(6)],
        [
            exp(&v(3)) * t.1[0].map(D::from_re),
            exp(&v(9)) * t.1[1].map(D::from_re),
        ],
    );
    let (n0, m0) = e.resultants(&s.0, &s.1);
    let (n1, m1) = e.resultants(&td.0, &td.1);
    let half = D::from_re(0.5);
    let q = e.discrete_gradient_force(
        &sd,
        &td,
        &((n0.map(D::from_re) + n1) * half),
        &((m0.map(D::from_re) + m1) * half),
    );
    let h = 1e-6;
    for j in 0..12 {
        let mut ep = SVector::<f64, 12>::zeros();
        ep[j] = h;
        let fd = (f(&ep) - f(&(-ep))) / (2.0 * h);
        let ad: SVector<f64, 12> = SVector::from_fn(|i, _| {
            q[i].eps.unwrap_generic(nalgebra::Const::<12>, nalgebra::U1)[j]
        });
        assert!(
            (fd - ad).norm() <= 1e-6 * ad.norm().max(1.0),
            "column {j}: {} vs {}",
            fd,
            ad
        );
    }
}
