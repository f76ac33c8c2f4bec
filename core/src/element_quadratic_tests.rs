//! The 3-node kernels through invariant coordinates against the AD oracle:
//! the hyper-dual gradient and Hessian of the whole element energy
//! ([`BeamElement::residual_tangent_ad`]) over random large-rotation states
//! of a curved element.

use super::*;
use crate::rotation::exp;
use crate::section::Section;
use proptest::prelude::*;

/// Both sides are exact: only round-off of different operation orders
/// separates them.
const ORACLE_TOL: f64 = 1e-10;

/// A curved 3-node element (a 0.9 rad arc of radius 2, tilted out of its
/// plane) with an anisotropic section.
fn element() -> (BeamElement<3>, [Vector3<f64>; 3]) {
    let sec = Section::new(
        [2.0e4, 8.0e3, 9.0e3],
        [30.0, 45.0, 60.0],
        1.0,
        [0.2, 0.1, 0.1],
    );
    let tilt = exp(&Vector3::new(0.3, -0.2, 0.1));
    let (r, sweep) = (2.0, 0.9);
    let x0: [Vector3<f64>; 3] = std::array::from_fn(|i| {
        let a = sweep * i as f64 / 2.0;
        tilt * Vector3::new(r * a.sin(), r * (1.0 - a.cos()), 0.0)
    });
    let l0: [Matrix3<f64>; 3] = std::array::from_fn(|i| {
        let a = sweep * i as f64 / 2.0;
        let t = Vector3::new(a.cos(), a.sin(), 0.0);
        tilt * Matrix3::from_columns(&[t, Vector3::z().cross(&t), Vector3::z()])
    });
    (BeamElement::new([0, 1, 2], sec, r * sweep, &x0, l0), x0)
}

fn rel(err: f64, size: f64) -> f64 {
    err / size.max(1.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn residual_and_tangent_equal_the_hyper_dual_oracle(
        du in prop::array::uniform9(-0.3..0.3f64),
        dr in prop::array::uniform9(-1.2..1.2f64),
        rigid in prop::array::uniform3(-2.5..2.5f64),
    ) {
        let (e, x0) = element();
        let q = exp(&Vector3::from(rigid));
        let x: [Vector3<f64>; 3] =
            std::array::from_fn(|i| q * (x0[i] + Vector3::new(du[3 * i], du[3 * i + 1], du[3 * i + 2])));
        let rot: [Matrix3<f64>; 3] =
            std::array::from_fn(|i| q * exp(&Vector3::new(dr[3 * i], dr[3 * i + 1], dr[3 * i + 2])));
        let (r_ad, k_ad) = e.residual_tangent_ad::<18>(&x, &rot);
        let (r, k) = e.residual_tangent_quadratic(&x, &rot);
        prop_assert!(rel((r - r_ad).norm(), r_ad.norm()) <= ORACLE_TOL, "residual");
        prop_assert!(rel((k - k_ad).norm(), k_ad.norm()) <= ORACLE_TOL, "tangent {}", (k - k_ad).norm());
        let f = e.internal_force_quadratic(&x, &rot);
        prop_assert!(rel((f - r_ad).norm(), r_ad.norm()) <= ORACLE_TOL, "internal force");
    }
}

#[test]
fn unstrained_rigid_motion_has_no_force() {
    let (e, x0) = element();
    let q = exp(&Vector3::new(0.7, -1.1, 0.4));
    let t = Vector3::new(1.0, -2.0, 0.5);
    let x = x0.map(|p| q * p + t);
    let f = e.internal_force_quadratic(&x, &[q; 3]);
    assert!(f.norm() < 1e-10, "{f}");
}
