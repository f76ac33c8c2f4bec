//! Cylindrical joint: a released rotation `ψ` about `axis` and an independent
//! released translation `s` along `slide`: `r_R = s t_r`, `Λ_R = exp((ψ−ψ₀) t̂)`.

use crate::kinematics::{axis_rotation, AngleAt, AngleSlide, JointKinematics};
use crate::model_joint::{direction, ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;

/// The cylindrical joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylindrical {
    /// Unit axis of the released rotation (master frame).
    pub axis: Vector3<f64>,
    /// Unit direction of the released translation (master frame).
    pub slide: Vector3<f64>,
}

impl JointKinematics for Cylindrical {
    type Coordinates = AngleSlide;

    fn released<T: Scalar>(&self, (angle, s): &(AngleAt<T>, T)) -> (Vector3<T>, Matrix3<T>) {
        (
            self.slide.map(cst::<T>) * *s,
            axis_rotation(&self.axis, angle.turn()),
        )
    }
}

/// Parameters of a `cylindrical` joint in model files.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylindricalParams {
    /// Axis of the released rotation.
    pub axis: [f64; 3],
    /// Direction of the released translation.
    pub slide: [f64; 3],
}

impl ModelJoint for Cylindrical {
    const NAME: &'static str = "cylindrical";
    type Params = CylindricalParams;
    fn from_params(p: CylindricalParams) -> Result<Self, ParamError> {
        Ok(Cylindrical {
            axis: direction("axis", p.axis)?,
            slide: direction("slide", p.slide)?,
        })
    }
}
