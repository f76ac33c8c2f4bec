//! Joints whose released translation depends on the released rotation,
//! `r_R = f(ψ)` (paper §3): screw, rack-and-pinion, cam, lobe, and any profile
//! a researcher writes.
//!
//! A kind supplies only the axis `t` of the released rotation and `f`, written
//! once for any [`Scalar`]. Everything else is derived by automatic
//! differentiation:
//!
//! * the kinematics `Λ_R = exp((ψ − ψ₀) t̂)`, `r_R = f(ψ)`, hence the variation
//!   map `N` of eqs 10–11 (`δr_s = δr_m − (Λ_m r_R)^ δφ_m + Λ_m f′(ψ) δψ`,
//!   `δφ_s = δφ_m + Λ_m t δψ`) and its derivative (see [`crate::kinematics`]);
//! * `f′(ψ)` and `f″(ψ)` ([`DependentJointMaps::derivative`],
//!   [`DependentJointMaps::second_derivative`]);
//! * the secant `G` of eq. 22 with `u_R = f(ψₙ₊₁) − f(ψₙ) = G θ_R`
//!   ([`DependentJointMaps::secant`]), robust as the increment tends to zero;
//! * the exact incremental map `Ñ` of eqs 21–22
//!   ([`DependentJointMaps::incremental_map`]).
//!
//! # Adding a joint
//!
//! ```
//! use flexmech_core::Scalar;
//! use flexmech_joints::DependentJoint;
//! use nalgebra::Vector3;
//!
//! /// A screw whose pitch varies with the angle: f(ψ) = (cψ + d sin ψ) t.
//! #[derive(Debug)]
//! struct VariablePitchScrew { c: f64, d: f64, axis: Vector3<f64> }
//!
//! impl DependentJoint for VariablePitchScrew {
//!     fn axis(&self) -> Vector3<f64> { self.axis }
//!     fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
//!         let s = psi * T::from_subset(&self.c) + psi.sin() * T::from_subset(&self.d);
//!         self.axis.map(|a| T::from_subset(&a)) * s
//!     }
//! }
//! ```
//!
//! That is the whole joint: it can be used in a mechanism like the built-in
//! kinds, and its `N`, `G`, `Ñ` and tangents follow from `translation`.

use crate::kinematics::{axis_rotation, Angle, AngleAt, JointKinematics};
use crate::ReleasedState;
use flexmech_core::rotation::{cayley_mid, skew};
use flexmech_core::Scalar;
use nalgebra::{Matrix3, SMatrix, Vector3};
use num_dual::{Dual2_64, Dual64, HyperDual64};
use std::fmt::Debug;

/// A joint with one released rotation `ψ` about the axis `t` (master body
/// frame) and the released translation `r_R = f(ψ)`.
pub trait DependentJoint: Send + Sync + Debug {
    /// Unit axis `t` of the released rotation.
    fn axis(&self) -> Vector3<f64>;
    /// The released translation `f(ψ)` in the master body frame.
    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T>;

    /// `∂f/∂p` and `∂²f/∂ψ∂p` at `ψ` for the kind's real parameter `name`,
    /// where the kind can differentiate by it (exact sensitivities by joint
    /// parameters). Default: `None`, none of its parameters.
    fn translation_by(&self, _name: &str, _psi: f64) -> Option<[Vector3<f64>; 2]> {
        None
    }
}

/// `[∂f/∂p, ∂²f/∂ψ∂p]` at `(ψ, p)` of a translation `f(ψ; p)` written
/// once for any scalar: `f` is evaluated in hyper-dual numbers with `ψ`
/// seeded in the first direction and `p` in the second, so both come exact
/// (the kinds' [`DependentJoint::translation_by`]).
pub fn parameter_slopes(
    psi: f64,
    p: f64,
    f: impl Fn(HyperDual64, HyperDual64) -> Vector3<HyperDual64>,
) -> [Vector3<f64>; 2] {
    let v = f(
        HyperDual64::new(psi, 1.0, 0.0, 0.0),
        HyperDual64::new(p, 0.0, 1.0, 0.0),
    );
    [v.map(|x| x.eps2), v.map(|x| x.eps1eps2)]
}

impl<J: DependentJoint> JointKinematics for J {
    type Coordinates = Angle;

    fn parameter_derivative(&self, name: &str, state: &ReleasedState) -> Option<[Vector3<f64>; 2]> {
        self.translation_by(name, state.q[0])
    }

    fn released<T: Scalar>(&self, psi: &AngleAt<T>) -> (Vector3<T>, Matrix3<T>) {
        (
            self.translation(psi.angle),
            axis_rotation(&self.axis(), psi.turn()),
        )
    }
}

/// Nodes of the 8-point Gauss–Legendre rule on [0, 1] (abscissae, weights).
const GL8: [(f64, f64); 8] = [
    (0.019_855_071_751_231_856, 0.050_614_268_145_188_13),
    (0.101_666_761_293_186_63, 0.111_190_517_226_687_24),
    (0.237_233_795_041_835_5, 0.156_853_322_938_943_64),
    (0.408_282_678_752_175, 0.181_341_891_689_181),
    (0.591_717_321_247_825, 0.181_341_891_689_181),
    (0.762_766_204_958_164_5, 0.156_853_322_938_943_64),
    (0.898_333_238_706_813_4, 0.111_190_517_226_687_24),
    (0.980_144_928_248_768_2, 0.050_614_268_145_188_13),
];

/// Maps derived from `f` for every [`DependentJoint`].
pub trait DependentJointMaps {
    /// `f′(ψ)` by forward-mode AD.
    fn derivative(&self, psi: f64) -> Vector3<f64>;
    /// `f″(ψ)` by second-order AD.
    fn second_derivative(&self, psi: f64) -> Vector3<f64>;
    /// Mean slope `(f(ψ + ω) − f(ψ))/ω`, without cancellation for small `ω`
    /// (8-point Gauss–Legendre quadrature of `f′` below `|ω| = 10⁻²`, where it
    /// is exact to round-off for smooth `f`; the difference quotient above, and
    /// also below when the quadrature is not exact — a piecewise-smooth `f`
    /// such as a tabulated lift whose knot lies in `[ψ, ψ+ω]` — detected by
    /// comparing the rule on the whole interval with the rule on its halves).
    fn mean_slope(&self, psi: f64, omega: f64) -> Vector3<f64>;
    /// The secant `G` of paper eq. 22: `u_R = f(ψₙ + ω) − f(ψₙ) = G θ_R` with
    /// `θ_R = 2 tan(ω/2) t`, i.e. `G = (f(ψₙ₊₁) − f(ψₙ)) ⊗ t / (t·θ_R)`;
    /// tends to `f′(ψₙ) ⊗ t` as `ω → 0`.
    fn secant(&self, psi_n: f64, omega: f64) -> Matrix3<f64>;
    /// The exact incremental map `Ñ` of paper eqs 21–22 for the conserving
    /// schemes: with the master's tangent-scaled increment `θ_m`, its rotation
    /// `Λ_m,ₙ` at step start and the released increment `ω`,
    /// `(u_s, θ_s) = Ñ (τ, u_m, θ_m)` exactly, where `τ = 2 tan(ω/2)` is the
    /// released tangent-scaled increment (`θ_R = τ t`):
    /// `u_s = u_m + Λ̄_m G θ_R − (Λ̄_m r̄_R)^ θ_m`,
    /// `θ_s = θ_m + A θ_R`, `A = (I + ½θ̂_m + ¼θ_m⊗θ_m) Λ_m,ₙ / (1 − ¼ θ_m·θ_r)`,
    /// `θ_r = Λ_m,ₙ θ_R`, `Λ̄_m = S(θ_m)⁻¹Λ_m,ₙ`, `r̄_R = ½(f(ψₙ) + f(ψₙ₊₁))`.
    /// Columns: `τ`, `u_m` (3), `θ_m` (3).
    fn incremental_map(
        &self,
        r_mn: &Matrix3<f64>,
        theta_m: &Vector3<f64>,
        psi_n: f64,
        omega: f64,
    ) -> SMatrix<f64, 6, 7>;
}

impl<J: DependentJoint> DependentJointMaps for J {
    fn derivative(&self, psi: f64) -> Vector3<f64> {
        self.translation(Dual64::new(psi, 1.0)).map(|v| v.eps)
    }

    fn second_derivative(&self, psi: f64) -> Vector3<f64> {
        self.translation(Dual2_64::new(psi, 1.0, 0.0)).map(|v| v.v2)
    }

    fn mean_slope(&self, psi: f64, omega: f64) -> Vector3<f64> {
        let quotient = || (self.translation(psi + omega) - self.translation(psi)) / omega;
        if omega.abs() >= 1e-2 {
            return quotient();
        }
        // Gauss–Legendre on [ψ, ψ+ω] and, as an error estimate, on its two halves.
        let mut scale = 0.0;
        let mut rule = |a: f64, w: f64| -> Vector3<f64> {
            GL8.iter()
                .map(|&(s, wt)| {
                    let d = self.derivative(a + s * w) * wt;
                    scale += d.norm();
                    d
                })
                .sum()
        };
        let whole = rule(psi, omega);
        let halves = (rule(psi, 0.5 * omega) + rule(psi + 0.5 * omega, 0.5 * omega)) * 0.5;
        // For a smooth f both rules agree to round-off. A profile that is only
        // piecewise smooth (a tabulated lift, C² at its knots) defeats the rule
        // when [ψ, ψ+ω] straddles a knot; then G θ_R would miss
        // f(ψ+ω) − f(ψ) by far more than round-off, and the difference quotient
        // (exact increment, mild cancellation) is used instead.
        if omega == 0.0 || (whole - halves).norm() <= 64.0 * f64::EPSILON * scale {
            halves
        } else {
            quotient()
        }
    }

    fn secant(&self, psi_n: f64, omega: f64) -> Matrix3<f64> {
        // (f(ψ+ω) − f(ψ))/(2 tan(ω/2)) = mean slope · (ω/2)/tan(ω/2).
        let h = 0.5 * omega;
        let ratio = if h.abs() < 1e-4 {
            1.0 - h * h / 3.0 - h.powi(4) / 45.0
        } else {
            h / h.tan()
        };
        self.mean_slope(psi_n, omega) * ratio * self.axis().transpose()
    }

    fn incremental_map(
        &self,
        r_mn: &Matrix3<f64>,
        theta_m: &Vector3<f64>,
        psi_n: f64,
        omega: f64,
    ) -> SMatrix<f64, 6, 7> {
        let t = self.axis();
        let tau = 2.0 * (0.5 * omega).tan();
        let theta_r = r_mn * (t * tau);
        let mid = cayley_mid(theta_m) * r_mn;
        let r_bar = (self.translation(psi_n) + self.translation(psi_n + omega)) * 0.5;
        let g = self.secant(psi_n, omega);
        let a = (Matrix3::identity() + skew(theta_m) * 0.5 + theta_m * theta_m.transpose() * 0.25)
            * r_mn
            / (1.0 - 0.25 * theta_m.dot(&theta_r));
        let mut n = SMatrix::<f64, 6, 7>::zeros();
        n.fixed_view_mut::<3, 1>(0, 0).copy_from(&(mid * g * t));
        n.fixed_view_mut::<3, 3>(0, 1)
            .copy_from(&Matrix3::identity());
        n.fixed_view_mut::<3, 3>(0, 4)
            .copy_from(&(-skew(&(mid * r_bar))));
        n.fixed_view_mut::<3, 1>(3, 0).copy_from(&(a * t));
        n.fixed_view_mut::<3, 3>(3, 4)
            .copy_from(&Matrix3::identity());
        n
    }
}
