//! The energy–momentum scheme's secant operators `(B, T)` of a 2-node
//! element's step seen from both ends at once, one end in each lane of a pair
//! of doubles ([`crate::rotation_pair`]): the step from the start
//! (`Λ₁,ₙ`, `+g`, `+θᵢ`) in lane 0 and the same step seen from its end
//! (`Λ₁,ₙ₊₁`, `−g`, `−θᵢ`) in lane 1 (FORMULATION §4.3). Each lane does the
//! operations of [`crate::discrete_gradient::secant_operators_at`] in the
//! same order, with no fused products; the scalar coefficients with a
//! series branch or a transcendental function (`atan2`, `sin`, `cot`) are
//! the one-end functions called lane by lane, so each lane holds the bits
//! the one-end operators give (tested on every branch).

use crate::rotation_pair::{
    cross, dot, id, log_factor, mat_mat, mat_scale, mat_t_mat, mat_vec, matrices, pair, scale,
    skew, splat, tangent, tangent_inverse, unpack, vectors, M2, V2,
};
use nalgebra::{Matrix3, Vector3, Vector4};
use wide::f64x2;

/// A quaternion `(w, x, y, z)` of pairs.
type Q2 = [f64x2; 4];

/// One end's inputs of [`crate::discrete_gradient::secant_operators_at`]:
/// node 1's triad, the relative rotation's quaternion and its half's, the
/// reference rotation's relative increment and the nodes' increments.
pub(crate) struct EndView<'a> {
    pub(crate) lam1: &'a Matrix3<f64>,
    pub(crate) rel0: &'a Vector4<f64>,
    pub(crate) half0: &'a Vector4<f64>,
    pub(crate) g: Vector3<f64>,
    pub(crate) th: [Vector3<f64>; 2],
}

#[inline]
fn quat2(a: &Vector4<f64>, b: &Vector4<f64>) -> Q2 {
    std::array::from_fn(|i| pair(a[i], b[i]))
}

/// [`crate::rotation::quaternion_product`].
#[inline]
fn product(a: &Q2, b: &Q2) -> Q2 {
    let (av, bv) = ([a[1], a[2], a[3]], [b[1], b[2], b[3]]);
    let c = cross(&av, &bv);
    let v: V2 = std::array::from_fn(|i| bv[i] * a[0] + av[i] * b[0] + c[i]);
    [a[0] * b[0] - dot(&av, &bv), v[0], v[1], v[2]]
}

/// [`crate::rotation::cayley_quaternion`].
#[inline]
fn cayley_quaternion(theta: &V2) -> Q2 {
    let half = splat(0.5);
    let f = splat(1.0) / (splat(1.0) + dot(theta, theta) * splat(0.25)).sqrt();
    [
        f,
        theta[0] * half * f,
        theta[1] * half * f,
        theta[2] * half * f,
    ]
}

/// [`crate::rotation::log_quaternion`] of quaternions with `w ≥ 0`.
#[inline]
fn log_quaternion(q: &Q2) -> V2 {
    let v = [q[1], q[2], q[3]];
    scale(&v, log_factor(q[0], dot(&v, &v)))
}

/// [`crate::rotation::quaternion_half`] followed by the Cayley vector of
/// its product with the conjugate of `half0`
/// ([`crate::rotation::cayley_of_quaternion`]).
#[inline]
fn relative_cayley_of_half(q: &Q2, half0: &Q2) -> V2 {
    let w1 = splat(1.0) + q[0];
    let f = splat(1.0) / (w1 * splat(2.0)).sqrt();
    let h = [w1 * f, q[1] * f, q[2] * f, q[3] * f];
    let p = product(&h, &[half0[0], -half0[1], -half0[2], -half0[3]]);
    scale(&[p[1], p[2], p[3]], splat(2.0) / p[0])
}

/// The Cayley map's spatial tangent `Q(c)` (as the one-end kernel's).
#[inline]
fn cayley_tangent(c: &V2) -> M2 {
    let sk = skew(c);
    let f = splat(1.0) / (splat(1.0) + dot(c, c) * splat(0.25));
    std::array::from_fn(|e| (id(e) + sk[e] * splat(0.5)) * f)
}

/// [`crate::rotation::cayley_tangent_inverse`].
#[inline]
fn cayley_tangent_inverse(theta: &V2) -> M2 {
    let sk = skew(theta);
    std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        id(e) - sk[e] * splat(0.5) + theta[i] * theta[j] * splat(0.25)
    })
}

/// The secant operators `(B, T)` of both ends, `[from the start, from the
/// end]`: [`crate::discrete_gradient::secant_operators_at`] of each end, two
/// at once.
pub(crate) fn secant_operators_both(ends: [EndView<'_>; 2]) -> [(Matrix3<f64>, Matrix3<f64>); 2] {
    let [a, b] = &ends;
    let (half, quarter) = (splat(0.5), splat(0.25));
    let lam1 = matrices([a.lam1, b.lam1]);
    let th = [0, 1].map(|n| vectors([&a.th[n], &b.th[n]]));
    let dtheta: V2 = std::array::from_fn(|i| th[1][i] - th[0][i]);
    let tbar: V2 = std::array::from_fn(|i| (th[0][i] + th[1][i]) * half);
    let sk = skew(&tbar);
    let inner: M2 = std::array::from_fn(|e| id(e) - sk[e] * half);
    let to_rel = mat_scale(
        &mat_t_mat(&lam1, &inner),
        splat(1.0) / (splat(1.0) + dot(&th[0], &th[1]) * quarter),
    );
    let c_half = scale(&mat_vec(&to_rel, &dtheta), half);
    let mut q = product(&cayley_quaternion(&c_half), &quat2(a.rel0, b.rel0));
    let w = q[0].to_array();
    let sign = pair(sign_of(w[0]), sign_of(w[1]));
    q = q.map(|x| x * sign);
    let phi_h = log_quaternion(&q);
    let g_h = relative_cayley_of_half(&q, &quat2(a.half0, b.half0));
    let t = mat_mat(
        &mat_mat(&tangent_inverse(&phi_h), &cayley_tangent(&c_half)),
        &to_rel,
    );
    let bv = mat_vec(&lam1, &vectors([&a.g, &b.g]));
    let sk0 = skew(&th[0]);
    let e_sum: M2 = std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        id(e) + sk0[e] * half + th[0][i] * th[0][j] * quarter
    });
    let e = mat_scale(
        &e_sum,
        splat(1.0) / (splat(1.0) - dot(&th[0], &bv) * quarter),
    );
    let dg = mat_mat(
        &cayley_tangent_inverse(&g_h),
        &tangent(&scale(&phi_h, half)),
    );
    let bm = mat_mat(&mat_mat(&mat_mat(&e, &lam1), &dg), &t);
    let bm: M2 = std::array::from_fn(|e| bm[e] * half - id(e) * half);
    [0, 1].map(|k| (unpack(&bm, k), unpack(&t, k)))
}

/// The factor that makes a quaternion's `w` non-negative (`−1` where
/// `w < 0`, as the one-end kernel's test).
#[inline]
fn sign_of(w: f64) -> f64 {
    if w < 0.0 {
        -1.0
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::{secant_operators_both, EndView};
    use crate::discrete_gradient::secant_operators_at;
    use crate::rotation::{exp, exp_quaternion, quaternion_half};
    use nalgebra::{Matrix3, Vector3, Vector4};
    use proptest::prelude::*;

    fn same_bits(a: &Matrix3<f64>, b: &Matrix3<f64>) -> bool {
        a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    }

    /// A unit quaternion with `w ≥ 0` of a rotation vector `10^scale · dir`.
    fn quaternion(dir: [f64; 3], scale: f64) -> Vector4<f64> {
        let q = exp_quaternion(&(Vector3::from(dir) * 10f64.powf(scale)));
        if q.x < 0.0 {
            -q
        } else {
            q
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1024))]

        /// Each lane holds the bits of the one-end operators, on every
        /// branch: relative rotations from 10⁻⁴ rad to past π (the
        /// quaternion's sign flip), increments from 10⁻⁵ to 1 (the series
        /// of the logarithm, of `H` and of `H⁻¹`, and their closed forms),
        /// and lanes on different branches.
        #[test]
        fn both_ends_at_once_give_the_bits_of_one_end_at_a_time(
            dirs in prop::array::uniform6(prop::array::uniform3(-1.0..1.0f64)),
            scales in prop::array::uniform6(-5.0..0.6f64),
        ) {
            let lam = [exp(&Vector3::from(dirs[0])), exp(&(Vector3::from(dirs[1]) * 3.0))];
            let rel = [quaternion(dirs[2], scales[0]), quaternion(dirs[3], scales[1])];
            let half = rel.map(|q| quaternion_half(&q));
            let v = |k: usize, s: f64| Vector3::from(dirs[k]) * 10f64.powf(s);
            let g = [v(4, scales[2]), v(5, scales[3])];
            let th = [[v(2, scales[4]), v(3, scales[5])], [v(5, scales[2]), v(4, scales[4])]];
            let ends = [0, 1].map(|k| EndView { lam1: &lam[k], rel0: &rel[k], half0: &half[k], g: g[k], th: th[k] });
            let both = secant_operators_both(ends);
            for k in 0..2 {
                let (b, t) = secant_operators_at(&lam[k], &rel[k], &half[k], &g[k], &th[k]);
                prop_assert!(same_bits(&both[k].0, &b), "B of lane {k}");
                prop_assert!(same_bits(&both[k].1, &t), "T of lane {k}");
            }
        }
    }
}
