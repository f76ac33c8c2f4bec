//! Prismatic (slider) joint: one released translation `s` along the unit
//! `slide` direction, no released rotation: `r_R = s t_r`, `Λ_R = I`.

use crate::kinematics::{JointKinematics, Slide};
use crate::model_joint::{direction, ModelJoint, ParamError, SlideParams};
use flexmech_core::{cst, Scalar};
use nalgebra::{Matrix3, Vector3};

/// The prismatic joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prismatic {
    /// Unit direction of the released translation (master frame).
    pub slide: Vector3<f64>,
}

impl JointKinematics for Prismatic {
    type Coordinates = Slide;

    fn released<T: Scalar>(&self, s: &T) -> (Vector3<T>, Matrix3<T>) {
        (self.slide.map(cst::<T>) * *s, Matrix3::identity())
    }
}

impl ModelJoint for Prismatic {
    const NAME: &'static str = "prismatic";
    type Params = SlideParams;
    fn from_params(p: SlideParams) -> Result<Self, ParamError> {
        Ok(Prismatic {
            slide: direction("slide", p.slide)?,
        })
    }
}
