//! The Newmark family's inertial moments `Rₙ₊₁(J₀Ȧₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)`
//! (FORMULATION §4.1, §4.5) of two nodes at once, one in each lane of a pair
//! of doubles ([`flexmech_core::rotation_pair`]): the operations of
//! `inertial_moment` in the same order, so each node's moment has the bits
//! of the one-node kernel. For the residual-only evaluations of a step,
//! where the moments are all that is needed; the tangent's stay node by
//! node.

use super::newmark_terms::{Coefficients, Kinematics};
use flexmech_core::rotation_pair::{
    cross, lane, log_pair, mat_mat_t, mat_t_vec, mat_vec, matrices, vectors, M2, V2,
};
use nalgebra::{Matrix3, Vector3};
use wide::f64x2;

/// Every node's inertial moment at the end rotations `r1` from the start
/// rotations `r_n` (zero where the node has no rotary inertia `j0`), two
/// nodes at a time — on two threads for a large mesh, each pair on its own,
/// so the same either way. `single(i)` is the one-node kernel, for a last
/// odd node and a pair with a node without rotary inertia.
pub(super) fn inertial_moments(
    k: &Coefficients,
    j0: &[Matrix3<f64>],
    (r_n, r1): (&[Matrix3<f64>], &[Matrix3<f64>]),
    prev: &Kinematics,
    dt: f64,
    single: impl Fn(usize) -> Vector3<f64> + Sync,
) -> Vec<Vector3<f64>> {
    let n = j0.len();
    let moment = |i: usize| {
        if j0[i] == Matrix3::zeros() {
            Vector3::zeros()
        } else {
            single(i)
        }
    };
    let pairs = crate::threads::map_nodes(n.div_ceil(2), |p| {
        let i = [2 * p, 2 * p + 1];
        if i[1] >= n || j0[i[0]] == Matrix3::zeros() || j0[i[1]] == Matrix3::zeros() {
            return i.map(|i| if i < n { moment(i) } else { Vector3::zeros() });
        }
        let at = |m: &[Matrix3<f64>]| matrices([&m[i[0]], &m[i[1]]]);
        let m = moment_pair(k, &at(j0), (&at(r_n), &at(r1)), prev, i, dt);
        [lane(&m, 0), lane(&m, 1)]
    });
    pairs.into_iter().flatten().take(n).collect()
}

/// `inertial_moment` of nodes `i` (rotary inertias `j0`, start rotations
/// `rn`, end rotations `r1p`, all as pairs).
fn moment_pair(
    k: &Coefficients,
    j0: &M2,
    (rn, r1p): (&M2, &M2),
    prev: &Kinematics,
    i: [usize; 2],
    dt: f64,
) -> V2 {
    let v = |x: &[Vector3<f64>]| vectors([&x[i[0]], &x[i[1]]]);
    let s = f64x2::splat;
    // ω = log(Rₙ₊₁Rₙᵀ), the body increment Rₙᵀω and the pseudo-acceleration.
    let rel = mat_mat_t(r1p, rn);
    let rel_m = [0, 1].map(|l| Matrix3::from_fn(|a, b| rel[3 * a + b].to_array()[l]));
    let omega = log_pair([&rel_m[0], &rel_m[1]], &rel);
    let big = mat_t_vec(rn, &omega);
    let (w_n, a_n) = (v(&prev.w), v(&prev.alpha));
    let (c_a, c_div) = (dt * dt * (0.5 - k.beta), k.beta * dt * dt);
    let a1: V2 = std::array::from_fn(|c| (big[c] - w_n[c] * s(dt) - a_n[c] * s(c_a)) / s(c_div));
    // Wₙ₊₁ and Ȧₙ₊₁ (generalized-α's average; Newmark's when α_m = α_f = 0).
    let (c_w, c_g) = (dt * (1.0 - k.gamma), dt * k.gamma);
    let w1: V2 = std::array::from_fn(|c| (w_n[c] + a_n[c] * s(c_w)) + a1[c] * s(c_g));
    let acc_n = v(&prev.ang_acc);
    let acc1: V2 = std::array::from_fn(|c| {
        let history = a_n[c] * s(k.alpha_m) - acc_n[c] * s(k.alpha_f);
        (a1[c] * s(1.0 - k.alpha_m) + history) / s(1.0 - k.alpha_f)
    });
    let (j_acc, gyro) = (mat_vec(j0, &acc1), cross(&w1, &mat_vec(j0, &w1)));
    mat_vec(r1p, &std::array::from_fn(|c| j_acc[c] + gyro[c]))
}

#[cfg(test)]
mod tests {
    use super::inertial_moments;
    use crate::dynamics::mass_slots::inertia_oracle::inertia;
    use crate::dynamics::newmark_terms::{inertial_moment, Coefficients, Kinematics};
    use flexmech_core::rotation::exp;
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    const NODES: usize = 5;

    fn vectors(a: &[[f64; 3]; NODES]) -> Vec<Vector3<f64>> {
        a.iter().map(|&v| Vector3::from(v)).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Every node's moment has the bits of the one-node kernel: pairs,
        /// a last odd node, a node without rotary inertia, increments
        /// whose logarithm takes either branch, both schemes.
        #[test]
        fn moments_in_pairs_give_the_bits_of_one_node_at_a_time(
            start in prop::array::uniform5(prop::array::uniform3(-3.0..3.0f64)),
            spin in prop::array::uniform5(prop::array::uniform3(-1.0..1.0f64)),
            scale in prop::array::uniform5(-4.0..-0.5f64),
            w in prop::array::uniform5(prop::array::uniform3(-5.0..5.0f64)),
            alpha in prop::array::uniform5(prop::array::uniform3(-50.0..50.0f64)),
            ang_acc in prop::array::uniform5(prop::array::uniform3(-50.0..50.0f64)),
            bare in 0..NODES,
        ) {
            let r_n: Vec<Matrix3<f64>> = start.iter().map(|&s| exp(&Vector3::from(s))).collect();
            let r1: Vec<Matrix3<f64>> = (0..NODES)
                .map(|i| exp(&(Vector3::from(spin[i]) * 10f64.powf(scale[i]))) * r_n[i])
                .collect();
            let j0: Vec<Matrix3<f64>> = (0..NODES)
                .map(|i| if i == bare { Matrix3::zeros() } else { inertia() * (1.0 + i as f64) })
                .collect();
            let prev = Kinematics {
                v: vec![],
                a: vec![],
                w: vectors(&w),
                alpha: vectors(&alpha),
                acc: vec![],
                ang_acc: vectors(&ang_acc),
            };
            for (k, dt) in [(Coefficients::TRAPEZOIDAL, 1e-3), (Coefficients::generalized_alpha(0.6), 0.05)] {
                let one = |i: usize| inertial_moment(&k, &j0[i], &r_n[i], &r1[i], &prev, i, dt);
                let pairs = inertial_moments(&k, &j0, (&r_n, &r1), &prev, dt, one);
                prop_assert_eq!(pairs.len(), NODES);
                for (i, got) in pairs.iter().enumerate() {
                    let expected = if i == bare { Vector3::zeros() } else { one(i) };
                    prop_assert!(expected.iter().zip(got.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "node {}", i);
                }
            }
        }
    }
}
