//! The configuration of a mesh: nodal positions and nodal rotations.

use crate::rotation::{
    exp_quaternion, matrix_from_quaternion, quaternion_from_matrix, quaternion_product,
};
use nalgebra::{Matrix3, Vector3, Vector4};

/// Positions `xᵢ` and rotations `Rᵢ` (from the initial configuration) of every node.
#[derive(Debug, PartialEq)]
pub struct Configuration {
    /// Nodal positions.
    pub x: Vec<Vector3<f64>>,
    /// Nodal rotations from the initial triads (`Λᵢ = Rᵢ Λᵢ,₀`).
    pub rot: Vec<Matrix3<f64>>,
}

impl Clone for Configuration {
    fn clone(&self) -> Self {
        Self {
            x: self.x.clone(),
            rot: self.rot.clone(),
        }
    }

    /// Into the storage already there (the solvers save every step's start
    /// this way).
    fn clone_from(&mut self, source: &Self) {
        self.x.clone_from(&source.x);
        self.rot.clone_from(&source.rot);
    }
}

impl Configuration {
    /// The initial configuration: positions as given, every rotation the identity.
    pub fn initial(positions: &[Vector3<f64>]) -> Self {
        Self {
            x: positions.to_vec(),
            rot: vec![Matrix3::identity(); positions.len()],
        }
    }

    /// Applies a nodal increment: `x ← x + u`, `R ← exp(φ̂) R` (spatial,
    /// multiplicative — rotation vectors are never added), re-normalised
    /// through the quaternion so that orthogonality does not drift.
    pub fn increment(&mut self, node: usize, u: &Vector3<f64>, phi: &Vector3<f64>) {
        increment_pose(&mut self.x[node], &mut self.rot[node], u, phi);
    }

    /// Unit quaternion `(w, x, y, z)` of node `i`'s rotation, `w ≥ 0`.
    pub fn quaternion(&self, i: usize) -> Vector4<f64> {
        quaternion_from_matrix(&self.rot[i]).normalize()
    }
}

/// [`Configuration::increment`] of one node's pose `(x, rot)`: `x ← x + u`,
/// `R ← exp(φ̂) R`, composed as unit quaternions, `q(exp φ̂) ⊗ q(R)`, and
/// normalised (re-orthonormalising `R`): no matrix exponential and no
/// matrix product.
pub fn increment_pose(
    x: &mut Vector3<f64>,
    rot: &mut Matrix3<f64>,
    u: &Vector3<f64>,
    phi: &Vector3<f64>,
) {
    *x += u;
    let q = quaternion_product(&exp_quaternion(phi), &quaternion_from_matrix(rot));
    *rot = matrix_from_quaternion(&q.normalize());
}
