//! Rigid joint: nothing released; the slave moves with the master
//! (`r_R = 0`, `Λ_R = I`), so two beams that meet at a point act as one.

use crate::kinematics::{JointKinematics, NoCoordinates};
use crate::model_joint::{ModelJoint, NoParams, ParamError};
use flexmech_core::Scalar;
use nalgebra::{Matrix3, Vector3};

/// The rigid joint.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Rigid;

impl JointKinematics for Rigid {
    type Coordinates = NoCoordinates;

    fn released<T: Scalar>(&self, _: &()) -> (Vector3<T>, Matrix3<T>) {
        (Vector3::zeros(), Matrix3::identity())
    }
}

impl ModelJoint for Rigid {
    const NAME: &'static str = "rigid";
    type Params = NoParams;
    fn from_params(_: NoParams) -> Result<Self, ParamError> {
        Ok(Rigid)
    }
}
