//! flexmech-studies: model files, the mechanism builder, runs that stream
//! results into HDF5 files, and the `flexmech` command line.

#![warn(missing_docs)]

pub mod bench;
pub mod build;
pub mod charts;
mod checks;
pub mod cli;
pub mod export;
pub mod fuzz;
mod initial_check;
pub mod model;
pub mod reproduce;
pub mod results;
pub mod run;
pub mod study;

pub use build::{build, Built};
pub use run::{restart_model, run_model, run_model_to, RunError, RunSummary};
