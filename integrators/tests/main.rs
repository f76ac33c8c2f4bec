//! The integration tests of the solvers, gathered into one test binary.

mod arc_length;
mod builder;
mod common;
mod damping;
mod dynamics;
mod dynamics_free_joints;
mod dynamics_joints;
mod energy_momentum_consistency;
mod follower_loads;
mod generalized_alpha;
mod joints;
mod rigid_bodies;
mod simulation;
mod statics;
mod unrestrained;
