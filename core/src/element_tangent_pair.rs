//! The 2-node element's residual and consistent tangent of two elements at
//! once, one element in each lane of a pair of doubles
//! ([`crate::rotation_pair`]): the arithmetic of
//! [`BeamElement::residual_tangent_linear_into`] (FORMULATION §2, the
//! invariant coordinates `z = (φ, a)`) in the same order, with no fused
//! products and the coefficients' series or closed forms called lane by
//! lane, so that each lane holds the one-element bits (tested). The tangent
//! evaluations of a mesh on one thread take two neighbouring 2-node
//! elements through it.

use crate::element::BeamElement;
use crate::element_pair::triads;
use crate::mesh::gather_into;
use crate::rotation_derivatives_pair::{
    exp_transpose_first_pair, tangent_inverse_transpose_derivative_pair,
};
use crate::rotation_pair::{
    dot, log_pair, mat_mat, mat_t_mat, mat_t_vec, mat_vec, pair, scale, skew, splat,
    tangent_inverse, vectors, M2, V2,
};
use nalgebra::{Matrix3, Vector3};

/// The unknowns of a 2-node element.
const DOFS: usize = 12;

/// `mᵀ`.
fn transpose(m: &M2) -> M2 {
    std::array::from_fn(|e| m[3 * (e % 3) + e / 3])
}

/// `−m`.
fn neg(m: &M2) -> M2 {
    m.map(|v| -v)
}

/// `a − b`.
fn sub(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| a[e] - b[e])
}

/// `a + b`.
fn add(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| a[e] + b[e])
}

/// Each lane's `(v₁, v₂)` of two elements' vectors `v(k)`.
fn lanes(v: impl Fn(usize) -> Vector3<f64>) -> V2 {
    vectors([&v(0), &v(1)])
}

/// The gradient `e = ∂E/∂z` and the blocks `(H_φφ, H_φa, H_aa)` of
/// `∂²E/∂z²` of two elements at their relative rotations `phi` and
/// material chords `a` (the module docs of [`crate::element_linear`]),
/// with `A = exp(½φ̂)ᵀ`.
fn energy_derivatives(e: [&BeamElement<2>; 2], phi: &V2, a: &V2) -> ([V2; 2], [M2; 3]) {
    let (l, half) = (pair(e[0].length, e[1].length), splat(0.5));
    let ad = exp_transpose_first_pair(&scale(phi, half));
    let (am, da) = (&ad.value, &ad.d1);
    let (g0, k0) = (
        lanes(|k| e[k].initial_strains()[0].0),
        lanes(|k| e[k].initial_strains()[0].1),
    );
    let (cn, cm) = (lanes(|k| e[k].section.c_n), lanes(|k| e[k].section.c_m));
    let ama = mat_vec(am, a);
    let n: V2 = std::array::from_fn(|i| (ama[i] / l - g0[i]) * cn[i]);
    let m: V2 = std::array::from_fn(|i| (phi[i] / l - k0[i]) * cm[i]);
    let aa: [V2; 3] = std::array::from_fn(|i| mat_vec(&da[i], a));
    let cn_aa: [V2; 3] = std::array::from_fn(|i| std::array::from_fn(|c| aa[i][c] * cn[c]));
    let n_dda = ad.bilinear_hessian(&n, a);
    let mut e_phi = [splat(0.0); 3];
    let (mut h_pp, mut h_pa) = ([splat(0.0); 9], [splat(0.0); 9]);
    for i in 0..3 {
        e_phi[i] = half * dot(&n, &aa[i]) + m[i];
        for j in 0..3 {
            h_pp[3 * i + j] = splat(0.25) * (dot(&aa[j], &cn_aa[i]) / l + n_dda[3 * i + j]);
        }
        h_pp[4 * i] += cm[i] / l;
        let (da_n, am_cn) = (mat_t_vec(&da[i], &n), mat_t_vec(am, &cn_aa[i]));
        for c in 0..3 {
            h_pa[3 * i + c] = (da_n[c] + am_cn[c] / l) * half;
        }
    }
    let ea = mat_t_vec(am, &n);
    let scaled: M2 = std::array::from_fn(|x| am[3 * (x % 3) + x / 3] * cn[x % 3]);
    let h_aa = mat_mat(&scaled, am).map(|v| v / l);
    ([e_phi, ea], [h_pp, h_pa, h_aa])
}

/// [`BeamElement::residual_tangent_linear_into`] of two elements with
/// their nodes' positions `x[k]` and rotations `rot[k]`, `k` the element:
/// the residuals (12 entries each) into `r[k]`, the tangents (12 × 12,
/// column-major) into `kt[k]`.
pub fn residual_tangent_pair(
    e: [&BeamElement<2>; 2],
    x: &[[Vector3<f64>; 2]; 2],
    rot: &[[Matrix3<f64>; 2]; 2],
    r: [&mut [f64]; 2],
    kt: [&mut [f64]; 2],
) {
    let lam = triads(e, [&rot[0], &rot[1]]);
    let lt = transpose(&lam[0]);
    let phi = log_pair(&mat_t_mat(&lam[0], &lam[1]));
    let d = lanes(|k| x[k][1] - x[k][0]);
    let a = mat_t_vec(&lam[0], &d);
    let ([e_phi, ea], [h_pp, h_pa, h_aa]) = energy_derivatives(e, &phi, &a);
    // J = ∂z/∂(η₁, ε₁, η₂, ε₂): Jᵀ(∂²E/∂z²)J in 3 × 3 blocks (see the
    // one-element kernel).
    let s = mat_mat(&tangent_inverse(&phi), &lt);
    let dh = skew(&d);
    let pp = mat_mat(&mat_mat(&lam[0], &h_aa), &lt);
    let qq = mat_mat(&mat_t_mat(&s, &h_pp), &s);
    let qp = mat_mat(&mat_t_mat(&s, &h_pa), &lt);
    let pq = transpose(&qp);
    let (pp_d, qp_d) = (mat_mat(&pp, &dh), mat_mat(&qp, &dh));
    let (d_pp, d_pq) = (mat_mat(&dh, &pp), mat_mat(&dh, &pq));
    let k21 = sub(&pp_d, &pq);
    let k41 = sub(&qp_d, &qq);
    let k12 = sub(&neg(&qp), &d_pp);
    let k14 = sub(&neg(&qq), &d_pq);
    let k11 = sub(&add(&sub(&qq, &qp_d), &d_pq), &mat_mat(&d_pp, &dh));
    let mut blocks = [
        [pp, neg(&k21), neg(&pp), neg(&pq)],
        [neg(&k12), k11, k12, k14],
        [neg(&pp), k21, pp, pq],
        [neg(&qp), k41, qp, qq],
    ];
    // r = Jᵀe.
    let u = mat_t_vec(&s, &e_phi);
    let b = mat_vec(&lam[0], &ea);
    let dh_b = mat_vec(&dh, &b);
    let res: [V2; 4] = [
        b.map(|v| -v),
        std::array::from_fn(|i| -u[i] - dh_b[i]),
        b,
        u,
    ];
    // G: the derivative of Jᵀe with e held.
    let titd = tangent_inverse_transpose_derivative_pair(&phi, &e_phi);
    let mphi = mat_mat(&mat_mat(&lam[0], &titd), &s);
    let (u_hat, b_hat) = (skew(&u), skew(&b));
    let geometric = [
        (3, 1, sub(&neg(&u_hat), &mphi)),
        (3, 3, mphi),
        (1, 1, add(&add(&u_hat, &mphi), &mat_mat(&dh, &b_hat))),
        (1, 3, neg(&mphi)),
        (0, 1, b_hat),
        (2, 1, neg(&b_hat)),
        (1, 0, neg(&b_hat)),
        (1, 2, b_hat),
    ];
    for (row, col, g) in geometric {
        blocks[row][col] = add(&blocks[row][col], &g);
    }
    write_out(&res, &blocks, r, kt);
}

/// [`residual_tangent_pair`] of two elements with the nodes' positions `x`
/// and rotations `rot` of the whole mesh (gathered as
/// [`crate::Element::residual_tangent`] gathers them).
pub fn residual_tangent_pair_at(
    e: [&BeamElement<2>; 2],
    x: &[Vector3<f64>],
    rot: &[Matrix3<f64>],
    r: [&mut [f64]; 2],
    kt: [&mut [f64]; 2],
) {
    let (mut xx, mut rr) = ([[Vector3::zeros(); 2]; 2], [[Matrix3::zeros(); 2]; 2]);
    for k in 0..2 {
        gather_into(&e[k].nodes, x, rot, &mut xx[k], &mut rr[k]);
    }
    residual_tangent_pair(e, &xx, &rr, r, kt);
}

/// Lane `k` of the residual blocks into `r[k]` and of the tangent blocks
/// into `kt[k]` (column-major).
fn write_out(res: &[V2; 4], blocks: &[[M2; 4]; 4], r: [&mut [f64]; 2], kt: [&mut [f64]; 2]) {
    for (k, (r, kt)) in r.into_iter().zip(kt).enumerate() {
        for (row, v) in r.iter_mut().enumerate().take(DOFS) {
            *v = res[row / 3][row % 3].to_array()[k];
        }
        for (col, column) in kt.chunks_exact_mut(DOFS).enumerate().take(DOFS) {
            for (row, v) in column.iter_mut().enumerate() {
                let blk = &blocks[row / 3][col / 3];
                *v = blk[3 * (row % 3) + col % 3].to_array()[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::residual_tangent_pair;
    use crate::element_pair::tests::pairs;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Each lane holds the bits of the one-element residual and tangent,
        /// on every branch: relative rotations from 10⁻⁵ rad (the series of
        /// the Rodrigues coefficients, of `H⁻¹` and of the logarithm) to
        /// past 120° (the logarithm's quaternion not read from the trace),
        /// lanes on different branches, curved and prestrained elements.
        #[test]
        fn a_pair_gives_the_bits_of_one_elements_residual_and_tangent((e, x, rot) in pairs()) {
            let (mut r, mut kt) = ([[0.0; 12]; 2], [[0.0; 144]; 2]);
            let [r0, r1] = &mut r;
            let [k0, k1] = &mut kt;
            residual_tangent_pair([&e[0], &e[1]], &x, &rot, [r0, r1], [k0, k1]);
            let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            for k in 0..2 {
                let (one_r, one_k) = e[k].residual_tangent_linear(&x[k], &rot[k]);
                prop_assert_eq!(bits(one_r.as_slice()), bits(&r[k]), "residual of lane {}", k);
                prop_assert_eq!(bits(one_k.as_slice()), bits(&kt[k]), "tangent of lane {}", k);
            }
        }
    }
}
