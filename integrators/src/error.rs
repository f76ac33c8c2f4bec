//! Typed failures of the solvers. Every variant says where (time, step) and why.

use crate::free_motion::FreeMotion;
use thiserror::Error;

/// Why a solve stopped.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// Newton did not reach the tolerance even after `halvings` step halvings.
    #[error("no convergence at t = {time} after {halvings} step halvings (last: {reason})")]
    NoConvergence {
        /// Time (statics: load factor) the failed step aimed at.
        time: f64,
        /// Halvings in force when it failed.
        halvings: usize,
        /// The last Newton failure.
        reason: NewtonFailure,
    },
    /// The tangent could not be factorised (a mechanism or unsupported DOF).
    #[error("singular tangent: {0}")]
    Singular(String),
    /// An element turned too far between its nodes for its interpolation to
    /// follow (see [`crate::rotation_guard`]); `beam` names it where the
    /// caller knows the beams (empty otherwise).
    #[error(
        "element {element}{beam} turns by {angle:.3} rad between its nodes at t = {time} \
         (by {change:.3} rad in the last step): an element's interpolation follows at most \
         {limit:.3} rad between its nodes, {step_limit:.3} rad per step (it would wrap past π \
         and lose the strain); use more elements, or smaller steps",
        limit = flexmech_core::Element::ROTATION_LIMIT,
        step_limit = flexmech_core::Element::ROTATION_STEP_LIMIT
    )]
    ElementRotation {
        /// Index of the element in the mesh.
        element: usize,
        /// ` (element k of beam "name", which has m)` where the mechanism
        /// names its beams ([`crate::mechanism::Names`]), else empty.
        beam: String,
        /// Time (statics: load factor) of the rejected step.
        time: f64,
        /// Relative rotation between the element's nodes, rad.
        angle: f64,
        /// Its change in the step, rad.
        change: f64,
    },
    /// A prescribed nodal rotation changed by more than the step limit in one
    /// step (see [`crate::rotation_guard`]).
    #[error(
        "prescribed[{index}] turns its node by {change:.3} rad in the step to t = {time}: a \
         prescribed rotation is applied as one rotation by the change of its value, which is \
         ambiguous past π (2π is no rotation at all); keep it below {limit:.3} rad per step \
         with more load steps (statics) or a smaller dt (dynamics)",
        limit = flexmech_core::Element::ROTATION_STEP_LIMIT
    )]
    PrescribedRotationStep {
        /// Index of the prescribed DOF.
        index: usize,
        /// Time (statics: load factor) of the rejected step.
        time: f64,
        /// The value's change in the step, rad.
        change: f64,
    },
    /// A converged state whose tangent is singular: the answer is not unique
    /// (see [`crate::free_motion`]).
    #[error(
        "the mechanism is not held at t = {time}: its tangent is singular (condition number \
         {condition:.1e}), so the solution is not unique — {motion}"
    )]
    Unrestrained {
        /// Time (statics: load factor) of the state.
        time: f64,
        /// Estimated condition number of the equilibrated tangent.
        condition: f64,
        /// What is free, in the mechanism's terms.
        motion: Box<FreeMotion>,
    },
    /// The mechanism is inconsistent (for example a DOF that no element touches).
    #[error("invalid mechanism: {0}")]
    InvalidMechanism(String),
}

/// Why one Newton solve failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NewtonFailure {
    /// The iteration limit was reached above the tolerance.
    #[error("residual {residual:.3e} above tolerance after {iterations} iterations")]
    MaxIterations {
        /// Linear solves performed.
        iterations: usize,
        /// The last scaled residual.
        residual: f64,
    },
    /// The residual became NaN or infinite.
    #[error("residual is not finite at iteration {iteration}")]
    NotFinite {
        /// Iteration at which it was evaluated.
        iteration: usize,
    },
    /// The residual grew by the divergence factor
    /// ([`crate::tolerances::Tolerances::divergence_growth`]).
    #[error("residual grew to {residual:.3e} (from {initial:.3e}) at iteration {iteration}")]
    Diverged {
        /// Iteration at which it was detected.
        iteration: usize,
        /// The scaled residual then.
        residual: f64,
        /// The first iterate's scaled residual.
        initial: f64,
    },
    /// The sparse factorisation or solve failed.
    #[error("the linear solve failed: {0}")]
    LinearSolve(String),
    /// The tangent at the converged iterate is singular (see
    /// [`crate::newton::SINGULAR_CONDITION`]).
    #[error("singular tangent (condition number {condition:.1e}): {motion}")]
    Singular {
        /// Estimated condition number of the equilibrated tangent.
        condition: f64,
        /// What is free, in the mechanism's terms.
        motion: Box<FreeMotion>,
        /// At the converged iterate (the answer is not unique: no smaller
        /// step cures it), or at the start of the step (a smaller step may).
        converged: bool,
    },
    /// The step converged but its result was rejected (a change too large
    /// for one step, see [`crate::rotation_guard`]); a smaller step cures it.
    #[error("step rejected: {0}")]
    Rejected(String),
}
