//! The conserving schemes' tangents against the AD oracle: the full
//! 12-direction forward-mode Jacobian of the generic kernels
//! ([`BeamElement::midpoint_force`], [`BeamElement::discrete_gradient_force`])
//! over random large-rotation states and steps.

use super::*;
use crate::conserving::tests::element;
use crate::conserving::MidRotation;
use crate::rotation::{cayley, exp};
use proptest::prelude::*;

/// Agreement with the AD Jacobian, relative to its size: both are exact, so
/// only round-off of the operations separates them.
const TANGENT_TOL: f64 = 1e-11;

type D = DualSVec64<12>;

/// Which scheme's force.
#[derive(Clone, Copy)]
enum Kind {
    Momentum,
    EnergyMomentum,
}

/// The force and its Jacobian by forward AD over all twelve end increments
/// (`x ← x + η`, `R ← exp(η̂)R`).
fn ad_oracle(
    e: &BeamElement<2>,
    start: &Pose<f64>,
    end: &Pose<f64>,
    kind: Kind,
) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
    let seed = |k: usize| D::from_re(0.0).derivative(k);
    let v = |k: usize| Vector3::new(seed(k), seed(k + 1), seed(k + 2));
    let sd: Pose<D> = (
        start.0.map(|x| x.map(D::from_re)),
        start.1.map(|r| r.map(D::from_re)),
    );
    let ed: Pose<D> = (
        [
            end.0[0].map(D::from_re) + v(0),
            end.0[1].map(D::from_re) + v(6),
        ],
        [
            exp(&v(3)) * end.1[0].map(D::from_re),
            exp(&v(9)) * end.1[1].map(D::from_re),
        ],
    );
    let (n0, m0) = e.resultants(&start.0, &start.1);
    let (n1, m1) = e.resultants(&ed.0, &ed.1);
    let half = D::from_re(0.5);
    let nbar = (n0.map(D::from_re) + n1) * half;
    let mbar = (m0.map(D::from_re) + m1) * half;
    let q = match kind {
        Kind::Momentum => e.midpoint_force(&sd, &ed, &nbar, &mbar, MidRotation::Geodesic),
        Kind::EnergyMomentum => e.discrete_gradient_force(&sd, &ed, &nbar, &mbar),
    };
    let mut r = SVector::<f64, 12>::zeros();
    let mut k = SMatrix::<f64, 12, 12>::zeros();
    for i in 0..12 {
        r[i] = q[i].re;
        k.set_row(i, &q[i].eps.unwrap_generic(Const::<12>, U1).transpose());
    }
    (r, k)
}

/// A deformed start pose and a step from it: rotation vectors `rot` (start,
/// up to about 2 rad) and Cayley increments `inc`, position offsets `dx`.
fn poses(
    x0: &[Vector3<f64>; 2],
    rot: [f64; 6],
    inc: [f64; 6],
    dx: [f64; 6],
) -> (Pose<f64>, Pose<f64>) {
    let v = |a: &[f64; 6], i: usize| Vector3::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    let start = (
        [x0[0] + v(&dx, 0) * 0.3, x0[1] + v(&dx, 1) * 0.3],
        [exp(&v(&rot, 0)), exp(&v(&rot, 1))],
    );
    let end = (
        [start.0[0] + v(&dx, 1) * 0.1, start.0[1] + v(&dx, 0) * 0.1],
        [
            cayley(&v(&inc, 0)) * start.1[0],
            cayley(&v(&inc, 1)) * start.1[1],
        ],
    );
    (start, end)
}

fn check(kind: Kind, start: &Pose<f64>, end: &Pose<f64>) -> Result<(), TestCaseError> {
    let (e, _) = element();
    let (r_ad, k_ad) = ad_oracle(&e, start, end, kind);
    let (r, k) = match kind {
        Kind::Momentum => e.momentum_force_tangent(start, end),
        Kind::EnergyMomentum => e.energy_momentum_force_tangent(start, end),
    };
    let scale = r_ad.norm().max(1.0);
    prop_assert!(
        (r - r_ad).norm() <= TANGENT_TOL * scale,
        "residual {}",
        (r - r_ad).norm()
    );
    let kscale = k_ad.norm().max(1.0);
    let err = (k - k_ad).norm();
    prop_assert!(
        err <= TANGENT_TOL * kscale,
        "tangent error {err} of {kscale}"
    );
    Ok(())
}

fn angles(limit: f64) -> impl Strategy<Value = [f64; 6]> {
    prop::array::uniform6(-limit..limit)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn momentum_tangent_equals_the_ad_jacobian(
        rot in angles(1.2), inc in angles(0.4), dx in angles(1.0)
    ) {
        let (_, x0) = element();
        let (start, end) = poses(&x0, rot, inc, dx);
        check(Kind::Momentum, &start, &end)?;
    }

    #[test]
    fn energy_momentum_tangent_equals_the_ad_jacobian(
        rot in angles(1.2), inc in angles(0.4), dx in angles(1.0)
    ) {
        let (_, x0) = element();
        let (start, end) = poses(&x0, rot, inc, dx);
        check(Kind::EnergyMomentum, &start, &end)?;
    }
}

#[test]
fn tangents_hold_for_a_step_without_motion() {
    // No increment at all: ω = 0 and Δθ = 0 (the series branches and the
    // regularised rank-one corrections).
    let (_, x0) = element();
    let (start, _) = poses(&x0, [0.3, -0.2, 0.5, -0.1, 0.6, 0.2], [0.0; 6], [0.1; 6]);
    for kind in [Kind::Momentum, Kind::EnergyMomentum] {
        check(kind, &start, &start).unwrap();
    }
}
