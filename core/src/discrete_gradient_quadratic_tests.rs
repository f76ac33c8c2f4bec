//! Checks of the 3-node energy-consistent force (FORMULATION §4.3): exact
//! energy change for large steps, self-equilibrium about the mid-step
//! configuration, the static exact gradient (AD) as the zero-step limit,
//! second-order convergence to it, small corrections whatever the rigid
//! rotation, the closed-form `∂(Hᵀw)/∂ψ` against AD, and an AD Jacobian of
//! the force against central differences.

use super::*;
use crate::rotation::{cayley, exp};
use crate::section::Section;
use num_dual::DualSVec64;
use proptest::prelude::*;

/// Energy equality to within round-off of the energies involved.
const ENERGY_TOL: f64 = 1e-11;
/// Self-equilibrium to within round-off of the force's size.
const EQUILIBRIUM_TOL: f64 = 1e-12;

/// A curved 3-node element (a quarter of an arc of radius 1.5, tilted).
fn element() -> BeamElement<3> {
    let sec = Section::new(
        [2.0e4, 8.0e3, 9.0e3],
        [30.0, 45.0, 60.0],
        1.0,
        [0.2, 0.1, 0.1],
    );
    let tilt = exp(&Vector3::new(0.3, -0.2, 0.1));
    let r = 1.5;
    let x0: [Vector3<f64>; 3] = std::array::from_fn(|i| {
        let a = 0.4 * i as f64;
        tilt * Vector3::new(r * a.sin(), r * (1.0 - a.cos()), 0.0)
    });
    let l0: [Matrix3<f64>; 3] = std::array::from_fn(|i| {
        let a = 0.4 * i as f64;
        let t = Vector3::new(a.cos(), a.sin(), 0.0);
        let n = Vector3::z();
        tilt * Matrix3::from_columns(&[t, n.cross(&t), n])
    });
    BeamElement::new([0, 1, 2], sec, 0.8 * r, &x0, l0)
}

/// A deformed start pose and an end pose `h` times a large step away, plus
/// a rigid rotation `rigid` of the whole element.
fn step(
    e: &BeamElement<3>,
    h: f64,
    seed: [f64; 6],
    rigid: &Matrix3<f64>,
) -> (Pose3<f64>, Pose3<f64>) {
    let x0: [Vector3<f64>; 3] = std::array::from_fn(|i| {
        let a = 0.4 * i as f64;
        let tilt = exp(&Vector3::new(0.3, -0.2, 0.1));
        tilt * Vector3::new(1.5 * a.sin(), 1.5 * (1.0 - a.cos()), 0.0)
    });
    let _ = e;
    let start: Pose3<f64> = (
        [
            x0[0] + Vector3::new(0.05, -0.02, 0.1),
            x0[1] + Vector3::new(-0.03, 0.04, 0.02),
            x0[2] + Vector3::new(-0.1, 0.2, 0.05),
        ],
        [
            exp(&Vector3::new(0.3, -0.2, 0.5)),
            exp(&Vector3::new(0.1, 0.2, 0.3)),
            exp(&Vector3::new(-0.1, 0.6, 0.2)),
        ],
    );
    let theta = [
        Vector3::new(0.2 + seed[0], 0.1, -0.3) * h,
        Vector3::new(0.05, -0.1 + seed[1], 0.1) * h,
        Vector3::new(-0.1, 0.4 + seed[2], 0.2) * h,
    ];
    let u = [
        Vector3::new(0.1, 0.05 + seed[3], -0.02) * h,
        Vector3::new(0.02, -0.03, 0.05 + seed[4]) * h,
        Vector3::new(-0.03 + seed[5], 0.1, 0.08) * h,
    ];
    let end: Pose3<f64> = (
        std::array::from_fn(|i| rigid * (start.0[i] + u[i])),
        std::array::from_fn(|i| rigid * cayley(&theta[i]) * start.1[i]),
    );
    (start, end)
}

fn work(s: &Pose3<f64>, t: &Pose3<f64>, q: &SVector<f64, 18>) -> f64 {
    (0..3)
        .map(|i| {
            (t.0[i] - s.0[i]).dot(&q.fixed_rows::<3>(6 * i))
                + cayley_inverse(&(t.1[i] * s.1[i].transpose())).dot(&q.fixed_rows::<3>(6 * i + 3))
        })
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, rng_seed: proptest::test_runner::RngSeed::Fixed(11), ..ProptestConfig::default() })]

    /// Σ p·q = Πₙ₊₁ − Πₙ for large steps (with a rigid rotation of up to
    /// ~1 rad on top), and the force is self-equilibrated about x̄.
    #[test]
    fn exact_energy_change_and_equilibrium(
        h in 0.01f64..1.5,
        seed in proptest::array::uniform6(-0.3f64..0.3),
        rigid in proptest::array::uniform3(-0.5f64..0.5),
    ) {
        let e = element();
        let (s, t) = step(&e, h, seed, &exp(&Vector3::from(rigid)));
        let q = e.discrete_gradient_force(&s, &t);
        let de = e.energy(&t.0, &t.1) - e.energy(&s.0, &s.1);
        let scale = e.energy(&t.0, &t.1).abs() + e.energy(&s.0, &s.1).abs();
        prop_assert!((work(&s, &t, &q) - de).abs() <= ENERGY_TOL * scale,
            "work {} vs ΔΠ {de}", work(&s, &t, &q));
        let f: Vector3<f64> = (0..3).map(|i| q.fixed_rows::<3>(6 * i).into_owned()).sum();
        let m: Vector3<f64> = (0..3)
            .map(|i| ((s.0[i] + t.0[i]) * 0.5).cross(&q.fixed_rows::<3>(6 * i).into_owned())
                + q.fixed_rows::<3>(6 * i + 3))
            .sum();
        prop_assert!(f.norm() <= EQUILIBRIUM_TOL * q.norm() && m.norm() <= EQUILIBRIUM_TOL * 10.0 * q.norm(),
            "f {f}, m {m}");
    }
}

#[test]
fn the_zero_step_limit_is_the_static_exact_gradient() {
    let e = element();
    let (s, _) = step(&e, 1.0, [0.0; 6], &Matrix3::identity());
    let q = e.discrete_gradient_force(&s, &s);
    let r: SVector<f64, 18> = e.energy_gradient::<18>(&s.0, &s.1);
    assert!(
        (q - r).norm() <= 1e-10 * r.norm(),
        "difference {} of {}",
        (q - r).norm(),
        r.norm()
    );
}

#[test]
fn the_force_converges_to_the_static_gradient_at_second_order() {
    let e = element();
    let (mid, _) = step(&e, 1.0, [0.0; 6], &Matrix3::identity());
    let r: SVector<f64, 18> = e.energy_gradient::<18>(&mid.0, &mid.1);
    let errors: Vec<f64> = (0..5)
        .map(|k| {
            let h = 0.2 / f64::powi(2.0, k);
            let du = [
                Vector3::new(0.1, -0.2, 0.05) * h,
                Vector3::new(0.02, 0.1, -0.1) * h,
                Vector3::new(-0.1, 0.1, 0.2) * h,
            ];
            let th = [
                Vector3::new(0.3, 0.1, -0.2) * h,
                Vector3::new(0.1, -0.2, 0.3) * h,
                Vector3::new(-0.2, 0.4, 0.1) * h,
            ];
            let s: Pose3<f64> = (
                std::array::from_fn(|i| mid.0[i] - du[i]),
                std::array::from_fn(|i| exp(&(-th[i])) * mid.1[i]),
            );
            let t: Pose3<f64> = (
                std::array::from_fn(|i| mid.0[i] + du[i]),
                std::array::from_fn(|i| exp(&th[i]) * mid.1[i]),
            );
            (e.discrete_gradient_force(&s, &t) - r).norm() / r.norm()
        })
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "errors {errors:?}");
    }
}

#[test]
fn tangent_transpose_derivative_matches_ad() {
    type D = DualSVec64<3>;
    let w = Vector3::new(0.3, -0.7, 0.2);
    for psi in [
        Vector3::new(0.01, -0.02, 0.03),
        Vector3::new(0.3, -0.5, 0.8),
        Vector3::new(1.2, 0.4, -1.5),
    ] {
        let pd = Vector3::new(
            D::from_re(psi.x).derivative(0),
            D::from_re(psi.y).derivative(1),
            D::from_re(psi.z).derivative(2),
        );
        let v = tangent(&pd).transpose() * w.map(D::from_re);
        let ad =
            Matrix3::from_fn(|i, j| v[i].eps.unwrap_generic(nalgebra::Const::<3>, nalgebra::U1)[j]);
        let cf = tangent_transpose_derivative(&psi, &w);
        assert!(
            (ad - cf).norm() <= 1e-13 * ad.norm().max(1.0),
            "ψ = {psi}: {ad} vs {cf}"
        );
    }
}

#[test]
fn differentiable_with_automatic_differentiation() {
    type D = DualSVec64<18>;
    let e = element();
    let (s, t) = step(
        &e,
        0.3,
        [0.1, 0.0, -0.1, 0.05, 0.0, 0.02],
        &Matrix3::identity(),
    );
    let f = |eta: &SVector<f64, 18>| {
        let tt: Pose3<f64> = (
            std::array::from_fn(|i| t.0[i] + eta.fixed_rows::<3>(6 * i)),
            std::array::from_fn(|i| exp(&eta.fixed_rows::<3>(6 * i + 3).into_owned()) * t.1[i]),
        );
        e.discrete_gradient_force(&s, &tt)
    };
    let seed = |k: usize| D::from_re(0.0).derivative(k);
    let v = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
    let sd: Pose3<D> = (
        s.0.map(|x| x.map(D::from_re)),
        s.1.map(|r| r.map(D::from_re)),
    );
    let td: Pose3<D> = (
        std::array::from_fn(|i| t.0[i].map(D::from_re) + v(6 * i)),
        std::array::from_fn(|i| exp(&v(6 * i + 3)) * t.1[i].map(D::from_re)),
    );
    let q = e.discrete_gradient_force(&sd, &td);
    let h = 1e-6;
    for j in 0..18 {
        let mut ep = SVector::<f64, 18>::zeros();
        ep[j] = h;
        let fd = (f(&ep) - f(&(-ep))) / (2.0 * h);
        let ad: SVector<f64, 18> = SVector::from_fn(|i, _| {
            q[i].eps.unwrap_generic(nalgebra::Const::<18>, nalgebra::U1)[j]
        });
        assert!((fd - ad).norm() <= 1e-6 * ad.norm().max(1.0), "column {j}");
    }
}
