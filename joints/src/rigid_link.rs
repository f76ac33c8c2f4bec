//! Rigid link: nothing released, the slave held at a constant offset in the
//! master's frame (`r_R = c`, `Λ_R = I`) — relation (1) with a fixed arm. It
//! carries a rigid body's centre of mass away from the node it hangs on (the
//! body's mass sits on the slave, eliminated exactly like every slave).

use crate::kinematics::{JointKinematics, NoCoordinates};
use flexmech_core::Scalar;
use nalgebra::{Matrix3, Vector3};

/// A rigid link of arm `offset` (in the master's initial frame, the global
/// axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidLink {
    /// The slave's position relative to the master, master's frame.
    pub offset: Vector3<f64>,
}

impl JointKinematics for RigidLink {
    type Coordinates = NoCoordinates;

    fn released<T: Scalar>(&self, _: &()) -> (Vector3<T>, Matrix3<T>) {
        (self.offset.map(|c| T::from_subset(&c)), Matrix3::identity())
    }
}
