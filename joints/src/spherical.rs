//! Spherical (ball) joint: all three rotations released, no translation.
//! The released rotation is kept as a matrix and updated multiplicatively,
//! `Λ_R ← exp(ω̂) Λ_R` with `ω` in the master body frame, so the slave's spin
//! is `δφ_s = δφ_m + Λ_m δω`.

use crate::kinematics::{BallRotation, JointKinematics};
use crate::model_joint::{ModelJoint, NoParams, ParamError};
use flexmech_core::Scalar;
use nalgebra::{Matrix3, Vector3};

/// The spherical joint.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Spherical;

impl JointKinematics for Spherical {
    type Coordinates = BallRotation;

    fn released<T: Scalar>(&self, rotation: &Matrix3<T>) -> (Vector3<T>, Matrix3<T>) {
        (Vector3::zeros(), *rotation)
    }
}

impl ModelJoint for Spherical {
    const NAME: &'static str = "spherical";
    type Params = NoParams;
    fn from_params(_: NoParams) -> Result<Self, ParamError> {
        Ok(Spherical)
    }
}
