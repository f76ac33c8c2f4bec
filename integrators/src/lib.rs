//! flexmech-integrators: the mechanism, parallel assembly, sparse linear
//! solves, Newton's method with step control, and the solvers (statics and
//! the time integrators).

#![warn(missing_docs)]

pub mod arc_length;
pub mod assembly;
pub mod band_lu;
mod band_solve;
pub mod band_split;
pub mod builder;
pub mod constraints;
pub mod critical;
pub mod dofs;
pub mod dynamics;
mod element_split;
pub mod error;
pub mod frame_spin;
pub mod free_motion;
mod geometry;
pub mod joint_parameter;
pub mod linsolve;
pub mod measure;
pub mod mechanism;
pub mod modal;
pub mod newton;
pub mod record;
pub mod rotation_guard;
pub mod sensitivity;
mod sparsity;
pub mod stability;
mod start_shift;
pub mod statics;
pub mod step_control;
pub mod step_maps;
pub mod system;
pub mod team;
pub mod threads;
pub mod tolerances;

pub use constraints::{MechanismState, Topology};
pub use error::{NewtonFailure, SolveError};
pub use mechanism::{
    FollowerLoad, JointInstance, LoadField, Mechanism, Names, NodalLoad, PrescribedDof, RigidBody,
    Schedule,
};
pub use newton::NewtonSettings;
pub use record::{Energies, JointRecord, Sensitivity, StepRecord};
pub use sensitivity::Parameter;
pub use statics::{
    solve_static, solve_static_to, solve_static_with, PathEnd, StaticOutcome, StaticSettings,
};
