//! Cam joint with the paper's eccentric lobe (eq. 14): the follower moves
//! along `t_r` by `f(ψ) = (R cos ψ − R − a) t_r`; `a` and `2R + a` are the
//! smallest and largest released displacements.

use crate::dependent::DependentJoint;
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;

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
