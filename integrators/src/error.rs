//! Typed failures of the solvers. Every variant says where (time, step) and why.

use thiserror::Error;

/// Why a solve stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// Newton did not reach the tolerance even after `halvings` step halvings.
    #[error("no convergence at t = {time} after {halvings} step halvings (last: {reason})")]
    NoConvergence {
        time: f64,
        halvings: usize,
        reason: NewtonFailure,
    },
    /// The tangent could not be factorised (a mechanism or unsupported DOF).
    #[error("singular tangent: {0}")]
    Singular(String),
    /// The mechanism is inconsistent (for example a DOF that no element touches).
    #[error("invalid mechanism: {0}")]
    InvalidMechanism(String),
}

/// Why one Newton solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NewtonFailure {
    #[error("residual {residual:.3e} above tolerance after {iterations} iterations")]
    MaxIterations { iterations: usize, residual: f64 },
    #[error("residual is not finite at iteration {iteration}")]
    NotFinite { iteration: usize },
    #[error("residual grew to {residual:.3e} (from {initial:.3e}) at iteration {iteration}")]
    Diverged {
        iteration: usize,
        residual: f64,
        initial: f64,
    },
    #[error("the linear solve failed: {0}")]
    LinearSolve(String),
}
