//! Revolute (hinge) joint: one released rotation about the axis `t`, no
//! released translation — the dependent joint with `f(ψ) = 0`.

use crate::dependent::DependentJoint;
use crate::model_joint::{direction, AxisParams, ModelJoint, ParamError};
use flexmech_core::Scalar;
use nalgebra::Vector3;

/// The revolute joint about the unit `axis` (master body frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Revolute {
    /// Unit axis of the released rotation (master frame).
    pub axis: Vector3<f64>,
}

impl DependentJoint for Revolute {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, _psi: T) -> Vector3<T> {
        Vector3::zeros()
    }
}

impl ModelJoint for Revolute {
    const NAME: &'static str = "revolute";
    type Params = AxisParams;
    fn from_params(p: AxisParams) -> Result<Self, ParamError> {
        Ok(Revolute {
            axis: direction("axis", p.axis)?,
        })
    }
}
