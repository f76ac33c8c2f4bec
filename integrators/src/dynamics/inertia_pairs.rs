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
    cayley_inverse_pair, cross, lane, log_pair, mat_mat, mat_mat_t, mat_t_mat, mat_t_vec, mat_vec,
    matrices, skew, tangent_inverse, unpack, vectors, M2, V2,
};
use nalgebra::{Matrix3, Vector3};
use wide::f64x2;

/// Every node's rotary inertia `J₀`, start rotation `Rₙ` and end rotation
/// `Rₙ₊₁`.
type Rotary<'a> = (&'a [Matrix3<f64>], &'a [Matrix3<f64>], &'a [Matrix3<f64>]);

/// Every node's moment (zero where the node has no rotary inertia `j0`),
/// two nodes at a time by `pair` (`None`: where its lanes part, each node
/// by `single`), into `out` as [`in_node_pairs_into`] leaves them: node
/// `i`'s moment is `out[i / 2][i % 2]`.
pub(super) fn moments_in_pairs_into(
    j0: &[Matrix3<f64>],
    single: impl Fn(usize) -> Vector3<f64> + Sync,
    pair: impl Fn([usize; 2]) -> Option<V2> + Sync,
    out: &mut Vec<[Vector3<f64>; 2]>,
) {
    let pair = |i| pair(i).map(|m: V2| [lane(&m, 0), lane(&m, 1)]);
    in_node_pairs_into(j0, single, pair, out);
}

/// Every node's value (the default where the node has no rotary inertia
/// `j0`), two nodes at a time by `pair` (`None`: each node by `single`) —
/// on two threads for a large mesh, each pair on its own, so the same
/// either way. A last odd node, and a pair with a node without rotary
/// inertia, go by `single`. Into `out` (cleared first; its allocation
/// kept from one evaluation to the next), two nodes to an entry: node
/// `i`'s value is `out[i / 2][i % 2]` (a last odd node's partner is the
/// default).
pub(super) fn in_node_pairs_into<T: Copy + Default + Send>(
    j0: &[Matrix3<f64>],
    single: impl Fn(usize) -> T + Sync,
    pair: impl Fn([usize; 2]) -> Option<[T; 2]> + Sync,
    out: &mut Vec<[T; 2]>,
) {
    let n = j0.len();
    let one = |i: usize| {
        if i >= n || j0[i] == Matrix3::zeros() {
            T::default()
        } else {
            single(i)
        }
    };
    crate::threads::map_nodes_into(n.div_ceil(2), out, |p| {
        let i = [2 * p, 2 * p + 1];
        let both = i[1] < n && j0[i[0]] != Matrix3::zeros() && j0[i[1]] != Matrix3::zeros();
        both.then(|| pair(i))
            .flatten()
            .unwrap_or_else(|| i.map(one))
    });
}

/// The Newmark family's kinematics of a pair of nodes at the step's end:
/// `ω = log(Rₙ₊₁Rₙᵀ)`, `Wₙ₊₁`, `Ȧₙ₊₁` and the nodes' `J₀`, `Rₙ`, `Rₙ₊₁`.
struct NodePair {
    omega: V2,
    w1: V2,
    acc1: V2,
    j0: M2,
    rn: M2,
    r1: M2,
}

/// [`NodePair`] of nodes `i` (rotary inertias `j0`, start rotations `r_n`,
/// end rotations `r1`), as the one-node kernels compute it.
fn newmark_node_pair(
    k: &Coefficients,
    (j0, r_n, r1): Rotary<'_>,
    prev: &Kinematics,
    i: [usize; 2],
    dt: f64,
) -> NodePair {
    let at = |m: &[Matrix3<f64>]| matrices([&m[i[0]], &m[i[1]]]);
    let (j0, rn, r1) = (at(j0), at(r_n), at(r1));
    let v = |x: &[Vector3<f64>]| vectors([&x[i[0]], &x[i[1]]]);
    let s = f64x2::splat;
    let (w_n, a_n) = (v(&prev.w), v(&prev.alpha));
    let (omega, a1) = increment_pair(k, (&rn, &r1), (&w_n, &a_n), dt);
    // Wₙ₊₁ and Ȧₙ₊₁ (generalized-α's average; Newmark's when α_m = α_f = 0).
    let (c_w, c_g) = (dt * (1.0 - k.gamma), dt * k.gamma);
    let w1: V2 = std::array::from_fn(|c| (w_n[c] + a_n[c] * s(c_w)) + a1[c] * s(c_g));
    let acc_n = v(&prev.ang_acc);
    let acc1: V2 = std::array::from_fn(|c| {
        let history = a_n[c] * s(k.alpha_m) - acc_n[c] * s(k.alpha_f);
        (a1[c] * s(1.0 - k.alpha_m) + history) / s(1.0 - k.alpha_f)
    });
    NodePair {
        omega,
        w1,
        acc1,
        j0,
        rn,
        r1,
    }
}

/// The spatial increment `ω = log(Rₙ₊₁Rₙᵀ)` of two nodes and their body
/// angular pseudo-accelerations `aₙ₊₁ = (Rₙᵀω − Δt Wₙ − Δt²(½ − β)aₙ)/(βΔt²)`
/// (as `angular_acceleration` forms them), from the start and end
/// rotations `(rn, r1)` and the start's `(Wₙ, aₙ)`.
fn increment_pair(
    k: &Coefficients,
    (rn, r1): (&M2, &M2),
    (w_n, a_n): (&V2, &V2),
    dt: f64,
) -> (V2, V2) {
    let s = f64x2::splat;
    // ω = log(Rₙ₊₁Rₙᵀ), the body increment Rₙᵀω and the pseudo-acceleration.
    let omega = log_pair(&mat_mat_t(r1, rn));
    let big = mat_t_vec(rn, &omega);
    let (c_a, c_div) = (dt * dt * (0.5 - k.beta), k.beta * dt * dt);
    let a1: V2 = std::array::from_fn(|c| (big[c] - w_n[c] * s(dt) - a_n[c] * s(c_a)) / s(c_div));
    (omega, a1)
}

/// The Newmark family's body angular pseudo-accelerations at the step's
/// end of nodes `i` (start rotations `r_n`, end rotations `r1`, the start's
/// `W` and `a` in `w`, `alpha`), as `angular_acceleration` gives each.
pub(super) fn angular_acceleration_pair(
    k: &Coefficients,
    (r_n, r1): (&[Matrix3<f64>], &[Matrix3<f64>]),
    (w, alpha): (&[Vector3<f64>], &[Vector3<f64>]),
    i: [usize; 2],
    dt: f64,
) -> [Vector3<f64>; 2] {
    let at = |m: &[Matrix3<f64>]| matrices([&m[i[0]], &m[i[1]]]);
    let v = |x: &[Vector3<f64>]| vectors([&x[i[0]], &x[i[1]]]);
    let (_, a1) = increment_pair(k, (&at(r_n), &at(r1)), (&v(w), &v(alpha)), dt);
    [lane(&a1, 0), lane(&a1, 1)]
}

impl NodePair {
    /// `J₀W` and the moment `Rₙ₊₁(J₀Ȧ + W × J₀W)`.
    fn moment(&self) -> (V2, V2) {
        let jw = mat_vec(&self.j0, &self.w1);
        let (j_acc, gyro) = (mat_vec(&self.j0, &self.acc1), cross(&self.w1, &jw));
        (
            jw,
            mat_vec(&self.r1, &std::array::from_fn(|c| j_acc[c] + gyro[c])),
        )
    }
}

/// The Newmark family's `inertial_moment` of nodes `i` (rotary inertias
/// `j0`, start rotations `r_n`, end rotations `r1`).
pub(super) fn newmark_moment_pair(
    k: &Coefficients,
    rotary: Rotary<'_>,
    prev: &Kinematics,
    i: [usize; 2],
    dt: f64,
) -> V2 {
    newmark_node_pair(k, rotary, prev, i, dt).moment().1
}

/// The Newmark family's `inertial_moment_tangent` of nodes `i`: the moment
/// and its derivative under a spatial spin of the end rotation,
/// `−m̂ + Rₙ₊₁ dv/dȦ RₙᵀH⁻¹(ω)/(βΔt²)` with
/// `dv/dȦ = (1 − α_m)/(1 − α_f) J₀ + γΔt (ŴJ₀ − (J₀W)^)`.
pub(super) fn newmark_tangent_pair(
    k: &Coefficients,
    rotary: Rotary<'_>,
    prev: &Kinematics,
    i: [usize; 2],
    dt: f64,
) -> [(Vector3<f64>, Matrix3<f64>); 2] {
    let node = newmark_node_pair(k, rotary, prev, i, dt);
    let (jw, m) = node.moment();
    let s = f64x2::splat;
    let (c_j, c_g) = ((1.0 - k.alpha_m) / (1.0 - k.alpha_f), k.gamma * dt);
    let wj = mat_mat(&skew(&node.w1), &node.j0);
    let jw_hat = skew(&jw);
    let dv_da: M2 = std::array::from_fn(|e| node.j0[e] * s(c_j) + (wj[e] - jw_hat[e]) * s(c_g));
    let da_deta =
        mat_t_mat(&node.rn, &tangent_inverse(&node.omega)).map(|x| x / s(k.beta * dt * dt));
    let spin = mat_mat(&mat_mat(&node.r1, &dv_da), &da_deta);
    let m_hat = skew(&m);
    let t: M2 = std::array::from_fn(|e| -m_hat[e] + spin[e]);
    [0, 1].map(|l| (lane(&m, l), unpack(&t, l)))
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
    use super::{
        angular_acceleration_pair, in_node_pairs_into, midpoint_moment_pair, moments_in_pairs_into,
        newmark_moment_pair, newmark_tangent_pair, V2,
    };
    use crate::dynamics::mass_slots::inertia_oracle::inertia;
    use crate::dynamics::midpoint::inertial_moment_at;
    use crate::dynamics::newmark_terms::{
        angular_acceleration, inertial_moment, inertial_moment_tangent, Coefficients, Kinematics,
    };
    use flexmech_core::rotation::exp;
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    /// Every node's value in node order, as the terms read them from
    /// [`in_node_pairs_into`].
    fn in_node_pairs<T: Copy + Default + Send>(
        j0: &[Matrix3<f64>],
        single: impl Fn(usize) -> T + Sync,
        pair: impl Fn([usize; 2]) -> Option<[T; 2]> + Sync,
    ) -> Vec<T> {
        let mut out = Vec::new();
        in_node_pairs_into(j0, single, pair, &mut out);
        out.into_iter().flatten().take(j0.len()).collect()
    }

    /// Every node's moment in node order ([`moments_in_pairs_into`]).
    fn moments_in_pairs(
        j0: &[Matrix3<f64>],
        single: impl Fn(usize) -> Vector3<f64> + Sync,
        pair: impl Fn([usize; 2]) -> Option<V2> + Sync,
    ) -> Vec<Vector3<f64>> {
        let mut out = Vec::new();
        moments_in_pairs_into(j0, single, pair, &mut out);
        out.into_iter().flatten().take(j0.len()).collect()
    }

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
                for i in [[0, 1], [2, 3]] {
                    let two = angular_acceleration_pair(&k, (&r_n, &r1), (&prev.w, &prev.alpha), i, dt);
                    for (lane, &n) in i.iter().enumerate() {
                        let one = angular_acceleration(&k, &r_n[n], &r1[n], &prev.w[n], &prev.alpha[n], dt);
                        prop_assert!(one.iter().zip(two[lane].iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "angular acceleration of node {}", n);
                    }
                }
                let one = |i: usize| inertial_moment(&k, &j0[i], &r_n[i], &r1[i], &prev, i, dt);
                let pair = |i| Some(newmark_moment_pair(&k, (&j0, &r_n, &r1), &prev, i, dt));
                let pairs = moments_in_pairs(&j0, one, pair);
                prop_assert_eq!(pairs.len(), NODES);
                for (i, got) in pairs.iter().enumerate() {
                    let expected = if i == bare { Vector3::zeros() } else { one(i) };
                    prop_assert!(expected.iter().zip(got.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "node {}", i);
                }
                let one = |i: usize| inertial_moment_tangent(&k, &j0[i], &r_n[i], &r1[i], &prev, i, dt);
                let pair = |i| Some(newmark_tangent_pair(&k, (&j0, &r_n, &r1), &prev, i, dt));
                for (i, got) in in_node_pairs(&j0, one, pair).iter().enumerate() {
                    let expected = if i == bare { Default::default() } else { one(i) };
                    let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
                    prop_assert!(same(expected.0.as_slice(), got.0.as_slice()), "moment of node {}", i);
                    prop_assert!(same(expected.1.as_slice(), got.1.as_slice()), "tangent of node {}", i);
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
