//! Joint kinds named in model files.
//!
//! A kind declares, once and in its own file, the `type` it has in a model
//! file's `[[joint]]` table and a serde struct of its parameters (every key
//! besides `name`, `type`, `master`, `slave`, `angle` and `rate`):
//!
//! ```
//! use flexmech_core::{cst, Scalar};
//! use flexmech_joints::model_joint::{direction, ModelJoint, ParamError};
//! use flexmech_joints::DependentJoint;
//! use nalgebra::Vector3;
//! use serde::Deserialize;
//!
//! /// A screw whose pitch varies with the angle: f(ψ) = (cψ + d sin ψ) t.
//! #[derive(Debug)]
//! struct Wobble { axis: Vector3<f64>, c: f64, d: f64 }
//!
//! impl DependentJoint for Wobble {
//!     fn axis(&self) -> Vector3<f64> { self.axis }
//!     fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
//!         self.axis.map(cst::<T>) * (psi * cst::<T>(self.c) + psi.sin() * cst::<T>(self.d))
//!     }
//! }
//!
//! #[derive(Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct WobbleParams { axis: [f64; 3], c: f64, d: f64 }
//!
//! impl ModelJoint for Wobble {
//!     const NAME: &'static str = "wobble";
//!     type Params = WobbleParams;
//!     fn from_params(p: WobbleParams) -> Result<Self, ParamError> {
//!         Ok(Wobble { axis: direction("axis", p.axis)?, c: p.c, d: p.d })
//!     }
//! }
//! ```
//!
//! The model layer's registry maps `NAME` to the kind, deserialises the
//! parameters, reports unknown and missing keys, and calls
//! [`ModelJoint::from_params`], whose [`ParamError`] names the offending key.

use crate::kinematics::JointKinematics;
use nalgebra::Vector3;
use serde::de::DeserializeOwned;
use thiserror::Error;

/// `|cos|` above which two directions that must be perpendicular are refused.
pub const PERPENDICULAR_TOLERANCE: f64 = 1e-8;

/// A joint kind that model files can name.
pub trait ModelJoint: JointKinematics + Sized + 'static {
    /// The joint's `type` in model files, e.g. `"screw"`: lower case, unique
    /// among the registered kinds.
    const NAME: &'static str;
    /// The parameters as written in the `[[joint]]` table. Use
    /// `#[serde(deny_unknown_fields)]`; numbers are `f64` (integers in the
    /// file are accepted), directions `[f64; 3]` checked by [`direction`].
    type Params: DeserializeOwned;
    /// The joint from its parameters, or the key that is wrong and why.
    fn from_params(params: Self::Params) -> Result<Self, ParamError>;
    /// What `key` is, for the message on a missing key (a phrase such as
    /// `its pitch (translation per radian), e.g. pitch = 0.1`).
    fn key_help(key: &str) -> Option<&'static str> {
        common_key_help(key)
    }
}

/// A refused parameter: the key (relative to the joint's table, e.g. `axis`
/// or `lift.table`) and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("`{key}` {message}")]
pub struct ParamError {
    /// The key, relative to the `[[joint]]` table.
    pub key: String,
    /// What is wrong and how to fix it.
    pub message: String,
    /// The entry of an array the message is about (its line is reported).
    pub item: Option<usize>,
}

impl ParamError {
    /// An error about `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
            item: None,
        }
    }

    /// The same error, located at entry `index` of the array under `key`.
    pub fn at_item(mut self, index: usize) -> Self {
        self.item = Some(index);
        self
    }
}

/// `[x, y, z]` printed as in model files.
pub fn format_vector(a: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2])
}

/// The unit vector along `v` (any nonzero finite length), or an error at `key`.
pub fn direction(key: &str, v: [f64; 3]) -> Result<Vector3<f64>, ParamError> {
    let a = Vector3::from(v);
    let m = a.amax();
    if m == 0.0 || !v.iter().all(|x| x.is_finite()) {
        return Err(ParamError::new(
            key,
            format!(
                "must be a nonzero vector (it gives a direction), found {}",
                format_vector(v)
            ),
        ));
    }
    // Scale first, so that huge or tiny components do not overflow the norm.
    let b = a / m;
    Ok(b / b.norm())
}

/// `x` when it is > 0, or an error at `key`.
pub fn positive(key: &str, x: f64) -> Result<f64, ParamError> {
    if x > 0.0 {
        Ok(x)
    } else {
        Err(ParamError::new(key, format!("must be > 0, found {x:?}")))
    }
}

/// The unit vector along `slide`, which must be perpendicular to the unit
/// `axis` (to [`PERPENDICULAR_TOLERANCE`]) for a joint of type `kind`.
pub fn perpendicular_slide(
    kind: &str,
    slide: [f64; 3],
    axis: &Vector3<f64>,
) -> Result<Vector3<f64>, ParamError> {
    let s = direction("slide", slide)?;
    let cos = s.dot(axis);
    if cos.abs() > PERPENDICULAR_TOLERANCE {
        return Err(ParamError::new(
            "slide",
            format!(
                "must be perpendicular to `axis` for a joint of type {kind}, found slide = {} and axis = {} \
                 with |cos(angle)| = {:.3e}",
                format_vector(slide),
                format_vector([axis.x, axis.y, axis.z]),
                cos.abs()
            ),
        ));
    }
    Ok(s)
}

/// What the keys shared by the built-in kinds are.
pub fn common_key_help(key: &str) -> Option<&'static str> {
    Some(match key {
        "axis" => "its released rotation axis, e.g. axis = [0.0, 0.0, 1.0]",
        "slide" => "its slide direction t_r, e.g. slide = [1.0, 0.0, 0.0]",
        "pitch" => "its pitch (translation per radian along the axis), e.g. pitch = 0.1",
        "radius" => "its radius (> 0), e.g. radius = 0.05",
        "offset" => "its offset a, e.g. offset = 0.0",
        _ => return None,
    })
}

/// The parameters of a kind that takes none (rigid, spherical).
#[derive(Debug, Clone, Copy, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

/// The parameters of a kind with one direction `axis` (revolute).
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisParams {
    /// The released rotation axis (normalised).
    pub axis: [f64; 3],
}

/// The parameters of a kind with one slide direction (prismatic).
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlideParams {
    /// The slide direction (normalised).
    pub slide: [f64; 3],
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_are_normalised_and_zero_is_refused() {
        let d = direction("axis", [0.0, 3.0, 4.0]).unwrap();
        assert!((d - Vector3::new(0.0, 0.6, 0.8)).norm() <= 4.0 * f64::EPSILON);
        // Components near the overflow threshold still normalise.
        let d = direction("axis", [1e308, 1e308, 0.0]).unwrap();
        assert!((d.norm() - 1.0).abs() <= 4.0 * f64::EPSILON);
        let e = direction("axis", [0.0; 3]).unwrap_err();
        assert_eq!(e.key, "axis");
        assert!(e.message.contains("nonzero"), "{e}");
        assert!(direction("axis", [f64::NAN, 0.0, 1.0]).is_err());
    }

    #[test]
    fn a_slide_along_the_axis_is_refused() {
        let z = Vector3::z();
        assert!(perpendicular_slide("cam", [1.0, 0.0, 0.0], &z).is_ok());
        let e = perpendicular_slide("cam", [1.0, 0.0, 1.0], &z).unwrap_err();
        assert_eq!(e.key, "slide");
        assert!(e.message.contains("perpendicular") && e.message.contains("cam"));
    }
}
