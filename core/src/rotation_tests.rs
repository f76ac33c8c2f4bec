//! Identities of FORMULATION §1, each checked as a property over random
//! rotation vectors, including near 0 and near π.

use super::*;
use nalgebra::{Matrix3, Vector3};
use num_dual::{Dual64, DualNum};
use proptest::prelude::*;

fn close_m(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol * (1.0 + b.norm())
}
fn close_v(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol * (1.0 + b.norm())
}

/// Unit vector from spherical angles.
fn unit(theta: f64, phi: f64) -> Vector3<f64> {
    Vector3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Rotation vectors with |ψ| from 1e-9 up to π − 1e-6: uniform, tiny and near π.
fn rotation_vector() -> impl Strategy<Value = Vector3<f64>> {
    let mag = prop_oneof![
        0.0..3.1,
        1e-9..1e-3,
        (std::f64::consts::PI - 1e-3)..(std::f64::consts::PI - 1e-6),
    ];
    (
        mag,
        0.0..std::f64::consts::PI,
        0.0..(2.0 * std::f64::consts::PI),
    )
        .prop_map(|(m, t, p)| unit(t, p) * m)
}

fn small_vector() -> impl Strategy<Value = Vector3<f64>> {
    (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn exp_is_a_rotation(psi in rotation_vector()) {
        let r = exp(&psi);
        prop_assert!(close_m(&(r.transpose() * r), &Matrix3::identity(), 1e-14));
        prop_assert!((r.determinant() - 1.0).abs() < 1e-14);
        // exp(ψ̂)ψ = ψ: the axis is fixed.
        prop_assert!(close_v(&(r * psi), &psi, 1e-14));
    }

    #[test]
    fn log_inverts_exp(psi in rotation_vector()) {
        let back = log(&exp(&psi));
        prop_assert!((back - psi).norm() <= 1e-12 * (1.0 + psi.norm()) + 1e-7 * near_pi(psi.norm()),
            "psi {psi:?} back {back:?}");
        // Always exp(log(Λ)) = Λ, even at π where the vector's sign is ambiguous.
        prop_assert!(close_m(&exp(&back), &exp(&psi), 1e-13));
    }

    #[test]
    fn quaternion_round_trip(psi in rotation_vector()) {
        let r = exp(&psi);
        let q = quaternion_from_matrix(&r);
        prop_assert!((q.norm() - 1.0).abs() < 1e-14);
        prop_assert!(q.x >= 0.0);
        prop_assert!(close_m(&matrix_from_quaternion(&q), &r, 1e-14));
    }

    #[test]
    fn quaternion_maps_agree_with_the_matrices(
        psi in rotation_vector(),
        chi in rotation_vector(),
        theta in small_vector(),
    ) {
        // The quaternion route of the discrete gradient's secant operators
        // against the matrix maps it replaces.
        let (q, p) = (exp_quaternion(&psi), exp_quaternion(&chi));
        prop_assert!((q.norm() - 1.0).abs() < 1e-14 && q.x >= 0.0);
        prop_assert!(close_m(&matrix_from_quaternion(&q), &exp(&psi), 1e-14));
        let product = matrix_from_quaternion(&quaternion_product(&q, &p));
        prop_assert!(close_m(&product, &(exp(&psi) * exp(&chi)), 1e-14));
        let conjugate = matrix_from_quaternion(&quaternion_conjugate(&q));
        prop_assert!(close_m(&conjugate, &exp(&psi).transpose(), 1e-14));
        let half = matrix_from_quaternion(&quaternion_half(&q));
        prop_assert!(close_m(&half, &exp(&(psi * 0.5)), 1e-13));
        let cay = cayley_quaternion(&theta);
        prop_assert!(close_m(&matrix_from_quaternion(&cay), &cayley(&theta), 1e-14));
        prop_assert!(close_v(&cayley_of_quaternion(&cay), &theta, 1e-14));
    }

    #[test]
    fn tangent_fixes_its_vector(psi in rotation_vector()) {
        // H(ψ)ψ = ψ (check)
        prop_assert!(close_v(&(tangent(&psi) * psi), &psi, 1e-14));
    }

    #[test]
    fn tangent_is_the_derivative_of_exp(psi in rotation_vector(), dir in small_vector()) {
        // d/dε exp(ψ + εδ) · exp(ψ)ᵀ = (H(ψ) δ)^ at ε = 0, by forward-mode AD.
        let p: Vector3<Dual64> = psi.map(Dual64::from) + dir.map(|d| Dual64::new(0.0, d));
        let e = exp(&p);
        let de = e.map(|x| x.eps);
        let spin = de * exp(&psi).transpose();
        let expected = skew(&(tangent(&psi) * dir));
        prop_assert!(close_m(&spin, &expected, 1e-12), "{spin} vs {expected}");
        // The material tangent is Hᵀ: exp(ψ)ᵀ · d exp = (Hᵀ δ)^.
        let mat = exp(&psi).transpose() * de;
        prop_assert!(close_m(&mat, &skew(&(tangent(&psi).transpose() * dir)), 1e-12));
    }

    #[test]
    fn tangent_inverse_inverts(psi in rotation_vector()) {
        let h = tangent(&psi);
        let hi = tangent_inverse(&psi);
        // H is ill-conditioned towards 2π only; here |ψ| < π.
        prop_assert!(close_m(&(h * hi), &Matrix3::identity(), 1e-11));
    }

    #[test]
    fn cayley_inverse_agrees_with_the_quaternion_route_and_its_derivative(
        psi in rotation_vector(),
        dir in (0.0..std::f64::consts::PI, 0.0..(2.0 * std::f64::consts::PI)),
    ) {
        // The direct formula (1 + tr Λ ≥ 1) and the quaternion (beyond) give
        // θ = tan(|ψ|/2)/(|ψ|/2)·ψ; and, along a spatial spin, the same
        // derivative as θ = 2v/w of the quaternion, on both sides of the switch.
        prop_assume!(psi.norm() < 3.0);
        let r = exp(&psi);
        let th = tan_scaled(&psi);
        prop_assert!((cayley_inverse(&r) - th).norm() <= 1e-13 * (1.0 + th.norm_squared()));
        let w = unit(dir.0, dir.1).map(|d| Dual64::new(0.0, d));
        let rd = exp(&w) * r.map(Dual64::from);
        let q = quaternion_from_matrix(&rd);
        let by_quaternion = Vector3::new(q.y, q.z, q.w) * (Dual64::from(2.0) / q.x);
        let direct = cayley_inverse(&rd);
        let (a, b) = (direct.map(|x| x.eps), by_quaternion.map(|x| x.eps));
        prop_assert!((a - b).norm() <= 1e-12 * (1.0 + b.norm()));
    }

    #[test]
    fn cayley_is_exp_of_the_untangent_vector(theta in small_vector()) {
        // cay(θ) = exp(ω̂) iff θ = tan(|ω|/2)/(|ω|/2)·ω (check)
        let omega = untan_scaled(&theta);
        prop_assert!(close_m(&cayley(&theta), &exp(&omega), 1e-14));
        prop_assert!(close_v(&tan_scaled(&omega), &theta, 1e-13));
        prop_assert!(close_v(&cayley_inverse(&cayley(&theta)), &theta, 1e-13));
        // The closed form equals (I − ½θ̂)⁻¹(I + ½θ̂).
        let k = skew(&theta) * 0.5;
        let form = (Matrix3::identity() - k).try_inverse().unwrap() * (Matrix3::identity() + k);
        prop_assert!(close_m(&cayley(&theta), &form, 1e-14));
    }

    #[test]
    fn cayley_mid_point_identities(theta in small_vector(), psi in rotation_vector(), v in small_vector()) {
        // ½(cay(θ) + I) = (I − ½θ̂)⁻¹ = S(θ)⁻¹ (check)
        let s_inv = cayley_mid(&theta);
        let half_sum = (cayley(&theta) + Matrix3::identity()) * 0.5;
        let inv = (Matrix3::identity() - skew(&theta) * 0.5).try_inverse().unwrap();
        prop_assert!(close_m(&s_inv, &half_sum, 1e-14));
        prop_assert!(close_m(&s_inv, &inv, 1e-14));
        // (Λₙ₊₁ − Λₙ)v = θ × (Λₙ₊½ v), Λₙ₊₁ = cay(θ)Λₙ, Λₙ₊½ = S(θ)⁻¹Λₙ (check)
        let ln = exp(&psi);
        let ln1 = cayley(&theta) * ln;
        let mid = s_inv * ln;
        prop_assert!(close_m(&mid, &((ln + ln1) * 0.5), 1e-14));
        let lhs = (ln1 - ln) * v;
        let rhs = theta.cross(&(mid * v));
        prop_assert!(close_v(&lhs, &rhs, 1e-13));
    }

    #[test]
    fn cayley_composition(a in small_vector(), b in small_vector()) {
        prop_assume!((1.0 - 0.25 * a.dot(&b)).abs() > 1e-3);
        // cay(a)·cay(b) = cay(c), c = (a + b + ½ a×b)/(1 − ¼ a·b) (check)
        let c = cayley_compose(&a, &b);
        prop_assert!(close_m(&(cayley(&a) * cayley(&b)), &cayley(&c), 1e-12));
    }

    #[test]
    fn spatial_and_material_perturbations_agree(psi in rotation_vector(), d in small_vector()) {
        // exp((Λd)^)Λ = Λ exp(d̂): a spatial spin is the rotated material one.
        let r = exp(&psi);
        let left = exp(&(r * d * 0.1)) * r;
        let right = r * exp(&(d * 0.1));
        prop_assert!(close_m(&left, &right, 1e-13));
    }
}

/// Near |ψ| = π the rotation vector is determined only up to sign, and the
/// log's accuracy degrades like ε/(π − |ψ|); the tolerance admits exactly that.
fn near_pi(m: f64) -> f64 {
    if m > std::f64::consts::PI - 1e-2 {
        1e-9 / (std::f64::consts::PI - m).max(1e-9)
    } else {
        0.0
    }
}

#[test]
fn series_and_closed_forms_join_smoothly() {
    // Both sides of the series limit agree to round-off (no jump at the switch).
    let axis = Vector3::new(0.3, -0.5, 0.81).normalize();
    let below = axis * (SERIES_LIMIT.sqrt() * (1.0 - 1e-15));
    let above = axis * (SERIES_LIMIT.sqrt() * (1.0 + 1e-15));
    assert!(close_m(&exp(&below), &exp(&above), 1e-13));
    assert!(close_m(&tangent(&below), &tangent(&above), 1e-13));
    assert!(close_m(
        &tangent_inverse(&below),
        &tangent_inverse(&above),
        1e-13
    ));
    assert!(close_v(
        &tan_scaled(&(below * 2.0)),
        &tan_scaled(&(above * 2.0)),
        1e-13
    ));
}

#[test]
fn log_at_exact_half_turn_and_identity() {
    for axis in [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        Vector3::new(1.0, 1.0, 1.0).normalize(),
    ] {
        let psi = axis * std::f64::consts::PI;
        let back = log(&exp(&psi));
        assert!((back.norm() - std::f64::consts::PI).abs() < 1e-12);
        assert!(close_m(&exp(&back), &exp(&psi), 1e-14));
    }
    assert_eq!(log(&Matrix3::<f64>::identity()), Vector3::zeros());
}

#[test]
fn derivatives_are_finite_at_the_identity() {
    // AD through log and exp at exactly zero rotation (series branches).
    let z: Vector3<Dual64> =
        Vector3::new(Dual64::new(0.0, 1.0), Dual64::from(0.0), Dual64::from(0.0));
    let r = exp(&z);
    let back = log(&r);
    assert!((back.x.eps - 1.0).abs() < 1e-15 && back.y.eps.abs() < 1e-15);
    let h = tangent_inverse(&z);
    assert!(h.iter().all(|x| x.eps.is_finite() && x.re.is_finite()));
    let _ = Dual64::from(1.0).sqrt();
}
