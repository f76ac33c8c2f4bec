//! Residual and tangent of the 2-node element through its invariant strain
//! coordinates (FORMULATION §2), as for the 3-node element
//! ([`crate::element_quadratic`]).
//!
//! With node 1's triad `Λ₁` as base, the one-point strains depend on the
//! nodal unknowns only through six material coordinates
//!
//! ```text
//! z = (φ, a),   φ = log(Λ₁ᵀΛ₂),   a = Λ₁ᵀ d,   d = x₂ − x₁
//! Γ = exp(½φ̂)ᵀ a/L − Γ₀ = Λ_rᵀ d/L − Γ₀,   K = φ/L − K₀
//! E = ½L (Γ·C_N Γ + K·C_M K)
//! ```
//!
//! nonlinear only through `A = exp(p̂)ᵀ`, `p = ½φ`.
//! With `N = C_N Γ`, `M = C_M K`, `∂ᵢ = ∂/∂pᵢ`:
//!
//! ```text
//! ∂E/∂φᵢ = ½ N·∂ᵢA a + Mᵢ,                 ∂E/∂a = AᵀN
//! ∂²E/∂φᵢ∂φⱼ = ¼ (∂ⱼA a·C_N ∂ᵢA a/L + N·∂ᵢⱼA a) + (C_M)ᵢⱼ/L
//! ∂²E/∂a∂φᵢ = ½ (∂ᵢAᵀN + AᵀC_N ∂ᵢA a/L),    ∂²E/∂a² = AᵀC_N A/L
//! ```
//!
//! The map from the increments (`x ← x + η`, `R ← exp(ε̂)R`):
//! `δφ = S(ε₂ − ε₁)`, `S = H⁻¹(φ)Λ₁ᵀ`; `δa = Λ₁ᵀ(η₂ − η₁ + d̂ ε₁)`. The
//! residual is `r = Jᵀe` and the tangent `K = Jᵀ(∂²E/∂z²)J + G`, `G` the
//! derivative of `Jᵀe` with `e` held: with `u = Sᵀe_φ`,
//! `M_φ = Λ₁ ∂(H⁻ᵀ(φ)e_φ)/∂φ S`, `b = Λ₁ e_a`,
//!
//! ```text
//! ∂r_ε₂/∂ε₁ = −û − M_φ,  ∂r_ε₂/∂ε₂ = M_φ,  ∂r_ε₁/∂ε₁ = û + M_φ + d̂ b̂,  ∂r_ε₁/∂ε₂ = −M_φ
//! ∂r_η₁/∂ε₁ = b̂,  ∂r_η₂/∂ε₁ = −b̂,  ∂r_ε₁/∂η₁ = −b̂,  ∂r_ε₁/∂η₂ = b̂
//! ```
//!
//! equal to the hyper-dual Hessian of the element energy
//! ([`BeamElement::residual_tangent_ad`], the oracle) to round-off.

use crate::element::{BeamElement, Strains};
use crate::rotation::{exp, log, tangent_inverse};
use crate::rotation_derivatives::{exp_transpose_first, tangent_inverse_transpose_derivative};
use nalgebra::{Matrix3, SMatrix, SMatrixViewMut, SVector, SVectorViewMut, Vector3};

/// The total strains `(Γ, K) = (exp(½φ̂)ᵀΛ₁ᵀd/L, φ/L)`, `φ = log(Λ₁ᵀΛ₂)`,
/// of a 2-node element with nodal triads `lam`, chord `d = x₂ − x₁` and
/// length `l` (module docs).
pub(crate) fn invariant_strains(
    lam: (&Matrix3<f64>, &Matrix3<f64>),
    d: &Vector3<f64>,
    l: f64,
) -> Strains<f64> {
    let phi = log(&(lam.0.transpose() * lam.1));
    invariant_strains_with(&phi, lam.0, d, l)
}

/// [`invariant_strains`] with `φ = log(Λ₁ᵀΛ₂)` given (the relative rotation
/// the solvers' rotation guard has just computed, the same bits).
fn invariant_strains_with(
    phi: &Vector3<f64>,
    lam1: &Matrix3<f64>,
    d: &Vector3<f64>,
    l: f64,
) -> Strains<f64> {
    (
        exp(&(phi * 0.5)).transpose() * (lam1.transpose() * d) / l,
        phi / l,
    )
}

impl BeamElement<2> {
    /// Strain energy through the invariant coordinates (module docs):
    /// `E = ½L (Γ·C_N Γ + K·C_M K)` with `Γ = exp(½φ̂)ᵀ a/L − Γ₀`,
    /// `K = φ/L − K₀` (`Γ₀`, `K₀` of the initial configuration by the same
    /// formula, so that `E` is exactly zero there) — one logarithm and one exponential, where
    /// [`BeamElement::energy`]'s interpolation takes three logarithms and two
    /// exponentials (the nodes' rotation vectors relative to the mid triad
    /// are `∓½φ`, which it computes). Equal to it to round-off; the
    /// records' strain energy (the conserving schemes' energy equations
    /// keep [`BeamElement::energy`], which their derivatives are of).
    pub fn energy_linear(&self, x: &[Vector3<f64>; 2], rot: &[Matrix3<f64>; 2]) -> f64 {
        let lam = self.nodal_triads(rot);
        let total = invariant_strains((&lam[0], &lam[1]), &(x[1] - x[0]), self.length);
        self.energy_of_strains(total)
    }

    /// [`Self::energy_linear`] with the relative rotation `φ = log(Λ₁ᵀΛ₂)`
    /// given ([`crate::Element::relative_rotations`] at the same
    /// configuration): the same value to the bit, one logarithm fewer.
    pub fn energy_linear_with(
        &self,
        phi: &Vector3<f64>,
        x: &[Vector3<f64>; 2],
        rot: &[Matrix3<f64>; 2],
    ) -> f64 {
        let lam = self.nodal_triads(rot);
        let total = invariant_strains_with(phi, &lam[0], &(x[1] - x[0]), self.length);
        self.energy_of_strains(total)
    }

    /// `½L (Γ·C_N Γ + K·C_M K)` of the total strains `total` less the
    /// initial ones.
    fn energy_of_strains(&self, total: Strains<f64>) -> f64 {
        let initial = self.initial_invariant_strains();
        let (gam, kap) = (total.0 - initial.0, total.1 - initial.1);
        let (cn, cm) = (self.section.c_n, self.section.c_m);
        0.5 * self.length * (gam.component_mul(&cn).dot(&gam) + kap.component_mul(&cm).dot(&kap))
    }

    /// Residual and consistent tangent of the 2-node element (module docs);
    /// equal to [`BeamElement::residual_tangent_ad`].
    pub fn residual_tangent_linear(
        &self,
        x: &[Vector3<f64>; 2],
        rot: &[Matrix3<f64>; 2],
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        let (mut r, mut k) = (SVector::<f64, 12>::zeros(), SMatrix::<f64, 12, 12>::zeros());
        self.residual_tangent_linear_into(x, rot, r.as_view_mut(), k.as_view_mut());
        (r, k)
    }

    /// [`BeamElement::residual_tangent_linear`] written into `r` and `k`
    /// (every entry; views of an assembler's buffers, so that the 144
    /// entries are not returned and then copied).
    pub fn residual_tangent_linear_into(
        &self,
        x: &[Vector3<f64>; 2],
        rot: &[Matrix3<f64>; 2],
        mut r: SVectorViewMut<f64, 12>,
        mut k: SMatrixViewMut<f64, 12, 12>,
    ) {
        let lam = self.nodal_triads(rot);
        let l = self.length;
        let lt = lam[0].transpose();
        let phi = log(&(lt * lam[1]));
        let d = x[1] - x[0];
        let a = lt * d;
        let ad = exp_transpose_first(&(phi * 0.5));
        let (am, da) = (ad.value, ad.d1);
        let (g0, k0) = self.initial_strains()[0];
        // The section's diagonal stiffnesses as products by entries (a
        // product by the diagonal matrix adds only zeros to the same ones).
        let (cn, cm) = (self.section.c_n, self.section.c_m);
        let n = (am * a / l - g0).component_mul(&cn);
        let m = (phi / l - k0).component_mul(&cm);
        let aa: [Vector3<f64>; 3] = std::array::from_fn(|i| da[i] * a);
        let cn_aa: [Vector3<f64>; 3] = std::array::from_fn(|i| aa[i].component_mul(&cn));
        // N·∂ᵢⱼA a, the only use of A's second derivatives.
        let n_dda = ad.bilinear_hessian(&n, &a);
        // e = ∂E/∂z and the blocks of ∂²E/∂z² in z = (φ, a).
        let mut e_phi = Vector3::zeros();
        let mut h_pp = Matrix3::zeros();
        let mut h_pa = Matrix3::zeros();
        for i in 0..3 {
            e_phi[i] = 0.5 * n.dot(&aa[i]) + m[i];
            for j in 0..3 {
                h_pp[(i, j)] = 0.25 * (aa[j].dot(&cn_aa[i]) / l + n_dda[(i, j)]);
            }
            h_pp[(i, i)] += cm[i] / l;
            let phi_a = (da[i].transpose() * n + am.transpose() * cn_aa[i] / l) * 0.5;
            h_pa.set_row(i, &phi_a.transpose());
        }
        let ea = am.transpose() * n;
        // (Aᵀ C_N) A: Aᵀ with its columns scaled, times A.
        let h_aa = Matrix3::from_fn(|r, c| am[(c, r)] * cn[c]) * am / l;
        // J = ∂z/∂(η₁, ε₁, η₂, ε₂) has the column blocks
        // c₁ = −P, c₂ = −Q + P d̂, c₃ = P, c₄ = Q with P = (0; Λ₁ᵀ),
        // Q = (S; 0): Jᵀ(∂²E/∂z²)J from the four products of P and Q
        // (d̂ᵀ = −d̂), in 3 × 3 blocks.
        let s = tangent_inverse(&phi) * lt;
        let dh = d.cross_matrix();
        let pp = lam[0] * h_aa * lt;
        let qq = s.transpose() * h_pp * s;
        let qp = s.transpose() * h_pa * lt;
        let pq = qp.transpose();
        let (pp_d, qp_d, d_pp, d_pq) = (pp * dh, qp * dh, dh * pp, dh * pq);
        let k21 = pp_d - pq; // c₃ᵀHc₂
        let k41 = qp_d - qq; // c₄ᵀHc₂
        let k12 = -qp - d_pp; // c₂ᵀHc₃
        let k14 = -qq - d_pq; // c₂ᵀHc₄
        let k11 = qq - qp_d + d_pq - d_pp * dh; // c₂ᵀHc₂
        let blocks = [
            [pp, -k21, -pp, -pq],
            [-k12, k11, k12, k14],
            [-pp, k21, pp, pq],
            [-qp, k41, qp, qq],
        ];
        // The sixteen blocks cover the whole of k.
        for (a, row) in blocks.iter().enumerate() {
            for (b, blk) in row.iter().enumerate() {
                k.fixed_view_mut::<3, 3>(3 * a, 3 * b).copy_from(blk);
            }
        }
        // r = Jᵀe.
        let u = s.transpose() * e_phi;
        let b = lam[0] * ea;
        r.fixed_rows_mut::<3>(0).copy_from(&(-b));
        r.fixed_rows_mut::<3>(3).copy_from(&(-u - dh * b));
        r.fixed_rows_mut::<3>(6).copy_from(&b);
        r.fixed_rows_mut::<3>(9).copy_from(&u);
        // G: the derivative of Jᵀe with e held.
        let mphi = lam[0] * tangent_inverse_transpose_derivative(&phi, &e_phi) * s;
        let b_hat = b.cross_matrix();
        let mut add = |row: usize, col: usize, blk: Matrix3<f64>| {
            let mut v = k.fixed_view_mut::<3, 3>(row, col);
            v += blk;
        };
        add(9, 3, -u.cross_matrix() - mphi);
        add(9, 9, mphi);
        add(3, 3, u.cross_matrix() + mphi + dh * b_hat);
        add(3, 9, -mphi);
        add(0, 3, b_hat);
        add(6, 3, -b_hat);
        add(3, 0, -b_hat);
        add(3, 6, b_hat);
    }
}

#[cfg(test)]
mod tests {
    use crate::element::BeamElement;
    use crate::rotation::exp;
    use crate::section::Section;
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    /// Both sides are exact: only round-off separates them.
    const ORACLE_TOL: f64 = 1e-10;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn residual_and_tangent_equal_the_hyper_dual_oracle(
            du in prop::array::uniform6(-0.3..0.3f64),
            dr in prop::array::uniform6(-1.2..1.2f64),
            rigid in prop::array::uniform3(-2.5..2.5f64),
        ) {
            let sec = Section::new([2.0e4, 8.0e3, 9.0e3], [30.0, 45.0, 60.0], 1.0, [0.2, 0.1, 0.1]);
            let x0 = [Vector3::new(0.1, 0.2, -0.3), Vector3::new(1.2, 0.6, -0.1)];
            // Curved initial geometry: different initial triads at the nodes.
            let l0 = [exp(&Vector3::new(0.1, 0.2, 0.3)), exp(&Vector3::new(-0.2, 0.4, 0.1))];
            let e = BeamElement::new([0, 1], sec, (x0[1] - x0[0]).norm(), &x0, l0);
            let q = exp(&Vector3::from(rigid));
            let x: [Vector3<f64>; 2] = std::array::from_fn(|i| {
                q * (x0[i] + Vector3::new(du[3 * i], du[3 * i + 1], du[3 * i + 2]))
            });
            let rot: [Matrix3<f64>; 2] = std::array::from_fn(|i| {
                q * exp(&Vector3::new(dr[3 * i], dr[3 * i + 1], dr[3 * i + 2]))
            });
            let (r_ad, k_ad) = e.residual_tangent_ad::<12>(&x, &rot);
            let (r, k) = e.residual_tangent_linear(&x, &rot);
            let rel = |err: f64, size: f64| err / size.max(1.0);
            prop_assert!(rel((r - r_ad).norm(), r_ad.norm()) <= ORACLE_TOL, "residual");
            prop_assert!(rel((k - k_ad).norm(), k_ad.norm()) <= ORACLE_TOL, "tangent {}", (k - k_ad).norm());
            // And the closed-form internal force.
            prop_assert!(rel((e.internal_force(&x, &rot) - r).norm(), r.norm()) <= ORACLE_TOL);
        }
    }
}
