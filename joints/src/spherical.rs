//! Spherical (ball) joint: all three rotations released, no translation.
//! The released rotation is kept as a matrix and updated multiplicatively,
//! `Λ_R ← exp(ω̂) Λ_R` with `ω` in the master body frame, so the slave's spin
//! is `δφ_s = δφ_m + Λ_m δω`.

use crate::kinematics::{Increments, JointKinematics, ReleasedState, MAX_RELEASED};
use crate::model_joint::{ModelJoint, NoParams, ParamError};
use flexmech_core::rotation::{exp, log};
use flexmech_core::{cst, Scalar};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The spherical joint.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Spherical;

impl JointKinematics for Spherical {
    const RELEASED: usize = 3;

    fn released<T: Scalar>(
        &self,
        state: &ReleasedState,
        inc: Increments<'_, T>,
    ) -> (Vector3<T>, Matrix3<T>) {
        let a = Vector3::new(inc.first[0], inc.first[1], inc.first[2]);
        let b = Vector3::new(inc.second[0], inc.second[1], inc.second[2]);
        (
            Vector3::zeros(),
            exp(&a) * exp(&b) * state.rot.map(cst::<T>),
        )
    }

    /// The released increment is the rotation increment itself: `τ = θ_R`,
    /// `B = [0; I]`.
    fn step_map<T: Scalar>(
        &self,
        _start: &ReleasedState,
        _end: &ReleasedState,
        _inc: &[T; MAX_RELEASED],
    ) -> SMatrix<T, 6, MAX_RELEASED> {
        let mut b = SMatrix::<T, 6, MAX_RELEASED>::zeros();
        b.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&Matrix3::identity());
        b
    }

    fn advance(&self, state: &mut ReleasedState, delta: &[f64]) {
        state.rot = exp(&Vector3::new(delta[0], delta[1], delta[2])) * state.rot;
    }

    fn coordinate_names(&self) -> &'static [&'static str] {
        &["rx", "ry", "rz"]
    }

    /// The magnitude of the released rotation.
    fn reported_angle(&self, state: &ReleasedState) -> Option<f64> {
        Some(log(&state.rot).norm())
    }
}

impl ModelJoint for Spherical {
    const NAME: &'static str = "spherical";
    type Params = NoParams;
    fn from_params(_: NoParams) -> Result<Self, ParamError> {
        Ok(Spherical)
    }
}
