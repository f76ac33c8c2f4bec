//! Spherical (ball) joint: all three rotations released, no translation.
//! The released rotation is kept as a matrix and updated multiplicatively,
//! `Λ_R ← exp(ω̂) Λ_R` with `ω` in the master body frame, so the slave's spin
//! is `δφ_s = δφ_m + Λ_m δω`.
//!
//! The ball's centre may sit on a rigid arm of the master: `r_R = a`
//! constant in the master's body frame (relation (1) with `r_R = a`,
//! `Λ_R` free), the slave node at the centre — a ball joint between a beam
//! tip and a part that starts beside it.

use crate::kinematics::{BallRotation, JointKinematics};
use crate::model_joint::{ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;

/// The spherical joint; [`Spherical::default`] has its centre on the master
/// node.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Spherical {
    /// The ball's centre (and the slave node) from the master node, master
    /// body frame (the global axes at t = 0); zero by default.
    pub arm: Vector3<f64>,
}

impl JointKinematics for Spherical {
    type Coordinates = BallRotation;

    fn released<T: Scalar>(&self, rotation: &Matrix3<T>) -> (Vector3<T>, Matrix3<T>) {
        (self.arm.map(cst::<T>), *rotation)
    }
}

/// The parameters of a spherical joint in a model file.
#[derive(Debug, Clone, Copy, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphericalParams {
    /// Optional arm `a` (see [`Spherical::arm`]), e.g. `arm = [0.0, 1e-4, 0.0]`.
    #[serde(default)]
    pub arm: Option<[f64; 3]>,
}

impl ModelJoint for Spherical {
    const NAME: &'static str = "spherical";
    type Params = SphericalParams;
    fn from_params(p: SphericalParams) -> Result<Self, ParamError> {
        let arm = Vector3::from(p.arm.unwrap_or_default());
        if arm.iter().any(|c| !c.is_finite()) {
            return Err(ParamError::new(
                "arm",
                "must be three finite numbers, e.g. arm = [0.0, 1e-4, 0.0]",
            ));
        }
        Ok(Spherical { arm })
    }
}
