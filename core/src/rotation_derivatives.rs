//! First and second derivatives of the rotation maps the element kernels
//! chain through. `exp(p̂)ᵀ` and `Hᵀ(p)` are both `I + α(t) p̂ + β(t) p̂²`
//! with `t = |p|²`; their derivatives are written out in closed form from
//! `α, β` and their first two derivatives in `t` (one scalar second-order
//! dual number through the Rodrigues coefficients). The three-lane
//! hyper-dual evaluation of the whole matrix stays as the oracle in the
//! tests. `∂(H⁻ᵀv)/∂ψ` is by three-lane forward AD.

use crate::rotation::{rodrigues_coefficients, skew, skew_squared, tangent_inverse};
use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::{Dual2, DualSVec64};

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
struct Coefficient {
    value: f64,
    d1: f64,
    d2: f64,
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
fn coefficients(t: f64) -> [Coefficient; 3] {
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
    let s = skew(p);
    let q = skew_squared(p);
    let unit = |i: usize| Vector3::from_fn(|k, _| if k == i { 1.0 } else { 0.0 });
    let e_hat: [Matrix3<f64>; 3] = std::array::from_fn(|i| skew(&unit(i)));
    let dq: [Matrix3<f64>; 3] = std::array::from_fn(|i| {
        Matrix3::from_fn(|r, c| {
            let mut v = if r == i { p[c] } else { 0.0 } + if c == i { p[r] } else { 0.0 };
            if r == c {
                v -= 2.0 * p[i];
            }
            v
        })
    });
    let d1: [Matrix3<f64>; 3] = std::array::from_fn(|i| {
        s * (2.0 * alpha.d1 * p[i])
            + e_hat[i] * alpha.value
            + q * (2.0 * beta.d1 * p[i])
            + dq[i] * beta.value
    });
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
        value: Matrix3::identity() + s * alpha.value + q * beta.value,
        d1,
        d2,
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

/// `Hᵀ(p) = I − b p̂ + c p̂²` ([`crate::rotation::tangent`]) and its first
/// and second derivatives in `p`.
pub fn tangent_transpose(p: &Vector3<f64>) -> MatrixDerivatives {
    let [_, b, c] = coefficients(p.norm_squared());
    quadratic_in_skew(p, negated(b), c)
}

/// `∂(H⁻ᵀ(ψ) v)/∂ψ` (`H⁻ᵀ(ψ) = H⁻¹(−ψ)`).
pub fn tangent_inverse_transpose_derivative(psi: &Vector3<f64>, v: &Vector3<f64>) -> Matrix3<f64> {
    type D = DualSVec64<3>;
    let p = Vector3::from_fn(|i, _| D::from_re(psi[i]).derivative(i));
    let w = tangent_inverse(&(-p)) * v.map(D::from_re);
    let mut m = Matrix3::zeros();
    for i in 0..3 {
        m.set_row(i, &w[i].eps.unwrap_generic(Const::<3>, U1).transpose());
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{exp, tangent};
    use num_dual::HyperDualSVec64;

    /// Both sides are exact: only round-off separates them.
    const ORACLE_TOL: f64 = 1e-12;

    type H3 = HyperDualSVec64<3, 3>;

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
        for i in 0..3 {
            let e = Vector3::from_fn(|k, _| if k == i { h } else { 0.0 });
            let col =
                (tangent_inverse(&(-(p + e))) * v - tangent_inverse(&(-(p - e))) * v) / (2.0 * h);
            assert!((col - d.column(i)).norm() < 1e-8);
        }
    }
}
