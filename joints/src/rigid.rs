//! Rigid joint: nothing released; the slave moves with the master
//! (`r_R = 0`, `Λ_R = I`), so two beams that meet at a point act as one.

use crate::kinematics::{Increments, JointKinematics, ReleasedState};
use crate::model_joint::{ModelJoint, NoParams, ParamError};
use flexmech_core::Scalar;
use nalgebra::{Matrix3, Vector3};

/// The rigid joint.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Rigid;

impl JointKinematics for Rigid {
    const RELEASED: usize = 0;

    fn released<T: Scalar>(
        &self,
        _: &ReleasedState,
        _: Increments<'_, T>,
    ) -> (Vector3<T>, Matrix3<T>) {
        (Vector3::zeros(), Matrix3::identity())
    }

    fn coordinate_names(&self) -> &'static [&'static str] {
        &[]
    }
}

impl ModelJoint for Rigid {
    const NAME: &'static str = "rigid";
    type Params = NoParams;
    fn from_params(_: NoParams) -> Result<Self, ParamError> {
        Ok(Rigid)
    }
}
