//! First and second derivatives of the rotation maps the element kernels
//! chain through. `exp(p̂)ᵀ` and `Hᵀ(p)` are both `I + α(t) p̂ + β(t) p̂²`
//! with `t = |p|²`; their derivatives are written out in closed form from
//! `α, β` and their first two derivatives in `t` (one scalar second-order
//! dual number through the Rodrigues coefficients). The three-lane
//! hyper-dual evaluation of the whole matrix stays as the oracle in the
//! tests. `∂(H⁻ᵀv)/∂ψ` likewise, from `D(t)` of [`tangent_inverse`](crate::rotation::tangent_inverse) and
//! its derivative (one scalar dual number); its three-lane forward AD is the
//! oracle.

use crate::rotation::{rodrigues_coefficients, skew, skew_squared, tangent_inverse_coefficient};
use nalgebra::{Matrix3, Vector3};
use num_dual::{Dual2, Dual64};

/// A 3 × 3 matrix function of `p` with its derivatives: value,
/// `∂M/∂pᵢ` and `∂²M/∂pᵢ∂pⱼ`.
pub struct MatrixDerivatives {
    /// `M(p)`.
    pub value: Matrix3<f64>,
    /// `∂M/∂pᵢ`, `i = 0..3`.
    pub d1: [Matrix3<f64>; 3],
    /// `∂²M/∂pᵢ∂pⱼ`.
    pub d2: [[Matrix3<f64>; 3]; 3],
}

/// A scalar function of `t = |p|²` with its first and second derivatives.
#[derive(Clone, Copy)]
pub(crate) struct Coefficient {
    pub(crate) value: f64,
    pub(crate) d1: f64,
    pub(crate) d2: f64,
}

impl From<Dual2<f64>> for Coefficient {
    fn from(x: Dual2<f64>) -> Self {
        Self {
            value: x.re,
            d1: x.v1,
            d2: x.v2,
        }
    }
}

/// The Rodrigues coefficients `(sin ψ/ψ, (1 − cos ψ)/ψ², (ψ − sin ψ)/ψ³)`
/// with their derivatives in `t = ψ²`.
pub(crate) fn coefficients(t: f64) -> [Coefficient; 3] {
    let (a, b, c) = rodrigues_coefficients(Dual2::new(t, 1.0, 0.0));
    [a.into(), b.into(), c.into()]
}

/// `M(p) = I + α(t) p̂ + β(t) p̂²`, `t = |p|²`, with
///
/// ```text
/// ∂ᵢM  = 2α′pᵢ p̂ + α êᵢ + 2β′pᵢ p̂² + β ∂ᵢ(p̂²)
/// ∂ᵢⱼM = (4α″pᵢpⱼ + 2α′δᵢⱼ) p̂ + 2α′(pᵢêⱼ + pⱼêᵢ)
///      + (4β″pᵢpⱼ + 2β′δᵢⱼ) p̂² + 2β′(pᵢ∂ⱼ(p̂²) + pⱼ∂ᵢ(p̂²)) + β ∂ᵢⱼ(p̂²)
/// ```
///
/// where `p̂² = ppᵀ − tI`, `∂ᵢ(p̂²) = eᵢpᵀ + peᵢᵀ − 2pᵢI`,
/// `∂ᵢⱼ(p̂²) = eᵢeⱼᵀ + eⱼeᵢᵀ − 2δᵢⱼI`.
fn quadratic_in_skew(p: &Vector3<f64>, alpha: Coefficient, beta: Coefficient) -> MatrixDerivatives {
    let first = quadratic_in_skew_first(p, alpha, beta);
    let (s, q) = (skew(p), skew_squared(p));
    let (e_hat, dq) = (unit_skews(), skew_squared_derivatives(p));
    let mut d2 = [[Matrix3::zeros(); 3]; 3];
    for i in 0..3 {
        for j in i..3 {
            let delta = if i == j { 1.0 } else { 0.0 };
            let ddq = Matrix3::from_fn(|r, c| {
                let mut v = if r == i && c == j { 1.0 } else { 0.0 }
                    + if r == j && c == i { 1.0 } else { 0.0 };
                if r == c {
                    v -= 2.0 * delta;
                }
                v
            });
            let pij = p[i] * p[j];
            let m = s * (4.0 * alpha.d2 * pij + 2.0 * alpha.d1 * delta)
                + (e_hat[j] * p[i] + e_hat[i] * p[j]) * (2.0 * alpha.d1)
                + q * (4.0 * beta.d2 * pij + 2.0 * beta.d1 * delta)
                + (dq[j] * p[i] + dq[i] * p[j]) * (2.0 * beta.d1)
                + ddq * beta.value;
            d2[i][j] = m;
            d2[j][i] = m;
        }
    }
    MatrixDerivatives {
        value: first.value,
        d1: first.d1,
        d2,
    }
}

/// `êᵢ`, the skew matrices of the unit vectors.
fn unit_skews() -> [Matrix3<f64>; 3] {
    std::array::from_fn(|i| skew(&Vector3::from_fn(|k, _| if k == i { 1.0 } else { 0.0 })))
}

/// `∂ᵢ(p̂²) = eᵢpᵀ + peᵢᵀ − 2pᵢI`.
fn skew_squared_derivatives(p: &Vector3<f64>) -> [Matrix3<f64>; 3] {
    std::array::from_fn(|i| {
        Matrix3::from_fn(|r, c| {
            let mut v = if r == i { p[c] } else { 0.0 } + if c == i { p[r] } else { 0.0 };
            if r == c {
                v -= 2.0 * p[i];
            }
            v
        })
    })
}

/// The first-order part of [`quadratic_in_skew`]: `M(p)` and `∂ᵢM`, with
/// what [`SkewQuadratic::bilinear_hessian`] needs for second derivatives.
fn quadratic_in_skew_first(
    p: &Vector3<f64>,
    alpha: Coefficient,
    beta: Coefficient,
) -> SkewQuadratic {
    let s = skew(p);
    let q = skew_squared(p);
    let (e_hat, dq) = (unit_skews(), skew_squared_derivatives(p));
    let d1: [Matrix3<f64>; 3] = std::array::from_fn(|i| {
        s * (2.0 * alpha.d1 * p[i])
            + e_hat[i] * alpha.value
            + q * (2.0 * beta.d1 * p[i])
            + dq[i] * beta.value
    });
    SkewQuadratic {
        value: Matrix3::identity() + s * alpha.value + q * beta.value,
        d1,
        p: *p,
        alpha,
        beta,
    }
}

/// `M(p) = I + α(t) p̂ + β(t) p̂²` with its first derivatives; second
/// derivatives as the Hessians of bilinear forms `uᵀM(p)w` only (three
/// numbers each instead of the 81 of [`MatrixDerivatives::d2`]).
pub struct SkewQuadratic {
    /// `M(p)`.
    pub value: Matrix3<f64>,
    /// `∂M/∂pᵢ`, `i = 0..3`.
    pub d1: [Matrix3<f64>; 3],
    p: Vector3<f64>,
    alpha: Coefficient,
    beta: Coefficient,
}

impl SkewQuadratic {
    /// `∂²(uᵀM(p)w)/∂p²`: with `c = w × u`, `s₁ = p·c` (`= uᵀp̂w`),
    /// `s₂ = (u·p)(p·w) − t (u·w)` (`= uᵀp̂²w`), `g = ∇s₂ = u(p·w) + w(u·p) − 2(u·w)p`,
    ///
    /// ```text
    /// ∇²(uᵀMw) = 4(α″s₁ + β″s₂) ppᵀ + 2(α′s₁ + β′s₂) I
    ///          + 2α′(pcᵀ + cpᵀ) + 2β′(pgᵀ + gpᵀ) + β(uwᵀ + wuᵀ − 2(u·w) I)
    /// ```
    pub fn bilinear_hessian(&self, u: &Vector3<f64>, w: &Vector3<f64>) -> Matrix3<f64> {
        let (p, a, b) = (&self.p, &self.alpha, &self.beta);
        let c = w.cross(u);
        let (up, pw, uw) = (u.dot(p), p.dot(w), u.dot(w));
        let s1 = p.dot(&c);
        let s2 = up * pw - p.norm_squared() * uw;
        let g = u * pw + w * up - p * (2.0 * uw);
        let pc = p * c.transpose();
        let pg = p * g.transpose();
        let uwt = u * w.transpose();
        p * p.transpose() * (4.0 * (a.d2 * s1 + b.d2 * s2))
            + Matrix3::identity() * (2.0 * (a.d1 * s1 + b.d1 * s2) - 2.0 * b.value * uw)
            + (pc + pc.transpose()) * (2.0 * a.d1)
            + (pg + pg.transpose()) * (2.0 * b.d1)
            + (uwt + uwt.transpose()) * b.value
    }
}

/// Negates a coefficient (`p̂ᵀ = −p̂`).
fn negated(c: Coefficient) -> Coefficient {
    Coefficient {
        value: -c.value,
        d1: -c.d1,
        d2: -c.d2,
    }
}

/// `exp(p̂)ᵀ = I − a p̂ + b p̂²` and its first and second derivatives in `p`.
pub fn exp_transpose(p: &Vector3<f64>) -> MatrixDerivatives {
    let [a, b, _] = coefficients(p.norm_squared());
    quadratic_in_skew(p, negated(a), b)
}

/// `exp(p̂)ᵀ` and its first derivatives; second derivatives through
/// [`SkewQuadratic::bilinear_hessian`].
pub fn exp_transpose_first(p: &Vector3<f64>) -> SkewQuadratic {
    let [a, b, _] = coefficients(p.norm_squared());
    quadratic_in_skew_first(p, negated(a), b)
}

/// `Hᵀ(p)` and its first derivatives; second derivatives through
/// [`SkewQuadratic::bilinear_hessian`].
pub fn tangent_transpose_first(p: &Vector3<f64>) -> SkewQuadratic {
    let [_, b, c] = coefficients(p.norm_squared());
    quadratic_in_skew_first(p, negated(b), c)
}

/// `Hᵀ(p) = I − b p̂ + c p̂²` ([`crate::rotation::tangent`]) and its first
/// and second derivatives in `p`.
pub fn tangent_transpose(p: &Vector3<f64>) -> MatrixDerivatives {
    let [_, b, c] = coefficients(p.norm_squared());
    quadratic_in_skew(p, negated(b), c)
}

/// `∂(H⁻ᵀ(ψ) v)/∂ψ` (`H⁻ᵀ(ψ) = H⁻¹(−ψ) = I + ½ψ̂ + D(t) ψ̂²`,
/// `t = |ψ|²`): with `w = ψ̂²v = ψ(ψ·v) − t v`,
///
/// ```text
/// ∂(H⁻ᵀv)/∂ψ = −½ v̂ + 2D′(t) w ψᵀ + D(t) ((ψ·v) I + ψ vᵀ − 2 v ψᵀ)
/// ```
pub fn tangent_inverse_transpose_derivative(psi: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
    let t = psi.norm_squared();
    let d = tangent_inverse_coefficient(Dual64::new(t, 1.0));
    let (dv, dd) = (d.re, d.eps);
    let pv = psi.dot(v);
    let w = psi * pv - v * t;
    -skew(v) * 0.5
        + w * psi.transpose() * (2.0 * dd)
        + (Matrix3::identity() * pv + psi * v.transpose() - v * psi.transpose() * 2.0) * dv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp, tangent, tangent_inverse};
    use nalgebra::{Const, U1};
    use num_dual::{DualSVec64, HyperDualSVec64};

    /// Both sides are exact: only round-off separates them.
    const ORACLE_TOL: f64 = 1e-12;

    type H3 = HyperDualSVec64<3, 3>;

    /// The oracle of [`tangent_inverse_transpose_derivative`]: three-lane
    /// forward AD of `H⁻¹(−ψ) v`.
    fn tangent_inverse_transpose_derivative_ad(
        psi: &Vector3<f64>,
        v: &Vector3<f64>,
    ) -> Matrix3<f64> {
        type D = DualSVec64<3>;
        let p = Vector3::from_fn(|i, _| D::from_re(psi[i]).derivative(i));
        let w = tangent_inverse(&(-p)) * v.map(D::from_re);
        let mut m = Matrix3::zeros();
        for i in 0..3 {
            m.set_row(i, &w[i].eps.unwrap_generic(Const::<3>, U1).transpose());
        }
        m
    }

    /// The oracle: the whole matrix function over three-lane hyper-duals.
    fn by_ad(m: Matrix3<H3>) -> MatrixDerivatives {
        let mut d1 = [Matrix3::zeros(); 3];
        let mut d2 = [[Matrix3::zeros(); 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                let x = &m[(r, c)];
                let e1 = x.eps1.unwrap_generic(Const::<3>, U1);
                let e12 = x.eps1eps2.unwrap_generic(Const::<3>, Const::<3>);
                for i in 0..3 {
                    d1[i][(r, c)] = e1[i];
                    for j in 0..3 {
                        d2[i][j][(r, c)] = e12[(i, j)];
                    }
                }
            }
        }
        MatrixDerivatives {
            value: m.map(|x| x.re),
            d1,
            d2,
        }
    }

    fn seeded(p: &Vector3<f64>) -> Vector3<H3> {
        Vector3::from_fn(|i, _| H3::from_re(p[i]).derivative1(i).derivative2(i))
    }

    fn distance(a: &MatrixDerivatives, b: &MatrixDerivatives) -> f64 {
        let mut d = (a.value - b.value).norm();
        for i in 0..3 {
            d = d.max((a.d1[i] - b.d1[i]).norm());
            for j in 0..3 {
                d = d.max((a.d2[i][j] - b.d2[i][j]).norm());
            }
        }
        d
    }

    #[test]
    fn closed_forms_equal_the_hyper_dual_oracle_at_every_angle() {
        // Through the series branch (tiny angles), its limit and large angles.
        for scale in [0.0, 1e-9, 1e-4, 3e-3, 0.05, 0.4, 1.0, 2.5, 3.1] {
            for dir in [
                Vector3::new(0.3, -0.8, 0.52),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(-0.2, 0.1, 0.97),
            ] {
                let p = dir.normalize() * scale;
                let e = distance(&exp_transpose(&p), &by_ad(exp(&seeded(&p)).transpose()));
                let h = distance(
                    &tangent_transpose(&p),
                    &by_ad(tangent(&seeded(&p)).transpose()),
                );
                assert!(
                    e <= ORACLE_TOL && h <= ORACLE_TOL,
                    "|p| = {scale}: {e:e}, {h:e}"
                );
                // The bilinear Hessian against the oracle's second derivatives.
                let (u, w) = (Vector3::new(0.7, -1.3, 0.4), Vector3::new(-0.2, 0.9, 1.6));
                for (first, full) in [
                    (exp_transpose_first(&p), by_ad(exp(&seeded(&p)).transpose())),
                    (
                        tangent_transpose_first(&p),
                        by_ad(tangent(&seeded(&p)).transpose()),
                    ),
                ] {
                    let hess = Matrix3::from_fn(|i, j| u.dot(&(full.d2[i][j] * w)));
                    let bh = (first.bilinear_hessian(&u, &w) - hess).norm();
                    let d1 = (0..3).fold(0.0f64, |m, i| m.max((first.d1[i] - full.d1[i]).norm()));
                    let d0 = (first.value - full.value).norm();
                    assert!(
                        bh <= ORACLE_TOL && d1 <= ORACLE_TOL && d0 <= ORACLE_TOL,
                        "|p| = {scale}: {bh:e} {d1:e} {d0:e}"
                    );
                }
                // ∂(H⁻ᵀv)/∂ψ up to |ψ| = 2·3.1 (H⁻¹ holds below 2π).
                let (psi, v) = (p * 2.0, Vector3::new(1.0, 2.0, -0.5));
                let oracle = tangent_inverse_transpose_derivative_ad(&psi, &v);
                let g = (tangent_inverse_transpose_derivative(&psi, &v) - oracle).norm();
                assert!(
                    g <= ORACLE_TOL * oracle.norm().max(1.0),
                    "|ψ| = {}: {g:e}",
                    2.0 * scale
                );
            }
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        let p = Vector3::new(0.4, -0.9, 0.3);
        let h = 1e-5;
        for (f, name) in [
            (
                exp_transpose as fn(&Vector3<f64>) -> MatrixDerivatives,
                "exp",
            ),
            (tangent_transpose, "tangent"),
        ] {
            let m = f(&p);
            for i in 0..3 {
                let e = Vector3::from_fn(|k, _| if k == i { h } else { 0.0 });
                let (mp, mm) = (f(&(p + e)), f(&(p - e)));
                let d1 = (mp.value - mm.value) / (2.0 * h);
                assert!((d1 - m.d1[i]).norm() < 1e-8, "{name} d1 {i}");
                for j in 0..3 {
                    let d2 = (mp.d1[j] - mm.d1[j]) / (2.0 * h);
                    assert!((d2 - m.d2[i][j]).norm() < 1e-8, "{name} d2 {i}{j}");
                }
            }
        }
        let v = Vector3::new(1.0, 2.0, -0.5);
        let d = tangent_inverse_transpose_derivative(&p, &v);
        let oracle = tangent_inverse_transpose_derivative_ad(&p, &v);
        assert!((d - oracle).norm() <= ORACLE_TOL * oracle.norm().max(1.0));
        for i in 0..3 {
            let e = Vector3::from_fn(|k, _| if k == i { h } else { 0.0 });
            let col =
                (tangent_inverse(&(-(p + e))) * v - tangent_inverse(&(-(p - e))) * v) / (2.0 * h);
            assert!((col - d.column(i)).norm() < 1e-8);
        }
    }
}
