//! Screw joint (paper eq. 12 with `t_r = t`): the slave advances along the
//! axis by the pitch times the angle, `f(ψ) = c ψ t` (`c`: advance per radian).

use crate::dependent::DependentJoint;
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;

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
        self.axis.map(cst::<T>) * (psi * cst::<T>(self.pitch))
    }
}
