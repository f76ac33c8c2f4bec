//! Rack-and-pinion joint (paper eq. 12, `t_r ⊥ t`, `c = b`): the pinion of
//! radius `b` turns about `t`; the rack slides along `t_r`:
//! `f(ψ) = b (t_r × t) + b ψ t_r` — the constant term places the pinion's
//! center at distance `b` from the rack.

use crate::dependent::{parameter_slopes, DependentJoint};
use crate::model_joint::{direction, perpendicular_slide, positive, ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;
use serde::Deserialize;

/// The rack-and-pinion joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RackPinion {
    /// Unit axis `t` of the pinion.
    pub axis: Vector3<f64>,
    /// Unit slide direction `t_r` of the rack, perpendicular to `t`.
    pub slide: Vector3<f64>,
    /// Pinion radius `b`.
    pub radius: f64,
}

impl DependentJoint for RackPinion {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.rolled(psi, cst(self.radius))
    }

    /// By `radius` (exact, hyper-dual).
    fn translation_by(&self, name: &str, psi: f64) -> Option<[Vector3<f64>; 2]> {
        (name == "radius").then(|| parameter_slopes(psi, self.radius, |psi, b| self.rolled(psi, b)))
    }
}

impl RackPinion {
    /// `f(ψ) = b (t_r × t) + b ψ t_r` for the radius `b`.
    fn rolled<T: Scalar>(&self, psi: T, b: T) -> Vector3<T> {
        self.slide.cross(&self.axis).map(cst::<T>) * b + self.slide.map(cst::<T>) * (b * psi)
    }
}

/// Parameters of a `rack_pinion` joint in model files.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RackPinionParams {
    /// Pinion axis `t` (normalised).
    pub axis: [f64; 3],
    /// Pinion radius `b` (> 0).
    pub radius: f64,
    /// Rack direction `t_r`, perpendicular to `axis`.
    pub slide: [f64; 3],
}

impl ModelJoint for RackPinion {
    const NAME: &'static str = "rack_pinion";
    type Params = RackPinionParams;
    fn from_params(p: RackPinionParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let radius = positive("radius", p.radius)?;
        Ok(RackPinion {
            axis,
            radius,
            slide: perpendicular_slide(Self::NAME, p.slide, &axis)?,
        })
    }
}
