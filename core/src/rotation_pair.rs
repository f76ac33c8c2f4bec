//! The rotation maps of two nodes at once, one in each lane of a pair of
//! doubles (`wide::f64x2`, SSE2 on x86-64), with the operations of the
//! one-node maps of [`crate::rotation`] in the same order — no fused
//! products, transcendental functions called lane by lane — so that each
//! lane holds the bits the one-node map gives. Where the lanes would take
//! different branches, each lane goes through the one-node map.

use crate::rotation::{log, rodrigues_coefficients, tangent_inverse_coefficient, CAYLEY_DIRECT};
use nalgebra::{Matrix3, Vector3};
use wide::f64x2;

/// A 3-vector of pairs: lane `k` is node `k`'s.
pub type V2 = [f64x2; 3];
/// A 3 × 3 matrix of pairs, row by row.
pub type M2 = [f64x2; 9];

/// The pair `(a, b)`.
#[inline]
pub fn pair(a: f64, b: f64) -> f64x2 {
    f64x2::new([a, b])
}

/// Two vectors as one vector of pairs.
#[inline]
pub fn vectors(v: [&Vector3<f64>; 2]) -> V2 {
    std::array::from_fn(|i| pair(v[0][i], v[1][i]))
}

/// Two matrices as one matrix of pairs, row by row.
#[inline]
pub fn matrices(m: [&Matrix3<f64>; 2]) -> M2 {
    std::array::from_fn(|e| pair(m[0][(e / 3, e % 3)], m[1][(e / 3, e % 3)]))
}

/// Lane `k` of a matrix of pairs (the inverse of [`matrices`]).
#[inline]
pub fn unpack(m: &M2, k: usize) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[3 * i + j].to_array()[k])
}

/// Lane `k` of a vector of pairs.
#[inline]
pub fn lane(v: &V2, k: usize) -> Vector3<f64> {
    Vector3::from_fn(|i, _| v[i].to_array()[k])
}

/// `m v`, each entry `(m₀v₀ + m₁v₁) + m₂v₂` as nalgebra sums it.
#[inline]
pub fn mat_vec(m: &M2, v: &V2) -> V2 {
    std::array::from_fn(|i| m[3 * i] * v[0] + m[3 * i + 1] * v[1] + m[3 * i + 2] * v[2])
}

/// `mᵀ v`, summed as [`mat_vec`].
#[inline]
pub fn mat_t_vec(m: &M2, v: &V2) -> V2 {
    std::array::from_fn(|i| m[i] * v[0] + m[3 + i] * v[1] + m[6 + i] * v[2])
}

/// `a bᵀ`, summed as [`mat_vec`].
#[inline]
pub fn mat_mat_t(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] + a[3 * i + 2] * b[3 * j + 2]
    })
}

/// `(v, v)`.
#[inline]
pub fn splat(v: f64) -> f64x2 {
    f64x2::splat(v)
}

/// A scalar function of one lane applied lane by lane.
#[inline]
pub fn by_lane(x: f64x2, f: impl Fn(f64) -> f64) -> f64x2 {
    let a = x.to_array();
    pair(f(a[0]), f(a[1]))
}

/// `a·b`, summed `(a₀b₀ + a₁b₁) + a₂b₂` as nalgebra sums a 3-vector's.
#[inline]
pub fn dot(a: &V2, b: &V2) -> f64x2 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `s v`.
#[inline]
pub fn scale(v: &V2, s: f64x2) -> V2 {
    v.map(|x| x * s)
}

/// `â`, row by row (as [`crate::rotation::skew`]).
#[inline]
pub fn skew(a: &V2) -> M2 {
    let z = splat(0.0);
    [z, -a[2], a[1], a[2], z, -a[0], -a[1], a[0], z]
}

/// `a aᵀ − |a|² I` (as [`crate::rotation::skew_squared`]).
#[inline]
pub fn skew_squared(a: &V2) -> M2 {
    let n = dot(a, a);
    std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        if i == j {
            a[i] * a[i] - n
        } else {
            a[i] * a[j]
        }
    })
}

/// The identity's entry `e` (row by row).
#[inline]
pub fn id(e: usize) -> f64x2 {
    splat(if e.is_multiple_of(4) { 1.0 } else { 0.0 })
}

/// `s m`.
#[inline]
pub fn mat_scale(m: &M2, s: f64x2) -> M2 {
    m.map(|x| x * s)
}

/// `a b`, each entry summed left to right (as [`crate::rotation::mm`] and
/// nalgebra's product).
#[inline]
pub fn mat_mat(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j]
    })
}

/// `aᵀ b`, each entry summed left to right (as [`crate::rotation::mtm`]).
#[inline]
pub fn mat_t_mat(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j]
    })
}

/// [`crate::rotation::exp`].
#[inline]
pub fn exp(psi: &V2) -> M2 {
    rodrigues_sum(psi, |(a, b, _)| (a, b))
}

/// [`crate::rotation::tangent`].
#[inline]
pub fn tangent(psi: &V2) -> M2 {
    rodrigues_sum(psi, |(_, b, c)| (b, c))
}

/// `I + a ψ̂ + b ψ̂²`, `(a, b)` picked from the Rodrigues coefficients of
/// each lane.
#[inline]
fn rodrigues_sum(psi: &V2, pick: impl Fn((f64, f64, f64)) -> (f64, f64)) -> M2 {
    let t2 = dot(psi, psi).to_array();
    let [(a0, b0), (a1, b1)] = t2.map(|t| pick(rodrigues_coefficients::<f64>(t)));
    let (a, b) = (pair(a0, a1), pair(b0, b1));
    let (sk, sq) = (skew(psi), skew_squared(psi));
    std::array::from_fn(|e| id(e) + sk[e] * a + sq[e] * b)
}

/// [`crate::rotation::tangent_inverse`].
#[inline]
pub fn tangent_inverse(psi: &V2) -> M2 {
    let d = by_lane(dot(psi, psi), tangent_inverse_coefficient::<f64>);
    let (sk, sq) = (skew(psi), skew_squared(psi));
    std::array::from_fn(|e| id(e) - sk[e] * splat(0.5) + sq[e] * d)
}

/// `a × b`, as nalgebra's `cross`.
#[inline]
pub fn cross(a: &V2, b: &V2) -> V2 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Whether [`crate::rotation::quaternion_from_matrix`] reads `r`'s quaternion from its
/// trace (the trace is the largest diagonal term; then `w > 0`).
#[inline]
pub fn from_trace(r: &Matrix3<f64>) -> bool {
    let tr = r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    tr >= r[(0, 0)] && tr >= r[(1, 1)] && tr >= r[(2, 2)]
}

/// [`crate::rotation::quaternion_from_matrix`] of two matrices both read from their trace
/// ([`from_trace`]), `(w, x, y, z)`.
#[inline]
pub fn quaternion_from_trace(r: &M2) -> [f64x2; 4] {
    let tr = r[0] + r[4] + r[8];
    let w = (f64x2::splat(1.0) + tr).sqrt() * f64x2::splat(0.5);
    let f = f64x2::splat(0.25) / w;
    [w, (r[7] - r[5]) * f, (r[2] - r[6]) * f, (r[3] - r[1]) * f]
}

/// [`crate::rotation::cayley_inverse`] of two rotations given as pairs,
/// where both take its direct branch (`1 + tr ≥ 1`; `None` otherwise):
/// `θ = 2 vee(Λ − Λᵀ)/(1 + tr Λ)`.
pub fn cayley_inverse_pair(r: &M2) -> Option<V2> {
    let tr1 = f64x2::splat(1.0) + r[0] + r[4] + r[8];
    if !tr1.to_array().iter().all(|&t| t >= CAYLEY_DIRECT) {
        return None;
    }
    let f = f64x2::splat(2.0) / tr1;
    Some([(r[7] - r[5]) * f, (r[2] - r[6]) * f, (r[3] - r[1]) * f])
}

/// [`log`] of two rotations given as pairs.
pub fn log_pair(packed: &M2) -> V2 {
    let r = [0, 1].map(|k| unpack(packed, k));
    if !(from_trace(&r[0]) && from_trace(&r[1])) {
        let [a, b] = r.map(|r| log(&r));
        return vectors([&a, &b]);
    }
    let [w, x, y, z] = quaternion_from_trace(packed);
    let s2 = x * x + y * y + z * z;
    let factor = log_factor(w, s2);
    [x * factor, y * factor, z * factor]
}

/// `log_quaternion`'s factor `2 atan(s/w)/s` of the vector part (`w > 0`,
/// `s² = s2`): by its series where `s² < 10⁻⁶ w²`, else through `atan2`,
/// called lane by lane.
pub(crate) fn log_factor(w: f64x2, s2: f64x2) -> f64x2 {
    let (wa, sa) = (w.to_array(), s2.to_array());
    let series = [0, 1].map(|k| sa[k] < 1e-6 * wa[k] * wa[k]);
    let two = f64x2::splat(2.0);
    let by_series = || {
        let u = s2 / (w * w);
        let mut acc = f64x2::splat(1.0 / 9.0);
        for ck in [-1.0 / 7.0, 1.0 / 5.0, -1.0 / 3.0, 1.0] {
            acc = acc * u + f64x2::splat(ck);
        }
        acc * two / w
    };
    let by_atan2 = || {
        let s = s2.sqrt();
        let sl = s.to_array();
        pair(sl[0].atan2(wa[0]), sl[1].atan2(wa[1])) * two / s
    };
    match series {
        [true, true] => by_series(),
        [false, false] => by_atan2(),
        _ => {
            let (a, b) = (by_series().to_array(), by_atan2().to_array());
            let pick = |k: usize| if series[k] { a[k] } else { b[k] };
            pair(pick(0), pick(1))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{lane, log_pair, matrices};
    use crate::rotation::{exp, log};
    use nalgebra::Vector3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1024))]

        /// Each lane holds the bits of the one-node logarithm, on every
        /// branch: series and `atan2` (scales from 10⁻⁴ to 3 rad), mixed
        /// lanes, quaternions not read from the trace.
        #[test]
        fn a_pair_of_logarithms_gives_the_bits_of_one_at_a_time(
            dir in prop::array::uniform2(prop::array::uniform3(-1.0..1.0f64)),
            scale in prop::array::uniform2(-4.0..0.5f64),
        ) {
            let r = [0, 1].map(|k| exp(&(Vector3::from(dir[k]) * 10f64.powf(scale[k]))));
            let l = log_pair(&matrices([&r[0], &r[1]]));
            for (k, r) in r.iter().enumerate() {
                let one = log(r);
                prop_assert!(one.iter().zip(lane(&l, k).iter()).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
    }
}
