//! Cam joint with the paper's eccentric lobe (eq. 14): the follower moves
//! along `t_r` by `f(ψ) = (R cos ψ − R − a) t_r`; `a` and `2R + a` are the
//! smallest and largest released displacements.

use crate::dependent::{parameter_slopes, DependentJoint};
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
        self.lift(psi, cst(self.radius), cst(self.offset))
    }

    /// By `radius` or `offset` (exact, hyper-dual).
    fn translation_by(&self, name: &str, psi: f64) -> Option<[Vector3<f64>; 2]> {
        let (r, a) = (cst(self.radius), cst(self.offset));
        match name {
            "radius" => Some(parameter_slopes(psi, self.radius, |psi, r| {
                self.lift(psi, r, a)
            })),
            "offset" => Some(parameter_slopes(psi, self.offset, |psi, a| {
                self.lift(psi, r, a)
            })),
            _ => None,
        }
    }
}

impl Cam {
    /// `f(ψ) = (R cos ψ − R − a) t_r` for the eccentricity `R` and offset `a`.
    fn lift<T: Scalar>(&self, psi: T, r: T, a: T) -> Vector3<T> {
        self.slide.map(cst::<T>) * (r * psi.cos() - r - a)
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
