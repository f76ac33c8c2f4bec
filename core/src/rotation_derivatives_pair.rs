//! The rotation derivatives of [`crate::rotation_derivatives`] that the
//! 2-node element's tangent chains through, for two elements at once, one
//! in each lane of a pair of doubles ([`crate::rotation_pair`]): the
//! one-lane arithmetic in the same order (nalgebra's sums left to right, a
//! matrix times a scalar entry by entry, identity and unit-skew entries
//! multiplied in as they are), the coefficients' series or closed forms
//! called lane by lane — so each lane holds the one-lane bits (tested with
//! the element kernel, [`crate::element_tangent_pair`]).

use crate::rotation::tangent_inverse_coefficient;
use crate::rotation_derivatives::{coefficients, Coefficient};
use crate::rotation_pair::{dot, id, pair, skew, skew_squared, splat, M2, V2};
use num_dual::Dual64;
use wide::f64x2;

/// A coefficient of `t = |p|²` with its first two derivatives in `t`, lane
/// by lane.
#[derive(Clone, Copy)]
struct Coefficient2 {
    value: f64x2,
    d1: f64x2,
    d2: f64x2,
}

impl Coefficient2 {
    fn of(c: [Coefficient; 2]) -> Self {
        Self {
            value: pair(c[0].value, c[1].value),
            d1: pair(c[0].d1, c[1].d1),
            d2: pair(c[0].d2, c[1].d2),
        }
    }

    fn negated(self) -> Self {
        Self {
            value: -self.value,
            d1: -self.d1,
            d2: -self.d2,
        }
    }
}

/// [`crate::rotation_derivatives::exp_transpose_first`] of two vectors:
/// `exp(p̂)ᵀ = I + α p̂ + β p̂²` (`α = −sin|p|/|p|`) and `∂M/∂pᵢ`, second
/// derivatives through [`SkewQuadraticPair::bilinear_hessian`].
pub struct SkewQuadraticPair {
    /// `M(p)`.
    pub value: M2,
    /// `∂M/∂pᵢ`, `i = 0..3`.
    pub d1: [M2; 3],
    p: V2,
    alpha: Coefficient2,
    beta: Coefficient2,
}

/// `exp(p̂)ᵀ` of each lane's `p` with its first derivatives.
pub fn exp_transpose_first_pair(p: &V2) -> SkewQuadraticPair {
    let t = dot(p, p).to_array();
    let [c0, c1] = t.map(coefficients);
    let alpha = Coefficient2::of([c0[0], c1[0]]).negated();
    let beta = Coefficient2::of([c0[1], c1[1]]);
    let (s, q) = (skew(p), skew_squared(p));
    let two = splat(2.0);
    let d1: [M2; 3] = std::array::from_fn(|i| {
        let (e_hat, dq) = (unit_skew(i), skew_squared_derivative(p, i));
        let (ca, cb) = (two * alpha.d1 * p[i], two * beta.d1 * p[i]);
        std::array::from_fn(|e| s[e] * ca + e_hat[e] * alpha.value + q[e] * cb + dq[e] * beta.value)
    });
    SkewQuadraticPair {
        value: std::array::from_fn(|e| id(e) + s[e] * alpha.value + q[e] * beta.value),
        d1,
        p: *p,
        alpha,
        beta,
    }
}

/// `êᵢ`, the skew matrix of the unit vector `eᵢ`, row by row.
fn unit_skew(i: usize) -> M2 {
    let unit: V2 = std::array::from_fn(|k| splat(if k == i { 1.0 } else { 0.0 }));
    skew(&unit)
}

/// `∂ᵢ(p̂²) = eᵢpᵀ + peᵢᵀ − 2pᵢI`, formed entry by entry as the one-lane
/// map forms it.
fn skew_squared_derivative(p: &V2, i: usize) -> M2 {
    let z = splat(0.0);
    std::array::from_fn(|e| {
        let (r, c) = (e / 3, e % 3);
        let v = if r == i { p[c] } else { z } + if c == i { p[r] } else { z };
        if r == c {
            v - splat(2.0) * p[i]
        } else {
            v
        }
    })
}

/// `u wᵀ`, row by row.
fn outer(u: &V2, w: &V2) -> M2 {
    std::array::from_fn(|e| u[e / 3] * w[e % 3])
}

/// `m + mᵀ`.
fn plus_transpose(m: &M2) -> M2 {
    std::array::from_fn(|e| m[e] + m[3 * (e % 3) + e / 3])
}

impl SkewQuadraticPair {
    /// [`crate::rotation_derivatives::SkewQuadratic::bilinear_hessian`]:
    /// `∂²(uᵀM(p)w)/∂p²` of each lane.
    pub fn bilinear_hessian(&self, u: &V2, w: &V2) -> M2 {
        let (p, a, b) = (&self.p, &self.alpha, &self.beta);
        let c = crate::rotation_pair::cross(w, u);
        let (up, pw, uw) = (dot(u, p), dot(p, w), dot(u, w));
        let s1 = dot(p, &c);
        let s2 = up * pw - dot(p, p) * uw;
        let two = splat(2.0);
        let g: V2 = std::array::from_fn(|i| u[i] * pw + w[i] * up - p[i] * (two * uw));
        let (pc, pg, uwt) = (outer(p, &c), outer(p, &g), outer(u, w));
        let (pc, pg, uwt) = (
            plus_transpose(&pc),
            plus_transpose(&pg),
            plus_transpose(&uwt),
        );
        let pp = outer(p, p);
        let c_pp = splat(4.0) * (a.d2 * s1 + b.d2 * s2);
        let c_id = two * (a.d1 * s1 + b.d1 * s2) - two * b.value * uw;
        let (c_pc, c_pg) = (two * a.d1, two * b.d1);
        std::array::from_fn(|e| {
            pp[e] * c_pp + id(e) * c_id + pc[e] * c_pc + pg[e] * c_pg + uwt[e] * b.value
        })
    }
}

/// [`crate::rotation_derivatives::tangent_inverse_transpose_derivative`] of
/// each lane: `∂(H⁻ᵀ(ψ) v)/∂ψ = −½ v̂ + 2D′(t) w ψᵀ + D(t) ((ψ·v) I + ψ vᵀ
/// − 2 v ψᵀ)`, `w = ψ(ψ·v) − t v`.
pub fn tangent_inverse_transpose_derivative_pair(psi: &V2, v: &V2) -> M2 {
    let t = dot(psi, psi);
    let [d0, d1] = t
        .to_array()
        .map(|t| tangent_inverse_coefficient(Dual64::new(t, 1.0)));
    let (dv, dd) = (pair(d0.re, d1.re), pair(d0.eps, d1.eps));
    let pv = dot(psi, v);
    let w: V2 = std::array::from_fn(|i| psi[i] * pv - v[i] * t);
    let (sv, wp, pvt, vp) = (skew(v), outer(&w, psi), outer(psi, v), outer(v, psi));
    let (half, two) = (splat(0.5), splat(2.0));
    let c_wp = two * dd;
    std::array::from_fn(|e| {
        let bracket = id(e) * pv + pvt[e] - vp[e] * two;
        -sv[e] * half + wp[e] * c_wp + bracket * dv
    })
}
