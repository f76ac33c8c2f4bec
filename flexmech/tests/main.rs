//! The integration tests of the front door, gathered into one test binary (one link
//! instead of one per file). Children they start inherit the HDF5 files
//! other tests hold open; `.cargo/config.toml` turns HDF5's own file locks
//! off for them.

#![allow(dead_code)]

mod arc_length;
mod bench;
mod benchmarks;
mod charts;
mod cli;
mod common;
mod damping;
mod distributed_loads;
mod dynamic_models;
mod element_rotation;
mod energy_balance;
mod expression_joints;
mod expressions;
mod follower_loads;
mod four_bar;
mod fuzz;
#[path = "../fuzz/mod.rs"]
mod fuzz_engine;
mod ground_joints;
mod joint_models;
mod lee_frame;
mod merit;
mod model_files;
mod modes;
mod modified_newton;
mod paper_drive;
mod published_dynamics;
mod reactions;
mod refusals;
mod reproduce;
mod restart;
mod result_metadata;
mod resultants;
mod results_file;
mod rigid_bodies;
mod rust_loads;
mod rust_study;
mod sensitivity;
mod sinks;
mod slider_crank;
mod stability;
mod study;
mod velocities;
mod views;
