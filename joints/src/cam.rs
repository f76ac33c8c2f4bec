//! Cam joint with the paper's eccentric lobe (eq. 14): the follower moves
//! along `t_r` by `f(ψ) = (R cos ψ − R − a) t_r`; `a` and `2R + a` are the
//! smallest and largest released displacements.

use crate::dependent::DependentJoint;
use crate::model_joint::{direction, perpendicular_slide, positive, ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;
use serde::Deserialize;

/// The eccentric cam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cam {
    /// Unit axis `t` of the cam's rotation.
    pub axis: Vector3<f64>,
    /// Unit direction `t_r` of the follower, perpendicular to `t`.
    pub slide: Vector3<f64>,
    /// Eccentricity `R`.
    pub radius: f64,
    /// Offset `a`.
    pub offset: f64,
}

impl DependentJoint for Cam {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        let r = cst::<T>(self.radius);
        self.slide.map(cst::<T>) * (r * psi.cos() - r - cst::<T>(self.offset))
    }
}

/// Parameters of a `cam` joint in model files.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CamParams {
    /// Cam axis `t` (normalised).
    pub axis: [f64; 3],
    /// Eccentricity `R` (> 0).
    pub radius: f64,
    /// Offset `a`.
    pub offset: f64,
    /// Follower direction `t_r`, perpendicular to `axis`.
    pub slide: [f64; 3],
}

impl ModelJoint for Cam {
    const NAME: &'static str = "cam";
    type Params = CamParams;
    fn from_params(p: CamParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let radius = positive("radius", p.radius)?;
        Ok(Cam {
            axis,
            radius,
            offset: p.offset,
            slide: perpendicular_slide(Self::NAME, p.slide, &axis)?,
        })
    }
}
