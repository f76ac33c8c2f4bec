//! Residual and tangent of the 3-node element through its invariant strain
//! coordinates (FORMULATION §2).
//!
//! With the middle node's triad as reference (`Λ_r = Λ₁`), the strains at
//! Gauss point `g` depend on the nodal unknowns only through twelve material
//! (hence objective) coordinates
//!
//! ```text
//! z = (ψ₀, ψ₂, a₀, a₁),   ψₖ = log(Λ₁ᵀΛₖ),   a_g = Λ₁ᵀ r′(ξ_g)
//! Γ_g = exp(p̂_g)ᵀ a_g − Γ₀,   K_g = Hᵀ(p_g) p′_g − K₀,   p = Σ Iₖ ψₖ
//! ```
//!
//! so `E = Σ_g E_g(ψ₀, ψ₂, a_g)`, whose strains are linear in `a_g` and
//! `p′` and nonlinear only in `p` (three hyper-dual lanes give `exp(p̂)` and
//! `H(p)` with their first and second derivatives; the product rule the rest
//! of `∂E/∂z` and `∂²E/∂z²`); the map from the nodal increments (`x ← x + η`,
//! `R ← exp(ε̂)R`) to `z` is closed form,
//!
//! ```text
//! δψₖ = Sₖ (εₖ − ε₁),  Sₖ = H⁻¹(ψₖ)Λ₁ᵀ;    δa_g = Λ₁ᵀ(Σₖ I′ₖ(ξ_g) ηₖ + r̂′_g ε₁)
//! ```
//!
//! and the residual is `r = Jᵀe` (`J = ∂z/∂(η, ε)`, `e = ∂E/∂z`). Its
//! derivative under the same increments is `K = Jᵀ (∂²E/∂z²) J + G`, where
//! `G` differentiates `Jᵀe` with `e` held: with `uₖ = Sₖᵀ e_ψₖ`,
//! `Mₖ = Λ₁ ∂(H⁻ᵀ(ψ)e_ψₖ)/∂ψ Sₖ` and `b_g = Λ₁ e_a_g`,
//!
//! ```text
//! ∂r_εₖ/∂ε₁ = −ûₖ − Mₖ,  ∂r_εₖ/∂εₖ = Mₖ,  ∂r_ε₁/∂ε₁ = ûₖ + Mₖ,  ∂r_ε₁/∂εₖ = −Mₖ   (k = 0, 2)
//! ∂r_ηₖ/∂ε₁ = −I′ₖ b̂_g,   ∂r_ε₁/∂ε₁ = r̂′_g b̂_g,   ∂r_ε₁/∂ηₖ = I′ₖ b̂_g             (each g)
//! ```
//!
//! equal to the hyper-dual Hessian of the whole element energy
//! ([`BeamElement::residual_tangent_ad`], the oracle) to round-off, at a
//! small fraction of its cost.

use crate::element::BeamElement;
use crate::rotation::{log, tangent_inverse};
use crate::rotation_derivatives::{
    exp_transpose_first, tangent_inverse_transpose_derivative, tangent_transpose_first,
};
use crate::shape::{lagrange, reduced_gauss};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// The element's invariant coordinates and the closed-form pieces of their
/// Jacobian.
struct Coordinates {
    /// Middle node's triad `Λ₁`.
    lam1: Matrix3<f64>,
    /// `ψ₀`, `ψ₂`.
    psi: [Vector3<f64>; 2],
    /// `r′` at the Gauss points.
    dr: [Vector3<f64>; 2],
    /// `I′ₖ(ξ_g)·2/L`: the weights of the nodes in `r′_g`.
    dshape: [[f64; 3]; 2],
}

impl BeamElement<3> {
    fn coordinates(&self, x: &[Vector3<f64>; 3], rot: &[Matrix3<f64>; 3]) -> Coordinates {
        let lam = self.nodal_triads(rot);
        let ds = 2.0 / self.length;
        let gauss = reduced_gauss(3);
        let dshape: [[f64; 3]; 2] = std::array::from_fn(|g| {
            let (_, d) = lagrange(3, gauss[g].0);
            [d[0] * ds, d[1] * ds, d[2] * ds]
        });
        Coordinates {
            psi: [
                log(&(lam[1].transpose() * lam[0])),
                log(&(lam[1].transpose() * lam[2])),
            ],
            dr: dshape.map(|d| x[0] * d[0] + x[1] * d[1] + x[2] * d[2]),
            lam1: lam[1],
            dshape,
        }
    }

    /// Gradient and Hessian of Gauss point `g`'s strain energy
    /// `E_g = c (Γ·C_N Γ + K·C_M K)`, `c = w_g L/4`, in `(ψ₀, ψ₂, a_g)`.
    /// `Γ = A(p) a − Γ₀`, `K = B(p) p′ − K₀` with `A = exp(p̂)ᵀ`, `B = Hᵀ(p)`
    /// are linear in `a` and `p′` and nonlinear in `p` only, so AD runs over
    /// the three components of `p` (hyper-duals for `∂A`, `∂²A`, `∂B`, `∂²B`)
    /// and the rest is the product rule; `p = I₀ψ₀ + I₂ψ₂` and
    /// `p′ = I′₀ψ₀ + I′₂ψ₂` are linear.
    fn gauss_terms(
        &self,
        g: usize,
        psi: &[Vector3<f64>; 2],
        a: &Vector3<f64>,
    ) -> (SVector<f64, 9>, SMatrix<f64, 9, 9>) {
        let (xi, w) = reduced_gauss(3)[g];
        let (v, d) = lagrange(3, xi);
        let ds = 2.0 / self.length;
        let p = psi[0] * v[0] + psi[1] * v[2];
        let dp = (psi[0] * d[0] + psi[1] * d[2]) * ds;
        let ad = exp_transpose_first(&p);
        let bd = tangent_transpose_first(&p);
        let (am, da) = (ad.value, ad.d1);
        let (bm, db) = (bd.value, bd.d1);
        let (g0, k0) = self.initial_strains()[g];
        let (cn, cm) = (
            Matrix3::from_diagonal(&self.section.c_n),
            Matrix3::from_diagonal(&self.section.c_m),
        );
        let c2 = 2.0 * 0.25 * w * self.length;
        let n = cn * (am * a - g0);
        let m = cm * (bm * dp - k0);
        let aa: [Vector3<f64>; 3] = std::array::from_fn(|i| da[i] * a);
        let bp: [Vector3<f64>; 3] = std::array::from_fn(|i| db[i] * dp);
        // N·∂ᵢⱼA a and M·∂ᵢⱼBᵀ p′, the only uses of second derivatives.
        let (n_dda, m_ddb) = (ad.bilinear_hessian(&n, a), bd.bilinear_hessian(&m, &dp));
        // Gradient and Hessian in (p, p′, a).
        let mut grad = SVector::<f64, 9>::zeros();
        let mut hess = SMatrix::<f64, 9, 9>::zeros();
        for i in 0..3 {
            grad[i] = c2 * (n.dot(&aa[i]) + m.dot(&bp[i]));
            for j in 0..3 {
                hess[(i, j)] = c2
                    * (aa[j].dot(&(cn * aa[i]))
                        + n_dda[(i, j)]
                        + bp[j].dot(&(cm * bp[i]))
                        + m_ddb[(i, j)]);
            }
            let p_dp = (db[i].transpose() * m + bm.transpose() * (cm * bp[i])) * c2;
            let p_a = (da[i].transpose() * n + am.transpose() * (cn * aa[i])) * c2;
            for k in 0..3 {
                hess[(i, 3 + k)] = p_dp[k];
                hess[(3 + k, i)] = p_dp[k];
                hess[(i, 6 + k)] = p_a[k];
                hess[(6 + k, i)] = p_a[k];
            }
        }
        grad.fixed_rows_mut::<3>(3)
            .copy_from(&(bm.transpose() * m * c2));
        grad.fixed_rows_mut::<3>(6)
            .copy_from(&(am.transpose() * n * c2));
        hess.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(bm.transpose() * cm * bm * c2));
        hess.fixed_view_mut::<3, 3>(6, 6)
            .copy_from(&(am.transpose() * cn * am * c2));
        // To (ψ₀, ψ₂, a): p = I₀ψ₀ + I₂ψ₂, p′ = I′₀ψ₀ + I′₂ψ₂.
        let id = Matrix3::<f64>::identity();
        let mut map = SMatrix::<f64, 9, 9>::zeros();
        map.fixed_view_mut::<3, 3>(0, 0).copy_from(&(id * v[0]));
        map.fixed_view_mut::<3, 3>(0, 3).copy_from(&(id * v[2]));
        map.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(id * (d[0] * ds)));
        map.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(id * (d[2] * ds)));
        map.fixed_view_mut::<3, 3>(6, 6).copy_from(&id);
        (map.transpose() * grad, map.transpose() * hess * map)
    }

    /// `J = ∂z/∂(η₀, ε₀, η₁, ε₁, η₂, ε₂)` (12 × 18) and `S₀`, `S₂`.
    fn coordinate_jacobian(&self, c: &Coordinates) -> (SMatrix<f64, 12, 18>, [Matrix3<f64>; 2]) {
        let lt = c.lam1.transpose();
        let s = c.psi.map(|p| tangent_inverse(&p) * lt);
        let mut j = SMatrix::<f64, 12, 18>::zeros();
        for (k, node) in [(0, 0), (1, 2)] {
            j.fixed_view_mut::<3, 3>(3 * k, 6 * node + 3)
                .copy_from(&s[k]);
            j.fixed_view_mut::<3, 3>(3 * k, 9).copy_from(&(-s[k]));
        }
        for g in 0..2 {
            for node in 0..3 {
                j.fixed_view_mut::<3, 3>(6 + 3 * g, 6 * node)
                    .copy_from(&(lt * c.dshape[g][node]));
            }
            let mut rows = j.fixed_view_mut::<3, 3>(6 + 3 * g, 9);
            rows += lt * c.dr[g].cross_matrix();
        }
        (j, s)
    }

    /// `e = ∂E/∂z` and `∂²E/∂z²` from the Gauss points' terms.
    fn energy_derivatives_z(&self, c: &Coordinates) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        let mut e = SVector::<f64, 12>::zeros();
        let mut hess = SMatrix::<f64, 12, 12>::zeros();
        for g in 0..2 {
            let a = c.lam1.transpose() * c.dr[g];
            let (grad, h) = self.gauss_terms(g, &c.psi, &a);
            // z indices of this Gauss point's (ψ₀, ψ₂, a_g).
            let at = |i: usize| if i < 6 { i } else { 6 + 3 * g + (i - 6) };
            for i in 0..9 {
                e[at(i)] += grad[i];
                for j in 0..9 {
                    hess[(at(i), at(j))] += h[(i, j)];
                }
            }
        }
        (e, hess)
    }

    /// The internal force (the gradient of [`BeamElement::energy`] under
    /// nodal increments), `r = Jᵀe` (module docs).
    pub fn internal_force_quadratic(
        &self,
        x: &[Vector3<f64>; 3],
        rot: &[Matrix3<f64>; 3],
    ) -> SVector<f64, 18> {
        let c = self.coordinates(x, rot);
        let (j, _) = self.coordinate_jacobian(&c);
        j.transpose() * self.energy_derivatives_z(&c).0
    }

    /// Residual and consistent tangent, `K = Jᵀ(∂²E/∂z²)J + G` (module docs);
    /// equal to [`BeamElement::residual_tangent_ad`].
    pub fn residual_tangent_quadratic(
        &self,
        x: &[Vector3<f64>; 3],
        rot: &[Matrix3<f64>; 3],
    ) -> (SVector<f64, 18>, SMatrix<f64, 18, 18>) {
        let c = self.coordinates(x, rot);
        let (j, s) = self.coordinate_jacobian(&c);
        let (e, hess) = self.energy_derivatives_z(&c);
        let r = j.transpose() * e;
        let mut k = j.transpose() * hess * j;
        // G: the derivative of Jᵀe with e held.
        let mid = 9;
        for (kk, node) in [(0usize, 0usize), (1, 2)] {
            let ek = Vector3::new(e[3 * kk], e[3 * kk + 1], e[3 * kk + 2]);
            let u = s[kk].transpose() * ek;
            let dd = tangent_inverse_transpose_derivative(&c.psi[kk], &ek);
            let m = c.lam1 * dd * s[kk];
            let col = 6 * node + 3;
            let mut add = |row: usize, col: usize, b: Matrix3<f64>| {
                let mut v = k.fixed_view_mut::<3, 3>(row, col);
                v += b;
            };
            add(col, mid, -u.cross_matrix() - m);
            add(col, col, m);
            add(mid, mid, u.cross_matrix() + m);
            add(mid, col, -m);
        }
        for g in 0..2 {
            let eg = Vector3::new(e[6 + 3 * g], e[7 + 3 * g], e[8 + 3 * g]);
            let b_hat = (c.lam1 * eg).cross_matrix();
            for node in 0..3 {
                let w = c.dshape[g][node];
                let mut v = k.fixed_view_mut::<3, 3>(6 * node, mid);
                v -= b_hat * w;
                let mut v = k.fixed_view_mut::<3, 3>(mid, 6 * node);
                v += b_hat * w;
            }
            let mut v = k.fixed_view_mut::<3, 3>(mid, mid);
            v += c.dr[g].cross_matrix() * b_hat;
        }
        (r, k)
    }
}

#[cfg(test)]
#[path = "element_quadratic_tests.rs"]
mod tests;
