//! The energy–momentum scheme's cheap tangent — the momentum scheme's
//! closed-form derivative ([`crate::conserving_tangent`]) — of two 2-node
//! elements at once, one element in each lane of a pair of doubles
//! ([`crate::rotation_pair`]): the chain rule of that module's docs with the
//! arithmetic of `BeamElement::momentum_tangent_of` in the same order, so
//! each lane holds the bits of the one-element tangent (tested). The end
//! poses' rotation pieces are taken two at a time too (`frames_of_pair_into`).

use crate::conserving::{Frames, Pose};
use crate::discrete_gradient::{dg_step_in_pairs, step_force};
use crate::element::BeamElement;
use crate::frames_pair::frames_of_pair_into;
use crate::rotation_pair::{
    exp, log_pair, mat_mat, mat_mat_t, mat_scale, mat_vec, matrices, pair, scale, skew, splat,
    tangent, tangent_inverse, vectors, M2, V2,
};
use crate::step_start::StepStart;
use nalgebra::Vector3;

/// `a − b`, entry by entry.
fn sub(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|e| a[e] - b[e])
}

/// `−a`, entry by entry.
fn neg(a: &M2) -> M2 {
    a.map(|x| -x)
}

/// A diagonal matrix of pairs, its off-diagonal entries zero (as
/// `Matrix3::from_diagonal`, whose zeros take part in the products).
fn diagonal(v: &V2) -> M2 {
    let z = splat(0.0);
    [v[0], z, z, z, v[1], z, z, z, v[2]]
}

/// The rows of the element tangent `(−jn, ja − jm, jn, ja + jm)` of the
/// blocks `(η₁, ε₁, η₂, ε₂)` of `n`, `a` and `m`'s Jacobians (`None`: a
/// zero block, which takes part in the sums as the one-element `stack`'s
/// zeros do), written into lane `k`'s 12 × 12 matrix `out[k]` (column-major,
/// as `SMatrix::as_slice`; every entry written).
fn stack_lanes(jn: &[M2; 4], ja: &[M2; 4], jm: &[Option<M2>; 4], mut out: [&mut [f64]; 2]) {
    let zero = [splat(0.0); 9];
    for (b, (n, a)) in jn.iter().zip(ja).enumerate() {
        let m = jm[b].as_ref().unwrap_or(&zero);
        let rows = [neg(n), sub(a, m), *n, std::array::from_fn(|e| a[e] + m[e])];
        for (r, block) in rows.iter().enumerate() {
            for (e, v) in block.iter().enumerate() {
                let v = v.to_array();
                let at = 12 * (3 * b + e % 3) + 3 * r + e / 3;
                for (k, t) in out.iter_mut().enumerate() {
                    t[at] = v[k];
                }
            }
        }
    }
}

/// `BeamElement::momentum_tangent_of` of two elements from their step
/// starts' pieces `s0` to their end poses' pieces `s1`, with the step
/// averages of their resultants `res` (`BeamElement::averaged_from`), lane
/// by lane the same bits, into the column-major 12 × 12 slices `out`.
fn momentum_tangent_pair(
    e: [&BeamElement<2>; 2],
    (s0, s1): ([&Frames<f64>; 2], [&Frames<f64>; 2]),
    res: &[(Vector3<f64>, Vector3<f64>); 2],
    out: [&mut [f64]; 2],
) {
    let (nbar, mbar) = (
        vectors([&res[0].0, &res[1].0]),
        vectors([&res[0].1, &res[1].1]),
    );
    let half = splat(0.5);
    let (lam_r0, lam_r1) = (
        matrices([&s0[0].lam_r, &s0[1].lam_r]),
        matrices([&s1[0].lam_r, &s1[1].lam_r]),
    );
    let omega = log_pair(&mat_mat_t(&lam_r1, &lam_r0));
    let lt = mat_mat(&exp(&scale(&omega, half)), &lam_r0);
    let (n, m) = (mat_vec(&lt, &nbar), mat_vec(&lt, &mbar));
    let d0 = vectors([&s0[0].d, &s0[1].d]);
    let d1 = vectors([&s1[0].d, &s1[1].d]);
    let dbar: V2 = std::array::from_fn(|i| (d0[i] + d1[i]) * half);
    // S, P, G of the module docs of `conserving_tangent`.
    let phi = vectors([&s1[0].phi, &s1[1].phi]);
    let lam1 = matrices([&s1[0].lam[0], &s1[1].lam[0]]);
    let s = mat_mat_t(&tangent_inverse(&phi), &lam1);
    let p = mat_scale(
        &mat_mat(&mat_mat(&lam1, &tangent(&scale(&phi, half))), &s),
        half,
    );
    let g = mat_scale(
        &mat_mat(&tangent(&scale(&omega, half)), &tangent_inverse(&omega)),
        half,
    );
    let h = pair(0.5 / e[0].length, 0.5 / e[1].length);
    let c = |v: [&Vector3<f64>; 2]| diagonal(&scale(&vectors(v), h));
    let cn = c([&e[0].section.c_n, &e[1].section.c_n]);
    let cm = c([&e[0].section.c_m, &e[1].section.c_m]);
    let lta = mat_mat_t(&mat_mat(&lt, &cn), &lam_r1);
    let ltad = mat_mat(&lta, &skew(&d1));
    let ltds = mat_mat(&mat_mat(&lt, &cm), &s);
    let (ng, mg) = (mat_mat(&skew(&n), &g), mat_mat(&skew(&m), &g));
    let ltad_ng = sub(&ltad, &ng);
    let jn_e2 = mat_mat(&ltad_ng, &p);
    let jn_e1 = sub(&ltad_ng, &jn_e2);
    let jm_e2 = sub(&ltds, &mat_mat(&mg, &p));
    let jm_e1 = sub(&neg(&mg), &jm_e2);
    let half_dbar = mat_scale(&skew(&dbar), half);
    let ja_x2 = sub(
        &mat_scale(&skew(&n), splat(0.25)),
        &mat_mat(&half_dbar, &lta),
    );
    let minus_half_dbar = neg(&half_dbar);
    stack_lanes(
        &[neg(&lta), jn_e1, lta, jn_e2],
        &[
            neg(&ja_x2),
            mat_mat(&minus_half_dbar, &jn_e1),
            ja_x2,
            mat_mat(&minus_half_dbar, &jn_e2),
        ],
        &[None, Some(jm_e1), None, Some(jm_e2)],
        out,
    );
}

impl BeamElement<2> {
    /// [`BeamElement::energy_momentum_cheap_tangent_from`] of two elements
    /// from their step starts to their end poses, two at a time (the end
    /// poses' pieces too, where both relative rotations are read from their
    /// trace; else one by one), written into `k` (each a column-major
    /// 12 × 12 slice, as `SMatrix::as_slice`); with `forces`, each
    /// element's force of [`BeamElement::energy_momentum_force_cheap_tangent_from`]
    /// too (its discrete gradient one element at a time). The same bits.
    ///
    /// # Panics
    /// Where a slice of `k` is not 144 long or one of `forces` not 12.
    pub fn energy_momentum_cheap_tangent_pair_into(
        e: [&Self; 2],
        start: [&StepStart; 2],
        end: [&Pose<f64>; 2],
        forces: Option<[&mut [f64]; 2]>,
        k: [&mut [f64]; 2],
    ) {
        let mut ends = [Frames::zeros(); 2];
        let [a, b] = &mut ends;
        frames_of_pair_into(e, end, [a, b]);
        let s0 = [start[0].frames(), start[1].frames()];
        let res = [0, 1].map(|i| e[i].averaged_from(start[i], &ends[i]));
        momentum_tangent_pair(e, (s0, [&ends[0], &ends[1]]), &res, k);
        for (i, r) in forces.into_iter().flatten().enumerate() {
            let q = step_force(&dg_step_in_pairs(s0[i], &ends[i]), &res[i].0, &res[i].1).0;
            r.copy_from_slice(q.as_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element_pair::tests::pairs;
    use crate::rotation::exp as exp1;

    fn bits(m: &[f64]) -> Vec<u64> {
        m.iter().map(|v| v.to_bits()).collect()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(512))]
        /// Every lane is the one-element cheap tangent to the bit, on every
        /// branch of the pieces and coefficients: the step's rotation from
        /// 10⁻⁷ rad (the series of `H` and `H⁻¹` of the mid rotation) to
        /// about a radian, the end poses' relative rotations as in the
        /// force pair's test.
        #[test]
        fn a_pair_gives_the_bits_of_one_elements_cheap_tangent(
            (es, x, rot) in pairs(),
            spin in proptest::array::uniform2(proptest::array::uniform3(-1.0..1.0f64)),
            size in proptest::array::uniform2(-7.0..0.0f64),
        ) {
            let poses: [Pose<f64>; 2] = [0, 1].map(|k| (x[k], rot[k]));
            let starts = [0, 1].map(|k| {
                let turn = exp1(&(Vector3::from(spin[k]) * 10f64.powf(size[k])));
                let moved = x[k].map(|p| p - Vector3::from(spin[k]) * 0.01);
                es[k].step_start(&(moved, rot[k].map(|r| turn * r)))
            });
            // Every entry is written: the slices start as NaN.
            let (mut two, mut both) = ([[f64::NAN; 144]; 2], [[f64::NAN; 144]; 2]);
            let mut forces = [[f64::NAN; 12]; 2];
            let (e, s, p) = ([&es[0], &es[1]], [&starts[0], &starts[1]], [&poses[0], &poses[1]]);
            let [ta, tb] = &mut two;
            BeamElement::energy_momentum_cheap_tangent_pair_into(e, s, p, None, [ta, tb]);
            let ([ba, bb], [fa, fb]) = (&mut both, &mut forces);
            BeamElement::energy_momentum_cheap_tangent_pair_into(e, s, p, Some([fa, fb]), [ba, bb]);
            for k in 0..2 {
                let one = es[k].energy_momentum_cheap_tangent_from(&starts[k], &poses[k]);
                proptest::prop_assert_eq!(bits(&two[k]), bits(one.as_slice()), "lane {}", k);
                let (q, t) = es[k].energy_momentum_force_cheap_tangent_from(&starts[k], &poses[k]);
                proptest::prop_assert_eq!(bits(&both[k]), bits(t.as_slice()), "lane {}", k);
                proptest::prop_assert_eq!(bits(&forces[k]), bits(q.as_slice()), "lane {}", k);
            }
        }
    }
}
