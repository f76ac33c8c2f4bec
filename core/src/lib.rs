//! flexmech-core: rotations, cross-sections and geometrically exact
//! (Reissner–Simo) beam element kernels, generic over the scalar so that
//! automatic differentiation (num-dual) runs through every kernel.

#![warn(missing_docs)]

pub mod expr;
pub mod rotation;
pub mod rotation_derivatives;
pub mod rotation_derivatives_pair;
pub mod rotation_pair;
pub mod scalar;
mod secant_pair;

pub use scalar::{cst, Scalar};
pub mod conserving;
pub mod conserving_tangent;
pub mod conserving_tangent_pair;
pub mod discrete_gradient;
pub mod discrete_gradient_quadratic;
pub mod element;
pub mod element_linear;
pub mod element_pair;
pub mod element_quadratic;
pub mod element_tangent_pair;
pub mod frames_pair;
pub mod inertia;
pub mod section;
pub mod shape;

pub use element::BeamElement;
pub use inertia::{Inertia, MassKind};
pub use section::Section;
pub mod mesh;
pub mod pose_pair;
pub mod prestress;
pub mod state;
pub mod step_start;

pub use mesh::{Element, Mesh, MeshError};
pub use state::Configuration;
