//! A 2-node element's start of a time step, computed once per step: the
//! start pose's rotation pieces (`Frames`: triads, relative rotation, its
//! logarithm and half, reference rotation) that every Newton evaluation of
//! the conserving schemes needs again, since the start pose stays put while
//! the end pose is iterated. The kernels taking a [`StepStart`] are the ones
//! taking both poses with the start's pieces looked up instead of
//! recomputed: the same arithmetic, so the same results to the bit (tested).

use crate::conserving::{Frames, Pose};
use crate::discrete_gradient::{dg_step_in_pairs, step_force};
use crate::element::BeamElement;
use crate::frames_pair::frames_of_pair_into;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// An element's pose at the start of a step with its rotation pieces and
/// its resultants there.
#[derive(Debug, Clone)]
pub struct StepStart {
    pose: Pose<f64>,
    frames: Frames<f64>,
    /// The material resultants `(N, M)` at the start pose
    /// (`BeamElement::frame_resultants` of `frames`).
    resultants: (Vector3<f64>, Vector3<f64>),
}

impl StepStart {
    /// Whether this is the start of a step from `pose` (exactly: any other
    /// pose recomputes its pieces, so a start kept past its step is never
    /// used for another).
    pub fn is_of(&self, pose: &Pose<f64>) -> bool {
        self.pose == *pose
    }

    /// The pose this is the start of.
    pub fn pose(&self) -> &Pose<f64> {
        &self.pose
    }

    /// A start of no pose (its pose is NaN, so [`Self::is_of`] holds for
    /// none): a place for [`BeamElement::step_start_into`] and
    /// [`BeamElement::step_start_pair_into`].
    pub fn unset() -> Self {
        StepStart {
            pose: (
                [Vector3::repeat(f64::NAN); 2],
                [Matrix3::repeat(f64::NAN); 2],
            ),
            frames: Frames::zeros(),
            resultants: (Vector3::zeros(), Vector3::zeros()),
        }
    }

    /// The start pose's rotation pieces.
    pub(crate) fn frames(&self) -> &Frames<f64> {
        &self.frames
    }
}

impl BeamElement<2> {
    /// The element's [`StepStart`] at `pose`.
    pub fn step_start(&self, pose: &Pose<f64>) -> StepStart {
        let mut start = StepStart::unset();
        self.step_start_into(pose, &mut start);
        start
    }

    /// [`Self::step_start`] at `pose`, written into `out`.
    pub fn step_start_into(&self, pose: &Pose<f64>, out: &mut StepStart) {
        out.pose = *pose;
        out.frames = self.frames(pose);
        out.resultants = self.frame_resultants(&out.frames);
    }

    /// The [`StepStart`]s of two elements at their poses, written into
    /// `out`, their rotation pieces two at a time where the pair arithmetic
    /// takes them (`frames_pair`): the same bits as [`Self::step_start`] of
    /// each. (In place: moved by value, the 520-byte starts were copied
    /// with `memcpy` several times over at every step.)
    pub fn step_start_pair_into(e: [&Self; 2], poses: [&Pose<f64>; 2], out: [&mut StepStart; 2]) {
        let [a, b] = out;
        frames_of_pair_into(e, poses, [&mut a.frames, &mut b.frames]);
        (a.pose, b.pose) = (*poses[0], *poses[1]);
        a.resultants = e[0].frame_resultants(&a.frames);
        b.resultants = e[1].frame_resultants(&b.frames);
    }

    /// `BeamElement::averaged_resultants` from a step's start to the end
    /// pose's pieces `end`, the start's resultants looked up: the same bits.
    pub(crate) fn averaged_from(
        &self,
        start: &StepStart,
        end: &Frames<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let ((n0, m0), (n1, m1)) = (start.resultants, self.frame_resultants(end));
        ((n0 + n1) * 0.5, (m0 + m1) * 0.5)
    }

    /// [`Self::energy_momentum_force_parts`] from a step's start.
    pub fn energy_momentum_force_parts_from(
        &self,
        start: &StepStart,
        end: &Pose<f64>,
    ) -> (SVector<f64, 12>, SVector<f64, 12>) {
        let (s, e) = (&start.frames, &self.frames(end));
        let (nbar, mbar) = self.averaged_from(start, e);
        step_force(&dg_step_in_pairs(s, e), &nbar, &mbar)
    }

    /// [`Self::energy_momentum_force_cheap_tangent`] from a step's start.
    pub fn energy_momentum_force_cheap_tangent_from(
        &self,
        start: &StepStart,
        end: &Pose<f64>,
    ) -> (SVector<f64, 12>, SMatrix<f64, 12, 12>) {
        let (s0, s1) = (&start.frames, &self.frames(end));
        let (nbar, mbar) = self.averaged_from(start, s1);
        let q = step_force(&dg_step_in_pairs(s0, s1), &nbar, &mbar).0;
        (q, self.momentum_tangent_of(s0, s1).1)
    }

    /// The cheap tangent of [`Self::energy_momentum_force_cheap_tangent_from`]
    /// alone, its force left out (the discrete gradient, most of that
    /// kernel's work): the same bits.
    pub fn energy_momentum_cheap_tangent_from(
        &self,
        start: &StepStart,
        end: &Pose<f64>,
    ) -> SMatrix<f64, 12, 12> {
        self.momentum_tangent_of(&start.frames, &self.frames(end)).1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::exp;
    use crate::Section;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn kernels_from_a_step_start_equal_those_from_both_poses_to_the_bit() {
        let sec = Section::new(
            [1.0e7, 5.0e6, 5.0e6],
            [7.0e5, 8.0e5, 8.3e5],
            1.0,
            [0.2, 0.1, 0.1],
        );
        let x0 = [Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
        let e = BeamElement::new([0, 1], sec, 1.0, &x0, [Matrix3::identity(); 2]);
        let start: Pose<f64> = (
            [Vector3::new(0.01, 0.02, 0.0), Vector3::new(0.9, 0.3, 0.1)],
            [
                exp(&Vector3::new(0.1, 0.2, 0.3)),
                exp(&Vector3::new(-0.2, 0.5, 0.9)),
            ],
        );
        let end: Pose<f64> = (
            [start.0[0] + Vector3::new(0.01, -0.02, 0.005), start.0[1]],
            [
                exp(&Vector3::new(0.02, -0.01, 0.03)) * start.1[0],
                start.1[1],
            ],
        );
        let s = e.step_start(&start);
        assert!(s.is_of(&start) && !s.is_of(&end));
        assert_eq!(
            e.energy_momentum_force_parts_from(&s, &end),
            e.energy_momentum_force_parts(&start, &end)
        );
        assert_eq!(
            e.energy_momentum_force_cheap_tangent_from(&s, &end),
            e.energy_momentum_force_cheap_tangent(&start, &end)
        );
        assert_eq!(
            e.energy_momentum_cheap_tangent_from(&s, &end),
            e.energy_momentum_force_cheap_tangent(&start, &end).1
        );
    }
}
