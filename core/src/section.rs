//! Cross-section and material data of a beam, per unit length (FORMULATION §2).

use nalgebra::{Matrix3, Vector3};

/// Linear elastic section: `N = C_N Γ`, `M = C_M K` with
/// `C_N = diag(EA, GA₂, GA₃)`, `C_M = diag(GJ, EI₂, EI₃)`, and inertia
/// `A_ρ = ρA`, `J_ρ = ρ·diag(I₂+I₃, I₂, I₃)` per unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// `(EA, GA₂, GA₃)`: axial and shear stiffness.
    pub c_n: Vector3<f64>,
    /// `(GJ, EI₂, EI₃)`: torsional and bending stiffness.
    pub c_m: Vector3<f64>,
    /// Mass per unit length `ρA`.
    pub rho_a: f64,
    /// `ρ(I₂+I₃), ρI₂, ρI₃`: rotational inertia per unit length.
    pub rho_j: Vector3<f64>,
}

impl Section {
    /// A section from its stiffness and inertia values.
    pub fn new(c_n: [f64; 3], c_m: [f64; 3], rho_a: f64, rho_j: [f64; 3]) -> Self {
        Self {
            c_n: Vector3::from(c_n),
            c_m: Vector3::from(c_m),
            rho_a,
            rho_j: Vector3::from(rho_j),
        }
    }

    /// `C_N` as a matrix.
    pub fn c_n_matrix(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.c_n)
    }

    /// `C_M` as a matrix.
    pub fn c_m_matrix(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.c_m)
    }
}
