//! A structure spinning steadily about a fixed axis, seen from the frame
//! that turns with it (rotating blades, shafts): the steady state is a static
//! equilibrium with the centrifugal loads, and small motions about it carry
//! the gyroscopic (Coriolis) terms — FORMULATION §6.
//!
//! For a spin `Ω = Ω a` about the axis through `o`, a node of translational
//! masses `m_ij` (consistent or lumped) and spatial rotational inertia
//! `J = R J₀ Rᵀ` has, in the turning frame, the inertial forces
//!
//! ```text
//! fᵢ = Σⱼ m_ij (ẍⱼ + 2Ω̂ẋⱼ + Ω̂Ω̂(xⱼ − o)),   mᵢ = J θ̈ + G_J θ̇ + Ω̂JΩ,
//! ```
//!
//! whose steady parts `Σⱼ m_ij Ω̂Ω̂(xⱼ − o)` (the centrifugal load, outward)
//! and `Ω̂JΩ` enter the static residual, with their stiffness
//! `∂/∂xⱼ = m_ij Ω̂Ω̂` (centrifugal softening) and
//! `∂(Ω̂JΩ)/∂θ = Ω̂JΩ̂ − Ω̂(JΩ)^` (spatial spins); the velocity terms are the
//! gyroscopic matrix `G`: `2 m_ij Ω̂` and `G_J = JΩ̂ + Ω̂J − (JΩ)^`, both
//! skew-symmetric.

use crate::assembly::Assembler;
use crate::dofs::DofMap;
use flexmech_core::{Configuration, Inertia, MassKind};
use nalgebra::{Matrix3, Vector3};

/// A steady spin of the whole structure about a fixed axis.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSpin {
    /// The axis (unit).
    pub axis: Vector3<f64>,
    /// A point of the axis.
    pub origin: Vector3<f64>,
    /// The spin rate `Ω` (radians per unit of model time; the sense by the
    /// right hand about `axis`).
    pub rate: f64,
    /// The translational mass the inertial forces take.
    pub mass: MassKind,
}

impl FrameSpin {
    /// The spin vector `Ω a`.
    pub fn omega(&self) -> Vector3<f64> {
        self.axis * self.rate
    }

    /// Adds the steady inertial forces of the spin, scaled by `scale` (the
    /// fraction of `Ω²`: a static path ramps it with the load factor), at
    /// `config` to the nodal residual `g` and their magnitudes to `abs`;
    /// with `tangent`, their stiffness blocks.
    pub(crate) fn add_steady(
        &self,
        inertia: &Inertia,
        config: &Configuration,
        scale: f64,
        (g, abs): (&mut [f64], &mut [f64]),
        mut tangent: Option<(&mut Assembler, &DofMap)>,
    ) {
        let w = self.omega().cross_matrix();
        let ww = w * w * scale;
        for &(i, j, m) in &inertia.mass {
            let f = ww * (config.x[j] - self.origin) * m;
            for c in 0..3 {
                g[6 * i + c] += f[c];
                abs[6 * i + c] += f[c].abs();
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                asm.add_node_block(dofs, (i, 0), (j, 0), &(ww * m));
            }
        }
        let omega = self.omega();
        for (i, j0) in inertia.rotational.iter().enumerate() {
            let r = config.rot[i];
            let j = r * j0 * r.transpose();
            let h = j * omega;
            let moment = w * h * scale;
            for c in 0..3 {
                g[6 * i + 3 + c] += moment[c];
                abs[6 * i + 3 + c] += moment[c].abs();
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                let k = (w * j * w - w * h.cross_matrix()) * scale;
                asm.add_node_block(dofs, (i, 3), (i, 3), &k);
            }
        }
    }

    /// Adds the gyroscopic matrix `G` at `config` (values of `asm`, zeroed
    /// by the caller) through the node maps.
    pub(crate) fn add_gyroscopic(
        &self,
        inertia: &Inertia,
        config: &Configuration,
        asm: &mut Assembler,
        dofs: &DofMap,
    ) {
        let w = self.omega().cross_matrix();
        for &(i, j, m) in &inertia.mass {
            asm.add_node_block(dofs, (i, 0), (j, 0), &(w * (2.0 * m)));
        }
        let omega = self.omega();
        for (i, j0) in inertia.rotational.iter().enumerate() {
            let r = config.rot[i];
            let j: Matrix3<f64> = r * j0 * r.transpose();
            let g = j * w + w * j - (j * omega).cross_matrix();
            asm.add_node_block(dofs, (i, 3), (i, 3), &g);
        }
    }
}
