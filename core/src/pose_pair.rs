//! [`increment_pose`] for two nodes at once — the multiplicative update
//! `x ← x + u`, `Λ ← exp(φ̂)Λ` of FORMULATION §1, composed as unit
//! quaternions — one node in each lane of a pair of doubles: the same
//! operations in the same order (no fused products), so the same bits,
//! with the square roots and divisions of both nodes issued together (a
//! node's chain of them is what its update waits on). Where the two nodes
//! take different branches of the rotation maps (a large increment, a
//! rotation whose quaternion is not read from its trace) each goes its own
//! way through [`increment_pose`].

use crate::rotation::{rotation_entries, SERIES_LIMIT};
use crate::rotation_pair::{
    cross, from_trace, matrices, pair, quaternion_from_trace, unpack, vectors, V2,
};
use crate::state::increment_pose;
use nalgebra::{Matrix3, Vector3};
use wide::f64x2;

/// `increment_pose(x[k], rot[k], u[k], phi[k])` for `k = 0, 1`.
pub fn increment_pose_pair(
    x: [&mut Vector3<f64>; 2],
    rot: [&mut Matrix3<f64>; 2],
    u: [&Vector3<f64>; 2],
    phi: [&Vector3<f64>; 2],
) {
    let t2: [f64; 2] = std::array::from_fn(|k| phi[k].norm_squared());
    let lanes = t2.iter().all(|&t| t < SERIES_LIMIT) && from_trace(rot[0]) && from_trace(rot[1]);
    let [x0, x1] = x;
    let [r0, r1] = rot;
    if !lanes {
        increment_pose(x0, r0, u[0], phi[0]);
        increment_pose(x1, r1, u[1], phi[1]);
        return;
    }
    *x0 += u[0];
    *x1 += u[1];
    let e = exp_series(&vectors(phi), pair(t2[0], t2[1]));
    let q = quaternion_from_trace(&matrices([r0, r1]));
    let p = normalize(product(&e, &q));
    let m = rotation_entries(p, f64x2::splat(1.0), f64x2::splat(2.0));
    for (k, r) in [r0, r1].into_iter().enumerate() {
        *r = unpack(&m, k);
    }
}

/// The increments `inc(first + k)` (translation, spatial rotation vector;
/// `None`: the node stays) of the poses `(xs[k], rs[k])`, applied as
/// [`increment_pose`] would one node at a time — two nodes at once
/// ([`increment_pose_pair`]) wherever two are moved.
pub fn increment_poses(
    first: usize,
    xs: &mut [Vector3<f64>],
    rs: &mut [Matrix3<f64>],
    inc: impl Fn(usize) -> Option<(Vector3<f64>, Vector3<f64>)>,
) {
    let mut pending: Option<(usize, Vector3<f64>, Vector3<f64>)> = None;
    for k in 0..xs.len().min(rs.len()) {
        let Some((u, phi)) = inc(first + k) else {
            continue;
        };
        let Some((j, uj, phij)) = pending.take() else {
            pending = Some((k, u, phi));
            continue;
        };
        let ((xa, xb), (ra, rb)) = (xs.split_at_mut(k), rs.split_at_mut(k));
        increment_pose_pair(
            [&mut xa[j], &mut xb[0]],
            [&mut ra[j], &mut rb[0]],
            [&uj, &u],
            [&phij, &phi],
        );
    }
    if let Some((j, u, phi)) = pending {
        increment_pose(&mut xs[j], &mut rs[j], &u, &phi);
    }
}

/// `exp_quaternion` by its series (`|ψ|² = t2 <` [`SERIES_LIMIT`]).
fn exp_series(psi: &V2, t2: f64x2) -> [f64x2; 4] {
    let x = t2 * f64x2::splat(0.25);
    let w = horner(x, &[1.0, -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0]);
    let f = horner(
        x,
        &[
            0.5,
            -1.0 / 12.0,
            1.0 / 240.0,
            -1.0 / 10080.0,
            1.0 / 725760.0,
        ],
    );
    [w, psi[0] * f, psi[1] * f, psi[2] * f]
}

/// `Σ cₖ xᵏ` by Horner's rule from the highest term, as `series` does.
fn horner(x: f64x2, c: &[f64]) -> f64x2 {
    let mut acc = f64x2::splat(c[c.len() - 1]);
    for &ck in c.iter().rev().skip(1) {
        acc = acc * x + f64x2::splat(ck);
    }
    acc
}

/// The Hamilton product `a ⊗ b`, as `quaternion_product`.
fn product(a: &[f64x2; 4], b: &[f64x2; 4]) -> [f64x2; 4] {
    let (aw, av) = (a[0], [a[1], a[2], a[3]]);
    let (bw, bv) = (b[0], [b[1], b[2], b[3]]);
    let cross = cross(&av, &bv);
    let v: V2 = std::array::from_fn(|i| bv[i] * aw + av[i] * bw + cross[i]);
    let dot = av[0] * bv[0] + av[1] * bv[1] + av[2] * bv[2];
    [aw * bw - dot, v[0], v[1], v[2]]
}

/// `q / |q|`, as nalgebra's `normalize` (whose squared norm of a 4-vector
/// sums the first and third squares, the second and fourth, then both).
fn normalize(q: [f64x2; 4]) -> [f64x2; 4] {
    let n = ((q[0] * q[0] + q[2] * q[2]) + (q[1] * q[1] + q[3] * q[3])).sqrt();
    q.map(|c| c / n)
}

#[cfg(test)]
mod tests {
    use super::increment_pose_pair;
    use crate::rotation::exp;
    use crate::state::increment_pose;
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    fn v(a: [f64; 3]) -> Vector3<f64> {
        Vector3::from(a)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Both lanes give the bits of one node at a time, on either branch
        /// of the maps (increments past the series' range, rotations past
        /// a half turn whose quaternion is not read from the trace).
        #[test]
        fn a_pair_gives_the_bits_of_one_node_at_a_time(
            rot in prop::array::uniform2(prop::array::uniform3(-3.0..3.0f64)),
            phi in prop::array::uniform2(prop::array::uniform3(-0.08..0.08f64)),
            u in prop::array::uniform2(prop::array::uniform3(-1.0..1.0f64)),
            x in prop::array::uniform2(prop::array::uniform3(-5.0..5.0f64)),
        ) {
            let (mut xp, mut rp): ([Vector3<f64>; 2], [Matrix3<f64>; 2]) =
                (x.map(v), rot.map(|r| exp(&v(r))));
            let (mut xs, mut rs) = (xp, rp);
            let (u, phi) = (u.map(v), phi.map(v));
            let [x0, x1] = &mut xp;
            let [r0, r1] = &mut rp;
            increment_pose_pair([x0, x1], [r0, r1], [&u[0], &u[1]], [&phi[0], &phi[1]]);
            for k in 0..2 {
                increment_pose(&mut xs[k], &mut rs[k], &u[k], &phi[k]);
                prop_assert!(xs[k].iter().zip(xp[k].iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
                prop_assert!(rs[k].iter().zip(rp[k].iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
    }
}
