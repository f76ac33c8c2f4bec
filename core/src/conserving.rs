//! The internal force of the momentum- and energy–momentum conserving schemes
//! for the 2-node element (paper eq. 17, FORMULATION §4):
//!
//! ```text
//! q_k,i(N̄, M̄) = L [ Iᵢ′ n ;  −Iᵢ (r′ₙ₊½ × n) + Iᵢ′ m ],   n = Λ̃ N̄,  m = Λ̃ M̄
//! ```
//!
//! with one-point quadrature (`Iᵢ = ½`, `Iᵢ′ = ∓1/L`), `N̄`, `M̄` material
//! resultants (the step average `N̄ = Nₙ₊½` in the schemes, or `N_d = Nₙ₊₁ − Nₙ`
//! for the energy–momentum correction), and `Λ̃` the mid-step reference
//! rotation: geodesic `exp(½ω̂_r)Λ_r,ₙ` (momentum conserving) or algebraic
//! `½(Λ_r,ₙ + Λ_r,ₙ₊₁) = S(θ_r)⁻¹Λ_r,ₙ` (energy–momentum). Whatever `N̄`, `M̄`
//! and `Λ̃`, the force is self-equilibrated about the mid-step configuration
//! `x̄ = ½(xₙ + xₙ₊₁)`, which is what conserves linear and angular momentum.

use crate::element::BeamElement;
use crate::rotation::{
    exp, log, log_quaternion, mm, mtm, mv, quaternion_from_matrix, quaternion_half,
};
use crate::scalar::{cst, Scalar};
use nalgebra::{Matrix3, SVector, Vector3, Vector4};

/// The mid-step reference rotation `Λ̃`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MidRotation {
    /// `exp(½ω̂_r)Λ_r,ₙ` with `ω_r = log(Λ_r,ₙ₊₁Λ_r,ₙᵀ)`: a rotation.
    Geodesic,
    /// `½(Λ_r,ₙ + Λ_r,ₙ₊₁)`: not a rotation; makes the energy balance of the
    /// translational strains exact.
    Algebraic,
}

/// A configuration of one 2-node element: nodal positions and rotations.
pub type Pose<T> = ([Vector3<T>; 2], [Matrix3<T>; 2]);

/// The rotation pieces of one 2-node element pose (`Λᵢ = RᵢΛ₀ᵢ`):
/// computed once per pose and shared by the resultants, the discrete
/// gradient and the tangents, each of which needs the same logarithm and
/// exponential.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frames<T: Scalar> {
    /// Nodal triads `Λ₁`, `Λ₂`.
    pub(crate) lam: [Matrix3<T>; 2],
    /// Unit quaternion (`w ≥ 0`) of the relative rotation `Λ₁ᵀΛ₂ = exp(φ̂)`.
    pub(crate) rel: Vector4<T>,
    /// `φ = log(Λ₁ᵀΛ₂)`.
    pub(crate) phi: Vector3<T>,
    /// Unit quaternion of `exp(½φ̂)`, the square root of [`Self::rel`].
    pub(crate) half: Vector4<T>,
    /// Reference rotation `Λ_r = Λ₁ exp(½φ̂)`.
    pub(crate) lam_r: Matrix3<T>,
    /// Chord `d = x₂ − x₁`.
    pub(crate) d: Vector3<T>,
}

impl Frames<f64> {
    /// Zero pieces, to be overwritten (a place for `frames_pair_into`).
    pub(crate) fn zeros() -> Self {
        Frames {
            lam: [Matrix3::zeros(); 2],
            rel: Vector4::zeros(),
            phi: Vector3::zeros(),
            half: Vector4::zeros(),
            lam_r: Matrix3::zeros(),
            d: Vector3::zeros(),
        }
    }
}

/// A configuration of one 3-node element: nodal positions and rotations.
pub type Pose3<T> = ([Vector3<T>; 3], [Matrix3<T>; 3]);

impl BeamElement<2> {
    /// Reference rotation `Λ_r = Λ₁ exp(½ log(Λ₁ᵀΛ₂))` of the element's triads
    /// `Λᵢ = Rᵢ Λ₀ᵢ`.
    pub fn reference_rotation<T: Scalar>(&self, rot: &[Matrix3<T>; 2]) -> Matrix3<T> {
        let l1 = rot[0] * self.lambda0[0].map(cst::<T>);
        let l2 = rot[1] * self.lambda0[1].map(cst::<T>);
        l1 * exp(&(log(&(l1.transpose() * l2)) * cst::<T>(0.5)))
    }

    /// Material stress resultants `(N, M)` at the element's single Gauss
    /// point: `N = C_N(Λ_rᵀd/L − Γ₀)`, `M = C_M(φ/L − K₀)` with
    /// `φ = log(Λ₁ᵀΛ₂)`, `Λ_r = Λ₁ exp(½φ̂)`, `d = x₂ − x₁` (the general
    /// [`BeamElement::stresses`] specialised to two nodes: there `ψ₁,₂ = ∓½φ`
    /// and the Gauss point's triad is `Λ_r`).
    pub fn resultants<T: Scalar>(
        &self,
        x: &[Vector3<T>; 2],
        rot: &[Matrix3<T>; 2],
    ) -> (Vector3<T>, Vector3<T>) {
        self.frame_resultants(&self.frames(&(*x, *rot)))
    }

    /// The rotation pieces of a pose every conserving kernel needs, each
    /// computed once: triads, the quaternions of `Λ₁ᵀΛ₂` and of its half
    /// `exp(½φ̂)`, `φ`, `Λ_r` and the chord. `Λ_r = Λ₁ exp(½φ̂)` takes the
    /// exponential of `φ`, not the half quaternion's matrix: a function of
    /// `φ` alone, it stays a rotation along any derivative direction (with
    /// the half quaternion's matrix there, the central-difference check of
    /// the paper scheme's energy sensitivity on the spin-up missed its 1e-4
    /// bound: 1.4e-4).
    pub(crate) fn frames<T: Scalar>(&self, pose: &Pose<T>) -> Frames<T> {
        let lam = self.triads(&pose.1);
        let rel = quaternion_from_matrix(&mtm(&lam[0], &lam[1]));
        let phi = log_quaternion(&rel);
        let half = quaternion_half(&rel);
        Frames {
            lam_r: mm(&lam[0], &exp(&(phi * cst::<T>(0.5)))),
            lam,
            rel,
            phi,
            half,
            d: pose.0[1] - pose.0[0],
        }
    }

    /// [`Self::resultants`] of a pose's [`Frames`].
    pub(crate) fn frame_resultants<T: Scalar>(&self, f: &Frames<T>) -> (Vector3<T>, Vector3<T>) {
        let l = cst::<T>(self.length);
        let (g0, k0) = self.initial_strains()[0];
        (
            (mv(&f.lam_r.transpose(), &f.d) / l - g0.map(cst::<T>))
                .component_mul(&self.section.c_n.map(cst::<T>)),
            (f.phi / l - k0.map(cst::<T>)).component_mul(&self.section.c_m.map(cst::<T>)),
        )
    }

    /// `q_k` of paper eq. 17 between the poses at `n` and `n+1` for the
    /// material resultants `(nbar, mbar)`, ordered `(f₁, m₁, f₂, m₂)`:
    /// `f₁ = −n`, `f₂ = n`, `m₁,₂ = −½ d̄ × n ∓ m` with `d̄ = x̄₂ − x̄₁`.
    pub fn midpoint_force<T: Scalar>(
        &self,
        start: &Pose<T>,
        end: &Pose<T>,
        nbar: &Vector3<T>,
        mbar: &Vector3<T>,
        mid: MidRotation,
    ) -> SVector<T, 12> {
        let half = cst::<T>(0.5);
        let ln = self.reference_rotation(&start.1);
        let ln1 = self.reference_rotation(&end.1);
        let lt = match mid {
            MidRotation::Geodesic => exp(&(log(&(ln1 * ln.transpose())) * half)) * ln,
            MidRotation::Algebraic => (ln + ln1) * half,
        };
        let n = lt * nbar;
        let m = lt * mbar;
        let dbar = (end.0[1] + start.0[1] - end.0[0] - start.0[0]) * half;
        let arm = -dbar.cross(&n) * half;
        let mut q = SVector::<T, 12>::zeros();
        q.fixed_rows_mut::<3>(0).copy_from(&(-n));
        q.fixed_rows_mut::<3>(3).copy_from(&(arm - m));
        q.fixed_rows_mut::<3>(6).copy_from(&n);
        q.fixed_rows_mut::<3>(9).copy_from(&(arm + m));
        q
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::rotation::{cayley, tan_scaled};
    use crate::section::Section;

    /// A tilted 2-node element with an anisotropic section, shared with the
    /// discrete-gradient tests.
    pub(crate) fn element() -> (BeamElement<2>, [Vector3<f64>; 2]) {
        let sec = Section::new(
            [2.0e4, 8.0e3, 9.0e3],
            [30.0, 45.0, 60.0],
            1.0,
            [0.2, 0.1, 0.1],
        );
        let x0 = [Vector3::new(0.1, 0.2, -0.3), Vector3::new(1.2, 0.6, -0.1)];
        let t1 = (x0[1] - x0[0]).normalize();
        let t2 = (Vector3::z() - t1 * t1.z).normalize();
        let l0 = Matrix3::from_columns(&[t1, t2, t1.cross(&t2)]);
        (
            BeamElement::new([0, 1], sec, (x0[1] - x0[0]).norm(), &x0, [l0, l0]),
            x0,
        )
    }

    /// Two deformed poses a step apart: rotations advanced by Cayley increments.
    fn poses(x0: &[Vector3<f64>; 2], scale: f64) -> (Pose<f64>, Pose<f64>, [Vector3<f64>; 2]) {
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
            Vector3::new(0.2, 0.1, -0.3) * scale,
            Vector3::new(-0.1, 0.4, 0.2) * scale,
        ];
        let end = (
            [
                start.0[0] + Vector3::new(0.1, 0.05, -0.02) * scale,
                start.0[1] + Vector3::new(-0.03, 0.1, 0.08) * scale,
            ],
            [
                cayley(&theta[0]) * start.1[0],
                cayley(&theta[1]) * start.1[1],
            ],
        );
        (start, end, theta)
    }

    #[test]
    fn two_node_resultants_equal_the_general_stresses() {
        let (e, x0) = element();
        let (start, end, _) = poses(&x0, 1.0);
        for pose in [start, end] {
            let (n, m) = e.resultants(&pose.0, &pose.1);
            let (ng, mg) = e.stresses(&pose.0, &pose.1)[0];
            assert!((n - ng).norm() <= 1e-12 * ng.norm().max(1.0), "{n} {ng}");
            assert!((m - mg).norm() <= 1e-12 * mg.norm().max(1.0), "{m} {mg}");
        }
    }

    #[test]
    fn self_equilibrated_about_the_mid_configuration() {
        let (e, x0) = element();
        let (start, end, _) = poses(&x0, 1.0);
        let nbar = Vector3::new(3.0, -1.0, 2.0);
        let mbar = Vector3::new(0.5, 0.7, -0.2);
        for mid in [MidRotation::Geodesic, MidRotation::Algebraic] {
            let q = e.midpoint_force(&start, &end, &nbar, &mbar, mid);
            let xm = [(start.0[0] + end.0[0]) * 0.5, (start.0[1] + end.0[1]) * 0.5];
            let f = q.fixed_rows::<3>(0) + q.fixed_rows::<3>(6);
            let m = xm[0].cross(&q.fixed_rows::<3>(0).into_owned())
                + q.fixed_rows::<3>(3)
                + xm[1].cross(&q.fixed_rows::<3>(6).into_owned())
                + q.fixed_rows::<3>(9);
            assert!(
                f.norm() < 1e-14 * q.norm() && m.norm() < 1e-14 * q.norm(),
                "{mid:?}: {f} {m}"
            );
        }
    }

    #[test]
    fn rigid_increments_do_no_work() {
        // Increments of a rigid motion about a point c: θᵢ = θ for both nodes,
        // uᵢ = (cay(θ) − I)(xᵢ − c) + t. Self-equilibrium about x̄ makes
        // Σ pᵢ·q_k vanish exactly (for either mid rotation).
        let (e, x0) = element();
        let (start, _, _) = poses(&x0, 1.0);
        let theta = tan_scaled(&Vector3::new(0.4, -0.3, 0.9));
        let (c, t) = (Vector3::new(0.3, -0.7, 0.2), Vector3::new(0.1, 0.2, -0.4));
        let q_rot = cayley(&theta);
        let end = (
            start.0.map(|x| c + q_rot * (x - c) + t),
            start.1.map(|r| q_rot * r),
        );
        for mid in [MidRotation::Geodesic, MidRotation::Algebraic] {
            let q = e.midpoint_force(
                &start,
                &end,
                &Vector3::new(2.0, 1.0, -3.0),
                &Vector3::new(0.3, -0.4, 0.5),
                mid,
            );
            let work: f64 = (0..2)
                .map(|i| {
                    (end.0[i] - start.0[i]).dot(&q.fixed_rows::<3>(6 * i))
                        + theta.dot(&q.fixed_rows::<3>(6 * i + 3))
                })
                .sum();
            assert!(work.abs() < 1e-13 * q.norm(), "{mid:?}: work {work}");
            // And the strains, hence the resultants, are the same at both ends.
            let (n0, m0) = e.resultants(&start.0, &start.1);
            let (n1, m1) = e.resultants(&end.0, &end.1);
            assert!(
                (n0 - n1).norm() < 1e-9 * n0.norm() && (m0 - m1).norm() < 1e-9 * m0.norm().max(1.0)
            );
        }
    }

    #[test]
    fn consistent_with_the_static_force_for_small_increments() {
        // With no increment, N̄ = N and Λ̃ = Λ_r: q_k is the static internal
        // force up to the curvature terms of the exact gradient (H⁻ᵀ(φ) and
        // the moment of the reference rotation's variation), O(|φ|) here.
        let (e, x0) = element();
        let (start, _, _) = poses(&x0, 1.0);
        let (nn, mm) = e.resultants(&start.0, &start.1);
        let q = e.midpoint_force(&start, &start, &nn, &mm, MidRotation::Geodesic);
        let r = e.internal_force(&start.0, &start.1);
        // Forces agree exactly; moments to first order in the element's relative rotation.
        assert!((q.fixed_rows::<3>(0) - r.fixed_rows::<3>(0)).norm() < 1e-12 * r.norm());
        assert!((q.fixed_rows::<3>(6) - r.fixed_rows::<3>(6)).norm() < 1e-12 * r.norm());
        let phi =
            log(&((start.1[0] * e.lambda0[0]).transpose() * (start.1[1] * e.lambda0[1]))).norm();
        let diff = (q - r).norm() / r.norm();
        assert!(
            diff <= 2.0 * phi,
            "relative difference {diff} for |φ| = {phi}"
        );
        // Both variants coincide when nothing moves.
        let qa = e.midpoint_force(&start, &start, &nn, &mm, MidRotation::Algebraic);
        assert!((q - qa).norm() < 1e-12 * q.norm());
    }

    #[test]
    fn differentiable_with_automatic_differentiation() {
        // The kernel is generic: a Jacobian with respect to the end pose
        // (positions and Cayley increments) exists and matches central differences.
        use num_dual::DualSVec64;
        type D = DualSVec64<12>;
        let (e, x0) = element();
        let (start, _, _) = poses(&x0, 1.0);
        let (nn, mm) = e.resultants(&start.0, &start.1);
        let f = |u: [Vector3<f64>; 2], th: [Vector3<f64>; 2]| {
            let end = (
                [start.0[0] + u[0], start.0[1] + u[1]],
                [cayley(&th[0]) * start.1[0], cayley(&th[1]) * start.1[1]],
            );
            let (n1, m1) = e.resultants(&end.0, &end.1);
            e.midpoint_force(
                &start,
                &end,
                &((nn + n1) * 0.5),
                &((mm + m1) * 0.5),
                MidRotation::Algebraic,
            )
        };
        let s = |k: usize| D::from_re(0.0).derivative(k);
        let v = |k: usize| Vector3::new(s(k), s(k + 1), s(k + 2));
        let base = [
            Vector3::new(0.01, 0.02, -0.01),
            Vector3::new(-0.02, 0.01, 0.03),
        ];
        let tb = [
            Vector3::new(0.05, -0.02, 0.04),
            Vector3::new(0.01, 0.03, -0.05),
        ];
        let sd = (
            start.0.map(|x| x.map(D::from_re)),
            start.1.map(|r| r.map(D::from_re)),
        );
        let end = (
            [
                sd.0[0] + base[0].map(D::from_re) + v(0),
                sd.0[1] + base[1].map(D::from_re) + v(6),
            ],
            [
                cayley(&(tb[0].map(D::from_re) + v(3))) * sd.1[0],
                cayley(&(tb[1].map(D::from_re) + v(9))) * sd.1[1],
            ],
        );
        let (n1, m1) = e.resultants(&end.0, &end.1);
        let half = D::from_re(0.5);
        let q = e.midpoint_force(
            &sd,
            &end,
            &((nn.map(D::from_re) + n1) * half),
            &((mm.map(D::from_re) + m1) * half),
            MidRotation::Algebraic,
        );
        let h = 1e-6;
        for j in 0..12 {
            let (mut up, mut um, mut tp, mut tm) = (base, base, tb, tb);
            let (node, c) = (j / 6, j % 6);
            if c < 3 {
                up[node][c] += h;
                um[node][c] -= h;
            } else {
                tp[node][c - 3] += h;
                tm[node][c - 3] -= h;
            }
            let fd = (f(up, tp) - f(um, tm)) / (2.0 * h);
            let ad: SVector<f64, 12> = SVector::from_fn(|i, _| {
                q[i].eps.unwrap_generic(nalgebra::Const::<12>, nalgebra::U1)[j]
            });
            assert!((fd - ad).norm() <= 1e-6 * ad.norm().max(1.0), "column {j}");
        }
    }
}
