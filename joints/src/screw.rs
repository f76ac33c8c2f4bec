//! Screw joint (paper eq. 12 with `t_r = t`): the slave advances along the
//! axis by the pitch times the angle, `f(ψ) = c ψ t` (`c`: advance per radian).

use crate::dependent::{parameter_slopes, DependentJoint};
use crate::model_joint::{direction, ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;
use serde::Deserialize;

/// The screw joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw {
    /// Unit axis `t`.
    pub axis: Vector3<f64>,
    /// Pitch `c` (translation per radian).
    pub pitch: f64,
}

impl DependentJoint for Screw {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.advance(psi, cst(self.pitch))
    }

    /// By `pitch` (exact, hyper-dual).
    fn translation_by(&self, name: &str, psi: f64) -> Option<[Vector3<f64>; 2]> {
        (name == "pitch").then(|| parameter_slopes(psi, self.pitch, |psi, c| self.advance(psi, c)))
    }
}

impl Screw {
    /// `f(ψ) = c ψ t` for the pitch `c`.
    fn advance<T: Scalar>(&self, psi: T, pitch: T) -> Vector3<T> {
        self.axis.map(cst::<T>) * (psi * pitch)
    }
}

/// Parameters of a `screw` joint in model files.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScrewParams {
    /// Axis (normalised).
    pub axis: [f64; 3],
    /// Translation per radian along the axis.
    pub pitch: f64,
}

impl ModelJoint for Screw {
    const NAME: &'static str = "screw";
    type Params = ScrewParams;
    fn from_params(p: ScrewParams) -> Result<Self, ParamError> {
        Ok(Screw {
            axis: direction("axis", p.axis)?,
            pitch: p.pitch,
        })
    }
}
