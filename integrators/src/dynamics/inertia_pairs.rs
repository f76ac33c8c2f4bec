//! The inertial moments of two nodes at once, one in each lane of a pair
//! of doubles ([`flexmech_core::rotation_pair`]), for the residual-only
//! evaluations of a step, where the moments are all that is needed (the
//! tangent's stay node by node): the Newmark family's
//! `Rₙ₊₁(J₀Ȧₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)` (FORMULATION §4.1, §4.5) and the midpoint
//! schemes' `(πₙ₊₁ − πₙ)/Δt` (§4.2–4.3). Each pair kernel does the
//! operations of its one-node kernel in the same order, so each node's
//! moment has the one-node kernel's bits.

use super::newmark_terms::{Coefficients, Kinematics};
use flexmech_core::rotation_pair::{
    cayley_inverse_pair, cross, lane, log_pair, mat_mat_t, mat_t_vec, mat_vec, matrices, vectors,
    V2,
};
use nalgebra::{Matrix3, Vector3};
use wide::f64x2;

/// Every node's rotary inertia `J₀`, start rotation `Rₙ` and end rotation
/// `Rₙ₊₁`.
type Rotary<'a> = (&'a [Matrix3<f64>], &'a [Matrix3<f64>], &'a [Matrix3<f64>]);

/// Every node's moment (zero where the node has no rotary inertia `j0`),
/// two nodes at a time by `pair` (`None`: where its lanes part, each node
/// by `single`) — on two threads for a large mesh, each pair on its own,
/// so the same either way. A last odd node, and a pair with a node without
/// rotary inertia, go by `single`.
pub(super) fn moments_in_pairs(
    j0: &[Matrix3<f64>],
    single: impl Fn(usize) -> Vector3<f64> + Sync,
    pair: impl Fn([usize; 2]) -> Option<V2> + Sync,
) -> Vec<Vector3<f64>> {
    let n = j0.len();
    let moment = |i: usize| {
        if i >= n || j0[i] == Matrix3::zeros() {
            Vector3::zeros()
        } else {
            single(i)
        }
    };
    let pairs = crate::threads::map_nodes(n.div_ceil(2), |p| {
        let i = [2 * p, 2 * p + 1];
        let both = i[1] < n && j0[i[0]] != Matrix3::zeros() && j0[i[1]] != Matrix3::zeros();
        match both.then(|| pair(i)).flatten() {
            Some(m) => [lane(&m, 0), lane(&m, 1)],
            None => i.map(moment),
        }
    });
    pairs.into_iter().flatten().take(n).collect()
}

/// The Newmark family's `inertial_moment` of nodes `i` (rotary inertias
/// `j0`, start rotations `r_n`, end rotations `r1`).
pub(super) fn newmark_moment_pair(
    k: &Coefficients,
    (j0, r_n, r1): Rotary<'_>,
    prev: &Kinematics,
    i: [usize; 2],
    dt: f64,
) -> V2 {
    let at = |m: &[Matrix3<f64>]| matrices([&m[i[0]], &m[i[1]]]);
    let (j0, rn, r1p) = (at(j0), at(r_n), at(r1));
    let v = |x: &[Vector3<f64>]| vectors([&x[i[0]], &x[i[1]]]);
    let s = f64x2::splat;
    // ω = log(Rₙ₊₁Rₙᵀ), the body increment Rₙᵀω and the pseudo-acceleration.
    let omega = log_pair(&mat_mat_t(&r1p, &rn));
    let big = mat_t_vec(&rn, &omega);
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
    let (j_acc, gyro) = (mat_vec(&j0, &acc1), cross(&w1, &mat_vec(&j0, &w1)));
    mat_vec(&r1p, &std::array::from_fn(|c| j_acc[c] + gyro[c]))
}

/// The midpoint schemes' `inertial_moment_at` of nodes `i`,
/// `(Rₙ₊₁J₀Wₙ₊₁ − πₙ)/Δt` with `Wₙ₊₁ = 2Rₙᵀcay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ` and the
/// start momenta `pi_n(i) = Rₙ(J₀Wₙ)`; `None` where a lane's Cayley
/// vector is not taken directly (rotations beyond 120°).
pub(super) fn midpoint_moment_pair(
    (j0, r_n, r1): Rotary<'_>,
    (w_n, pi_n): (&[Vector3<f64>], impl Fn(usize) -> Vector3<f64>),
    i: [usize; 2],
    dt: f64,
) -> Option<V2> {
    let at = |m: &[Matrix3<f64>]| matrices([&m[i[0]], &m[i[1]]]);
    let (rn, r1p) = (at(r_n), at(r1));
    let theta = cayley_inverse_pair(&mat_mat_t(&r1p, &rn))?;
    let (s, w_n) = (f64x2::splat, vectors([&w_n[i[0]], &w_n[i[1]]]));
    let rt = mat_t_vec(&rn, &theta);
    let w1: V2 = std::array::from_fn(|c| rt[c] * s(2.0 / dt) - w_n[c]);
    let pi_n = vectors([&pi_n(i[0]), &pi_n(i[1])]);
    let pi1 = mat_vec(&r1p, &mat_vec(&at(j0), &w1));
    Some(std::array::from_fn(|c| (pi1[c] - pi_n[c]) / s(dt)))
}

#[cfg(test)]
mod tests {
    use super::{midpoint_moment_pair, moments_in_pairs, newmark_moment_pair};
    use crate::dynamics::mass_slots::inertia_oracle::inertia;
    use crate::dynamics::midpoint::inertial_moment_at;
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
        /// whose logarithm takes either branch, the Newmark family (both
        /// coefficient sets) and the midpoint schemes.
        #[test]
        fn moments_in_pairs_give_the_bits_of_one_node_at_a_time(
            start in prop::array::uniform5(prop::array::uniform3(-3.0..3.0f64)),
            spin in prop::array::uniform5(prop::array::uniform3(-1.0..1.0f64)),
            scale in prop::array::uniform5(-4.0..0.4f64),
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
                let pair = |i| Some(newmark_moment_pair(&k, (&j0, &r_n, &r1), &prev, i, dt));
                let pairs = moments_in_pairs(&j0, one, pair);
                prop_assert_eq!(pairs.len(), NODES);
                for (i, got) in pairs.iter().enumerate() {
                    let expected = if i == bare { Vector3::zeros() } else { one(i) };
                    prop_assert!(expected.iter().zip(got.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "node {}", i);
                }
            }
            // The midpoint schemes' moments, on both branches of the Cayley
            // vector (the larger spins pass 120°).
            let dt = 1e-3;
            let one = |i: usize| inertial_moment_at(&j0[i], &r_n[i], &r1[i], &prev.w[i], dt);
            let pi_n = |i: usize| r_n[i] * (j0[i] * prev.w[i]);
            let pair = |i| midpoint_moment_pair((&j0, &r_n, &r1), (&prev.w, pi_n), i, dt);
            for (i, got) in moments_in_pairs(&j0, one, pair).iter().enumerate() {
                let expected = if i == bare { Vector3::zeros() } else { one(i) };
                prop_assert!(expected.iter().zip(got.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "midpoint node {}", i);
            }
        }
    }
}
