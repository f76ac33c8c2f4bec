//! First and second derivatives of the rotation maps the element kernels
//! chain through, by forward AD over the three components of a rotation
//! vector (the AD stays inside these small functions; the kernels combine
//! the results with the product rule in `f64`).

use crate::rotation::{exp, tangent, tangent_inverse};
use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::{DualSVec64, HyperDualSVec64};

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

type H3 = HyperDualSVec64<3, 3>;

fn split(m: Matrix3<H3>) -> MatrixDerivatives {
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

/// `exp(p̂)ᵀ` and its first and second derivatives in `p`.
pub fn exp_transpose(p: &Vector3<f64>) -> MatrixDerivatives {
    split(exp(&seeded(p)).transpose())
}

/// `Hᵀ(p)` ([`tangent`]) and its first and second derivatives in `p`.
pub fn tangent_transpose(p: &Vector3<f64>) -> MatrixDerivatives {
    split(tangent(&seeded(p)).transpose())
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
