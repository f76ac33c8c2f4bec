//! The rotation pieces (`Frames`) of two 2-node element poses at once, one
//! element in each lane of a pair of doubles ([`crate::rotation_pair`]): the
//! arithmetic of `BeamElement::frames` in the same order, so each lane
//! holds the bits of the one-element pieces (tested). The energy–momentum
//! scheme's residual-only evaluations take the end pose's pieces of two
//! neighbouring elements this way ([`energy_momentum_force_pair_into`]).

use crate::conserving::{Frames, Pose};
use crate::discrete_gradient::{dg_step_in_pairs, step_force};
use crate::element::BeamElement;
use crate::element_pair::triads;
use crate::rotation_pair::{
    exp, from_trace, lane, log_factor, mat_mat, mat_t_mat, quaternion_from_trace, scale, splat,
    unpack,
};
use crate::step_start::StepStart;
use nalgebra::Vector4;
use wide::f64x2;

/// [`BeamElement::frames`] of two elements' poses, written into `out`;
/// `false` (and `out` unchanged) where a relative rotation's quaternion is
/// not read from its trace (a relative rotation beyond a half turn's
/// neighbourhood: the one-element path handles it). Two `Frames` are 656
/// bytes: returned by value, they were moved with a call to `memcpy`.
pub(crate) fn frames_pair_into(
    e: [&BeamElement<2>; 2],
    poses: [&Pose<f64>; 2],
    out: [&mut Frames<f64>; 2],
) -> bool {
    let lam = triads(e, [&poses[0].1, &poses[1].1]);
    let rel = mat_t_mat(&lam[0], &lam[1]);
    if !(0..2).all(|k| from_trace(&unpack(&rel, k))) {
        return false;
    }
    // `log_quaternion`: `w ≥ 0` from the trace, no sign flip.
    let [w, x, y, z] = quaternion_from_trace(&rel);
    let s2 = x * x + y * y + z * z;
    let factor = log_factor(w, s2);
    let phi = [x * factor, y * factor, z * factor];
    // `quaternion_half`: `(1 + w, v)/√(2(1 + w))`.
    let w1 = splat(1.0) + w;
    let f = splat(1.0) / (w1 * splat(2.0)).sqrt();
    let half = [w1 * f, x * f, y * f, z * f];
    let lam_r = mat_mat(&lam[0], &exp(&scale(&phi, splat(0.5))));
    let quaternion = |q: &[f64x2; 4], k: usize| Vector4::from_fn(|i, _| q[i].to_array()[k]);
    for (k, f) in out.into_iter().enumerate() {
        f.lam[0] = unpack(&lam[0], k);
        f.lam[1] = unpack(&lam[1], k);
        f.rel = quaternion(&[w, x, y, z], k);
        f.phi = lane(&phi, k);
        f.half = quaternion(&half, k);
        f.lam_r = unpack(&lam_r, k);
        f.d = poses[k].0[1] - poses[k].0[0];
    }
    true
}

/// [`BeamElement::frames`] of two elements' poses into `out`, two at a time
/// where [`frames_pair_into`] takes them, else one by one: the same bits.
/// (Written in place: returned by value, the two were moved with a call to
/// `memcpy` at every evaluation.)
pub(crate) fn frames_of_pair_into(
    e: [&BeamElement<2>; 2],
    poses: [&Pose<f64>; 2],
    out: [&mut Frames<f64>; 2],
) {
    let [a, b] = out;
    if !frames_pair_into(e, poses, [&mut *a, &mut *b]) {
        for (f, (e, pose)) in [a, b].into_iter().zip(e.iter().zip(poses)) {
            *f = e.frames(pose);
        }
    }
}

/// [`BeamElement::energy_momentum_force_parts_from`] of two elements from
/// their step starts to their end poses, the end poses' pieces two at a
/// time (`frames_pair_into`): each element's force written into `forces`
/// (12 long each) and the norms `(‖corrections‖, ‖force‖)` of its parts
/// returned, the same bits. (Written in place: the four vectors returned
/// by value were moved with a call to `memcpy` at every evaluation.)
///
/// # Panics
/// Where a slice of `forces` is not 12 long.
pub fn energy_momentum_force_pair_into(
    e: [&BeamElement<2>; 2],
    start: [&StepStart; 2],
    end: [&Pose<f64>; 2],
    forces: [&mut [f64]; 2],
) -> [(f64, f64); 2] {
    let mut ends = [Frames::zeros(); 2];
    let [a, b] = &mut ends;
    frames_of_pair_into(e, end, [a, b]);
    let mut norms = [(0.0, 0.0); 2];
    for (k, r) in forces.into_iter().enumerate() {
        let (s, f) = (start[k].frames(), &ends[k]);
        let (nbar, mbar) = e[k].averaged_from(start[k], f);
        let (q, c) = step_force(&dg_step_in_pairs(s, f), &nbar, &mbar);
        r.copy_from_slice(q.as_slice());
        norms[k] = (c.norm(), q.norm());
    }
    norms
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::exp as exp1;
    use crate::Section;
    use nalgebra::{Matrix3, Vector3};
    use proptest::prelude::*;

    /// An element whose initial triads differ by `kink` about z.
    fn element(kink: f64) -> BeamElement<2> {
        let section = Section::new([2e4, 1e4, 1e4], [30.0, 20.0, 10.0], 1.0, [0.1; 3]);
        let x0 = [Vector3::zeros(), Vector3::new(0.5, 0.0, 0.0)];
        let l0 = [Matrix3::identity(), exp1(&(Vector3::z() * kink))];
        BeamElement::new([0, 1], section, 0.5, &x0, l0)
    }

    fn pose(x: [f64; 6], psi: [f64; 6]) -> Pose<f64> {
        (
            [
                Vector3::new(x[0], x[1], x[2]),
                Vector3::new(x[3], x[4], x[5]),
            ],
            [
                exp1(&Vector3::new(psi[0], psi[1], psi[2])),
                exp1(&Vector3::new(psi[3], psi[4], psi[5])),
            ],
        )
    }

    fn bits(f: &Frames<f64>) -> Vec<u64> {
        let m = f.lam[0].iter().chain(f.lam[1].iter()).chain(f.lam_r.iter());
        let v = f
            .rel
            .iter()
            .chain(f.phi.iter())
            .chain(f.half.iter())
            .chain(f.d.iter());
        m.chain(v).map(|v| v.to_bits()).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]
        /// Every lane is the one-element pieces to the bit, on every branch:
        /// relative rotations from the identity (the logarithm's series) to
        /// beyond a half turn (the one-element path).
        #[test]
        fn a_pair_gives_the_bits_of_one_element_at_a_time(
            x in proptest::array::uniform12(-1.0f64..1.0),
            psi in proptest::array::uniform12(-2.0f64..2.0),
            small in proptest::array::uniform2(0u8..3),
            kink in -0.3f64..0.3,
        ) {
            let es = [element(kink), element(0.1 - kink)];
            let poses: [Pose<f64>; 2] = [0, 1].map(|k| {
                let mut p: [f64; 6] = std::array::from_fn(|i| psi[6 * k + i]);
                // Nearly equal nodal rotations: the logarithm's series.
                let near = [1.0, 1e-4, 1e-9][usize::from(small[k])];
                for i in 3..6 {
                    p[i] = p[i - 3] + near * p[i];
                }
                pose(std::array::from_fn(|i| x[6 * k + i]), p)
            });
            let one = [0, 1].map(|k| es[k].frames(&poses[k]));
            let mut two = [Frames::zeros(); 2];
            let [a, b] = &mut two;
            match frames_pair_into([&es[0], &es[1]], [&poses[0], &poses[1]], [a, b]) {
                true => for k in 0..2 {
                    prop_assert_eq!(bits(&two[k]), bits(&one[k]), "lane {}", k);
                },
                false => prop_assert!((0..2).any(|k| !from_trace(
                    &(one[k].lam[0].transpose() * one[k].lam[1])
                ))),
            }
            // The step starts of a pair, on either path: each element's bits.
            let mut started = [StepStart::unset(), StepStart::unset()];
            let [a, b] = &mut started;
            BeamElement::step_start_pair_into([&es[0], &es[1]], [&poses[0], &poses[1]], [a, b]);
            for k in 0..2 {
                prop_assert!(started[k].is_of(&poses[k]));
                prop_assert_eq!(bits(started[k].frames()), bits(&one[k]), "start {}", k);
            }
            let starts = [0, 1].map(|k| es[k].step_start(&pose([0.0; 6], [0.01 * k as f64; 6])));
            let mut forces = [[f64::NAN; 12]; 2];
            let [fa, fb] = &mut forces;
            let norms = energy_momentum_force_pair_into(
                [&es[0], &es[1]],
                [&starts[0], &starts[1]],
                [&poses[0], &poses[1]],
                [fa, fb],
            );
            for k in 0..2 {
                let (q, c) = es[k].energy_momentum_force_parts_from(&starts[k], &poses[k]);
                let b = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                prop_assert_eq!(b(&forces[k]), b(q.as_slice()));
                prop_assert_eq!(norms[k].0.to_bits(), c.norm().to_bits());
                prop_assert_eq!(norms[k].1.to_bits(), q.norm().to_bits());
            }
        }
    }

    #[test]
    fn relative_rotations_beyond_the_trace_branch_go_one_element_at_a_time() {
        let e = element(0.0);
        let p = pose(
            [0.0, 0.0, 0.0, 0.5, 0.0, 0.0],
            [0.0, 0.0, 0.0, 3.0, 0.0, 0.0],
        );
        let [mut a, mut b] = [Frames::zeros(); 2];
        assert!(!frames_pair_into([&e, &e], [&p, &p], [&mut a, &mut b]));
    }
}
