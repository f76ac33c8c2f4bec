//! Critical points of a static path, located between two converged steps.
//!
//! The stability count (the tangent's negative eigenvalues,
//! [`crate::stability`]) changes exactly where an eigenvalue of the tangent
//! crosses zero: at a limit point (the load factor turns) or at a
//! bifurcation (another branch crosses the path). A step whose count differs
//! from the step before brackets such a point; bisection on the count —
//! the path's point at a fraction `s` of the step solved again from the
//! step's start, its count compared with the start's — shrinks the bracket
//! to `LOCATE_TOLERANCE` of the step — or ends on the point itself, where a
//! solve converges with a tangent singular to working precision (bracket
//! 0). The critical mode (the eigenvector of
//! the eigenvalue nearest zero, by inverse iteration) says which of the two
//! it is: the load does work on a limit point's mode (`f·φ ≠ 0`), none on a
//! bifurcation's (`f·φ = 0`, Riks 1979; Wriggers, *Nonlinear Finite Element
//! Methods*, §7.4).

use crate::constraints::MechanismState;
use crate::error::NewtonFailure;
use crate::linsolve::SparseLu;
use crate::newton::NewtonSystem;
use crate::stability::InertiaCount;
use crate::statics::{begin_step, StaticTerms};
use crate::system::ReducedSystem;

/// What kind of critical point the stability count crossed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CriticalKind {
    /// The load factor has a maximum or minimum along the path: the load
    /// does work on the critical mode (snap-through, snap-back).
    Limit,
    /// Another equilibrium branch crosses the path: the critical mode is
    /// orthogonal to the load (buckling of a perfect structure).
    Bifurcation,
}

impl CriticalKind {
    /// `"limit"` or `"bifurcation"` (the result file's words).
    pub fn name(self) -> &'static str {
        match self {
            CriticalKind::Limit => "limit",
            CriticalKind::Bifurcation => "bifurcation",
        }
    }
}

/// A critical point located on a static path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalPoint {
    /// The load factor at the point (the middle of the last bracket).
    pub load_factor: f64,
    /// Limit point or bifurcation.
    pub kind: CriticalKind,
    /// Negative eigenvalues of the tangent before the point.
    pub negative_before: usize,
    /// Negative eigenvalues after it.
    pub negative_after: usize,
    /// Width of the last bracket in load factor (the location's precision).
    pub bracket: f64,
}

/// The bracket, as a fraction of the step, below which the bisection stops.
const LOCATE_TOLERANCE: f64 = 1e-6;
/// Bisections at most (2⁻²⁴ < `LOCATE_TOLERANCE`).
const MAX_BISECTIONS: usize = 24;
/// Inverse iterations for the critical mode.
const MODE_ITERATIONS: usize = 30;
/// A critical mode whose cosine with the load stays below this is a
/// bifurcation (the load does no work on it); above, a limit point.
pub(crate) const BIFURCATION_COSINE: f64 = 0.1;
/// Relative change of the load factor above which the path is taken to turn
/// at a located point (the solves' own load factors agree far closer).
const TURN_TOLERANCE: f64 = 1e-9;

/// The path's step from `start` (load factor `lambda_start`, `count`
/// negative eigenvalues) to the converged state now in `sys.end` (load
/// factor `lambda_end`, `count_end`) crossed a critical point: locate it.
/// `solve_at(sys, lu, s)` solves the path's point at the fraction `s` of
/// the step from `sys.start` (the step's start) and returns its load
/// factor; `set_load(sys, λ)` sets the loads of the load factor λ. On
/// return `sys.end`, its loads and its tangent are the step's end again.
/// `None` when a bisection's solve failed before the bracket shrank at all;
/// else the point and the nearest converged state past it with its load
/// factor (where a path switches branches), when the bisection solved one.
pub(crate) fn locate(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    (inertia, lu, scratch): (&mut InertiaCount, &mut SparseLu, &mut [f64]),
    (start, lambda_start, count): (&MechanismState, f64, usize),
    (lambda_end, count_end): (f64, usize),
    f_ref: &[f64],
    mut solve_at: impl FnMut(
        &mut ReducedSystem<'_, StaticTerms>,
        &mut SparseLu,
        f64,
    ) -> Result<f64, NewtonFailure>,
    set_load: impl Fn(&mut ReducedSystem<'_, StaticTerms>, f64),
) -> Option<(CriticalPoint, Option<(MechanismState, f64)>)> {
    let end = sys.end.clone();
    let (mut lo, mut hi) = ((0.0, lambda_start), (1.0, lambda_end));
    let mut past: Option<MechanismState> = None;
    for _ in 0..MAX_BISECTIONS {
        if hi.0 - lo.0 <= LOCATE_TOLERANCE {
            break;
        }
        let s = 0.5 * (lo.0 + hi.0);
        sys.end.clone_from(start);
        begin_step(sys);
        let lambda = match solve_at(sys, lu, s) {
            Ok(lambda) => lambda,
            // Converged where the tangent is singular to working precision:
            // on the point itself.
            Err(NewtonFailure::Singular {
                converged: true, ..
            }) => {
                (lo, hi) = ((s, sys.load_time), (s, sys.load_time));
                break;
            }
            Err(_) => break,
        };
        sys.update_tangent(scratch);
        match inertia.negative_eigenvalues(&sys.asm.values) {
            Some(c) if c == count => lo = (s, lambda),
            _ => {
                hi = (s, lambda);
                past = Some(sys.end.clone());
            }
        }
    }
    let located = hi.0 - lo.0 < 1.0;
    // The critical mode at the nearest state past the point.
    let at = if past.is_some() { hi.1 } else { lambda_end };
    sys.end = past.clone().unwrap_or_else(|| end.clone());
    set_load(sys, at);
    sys.update_tangent(scratch);
    let cosine = mode_cosine(sys, lu, f_ref);
    sys.end = end;
    set_load(sys, lambda_end);
    sys.update_tangent(scratch);
    let load_factor = 0.5 * (lo.1 + hi.1);
    let point = CriticalPoint {
        load_factor,
        kind: classify((lambda_start, load_factor, lambda_end), cosine),
        negative_before: count,
        negative_after: count_end,
        bracket: (hi.1 - lo.1).abs(),
    };
    located.then(|| (point, past.map(|state| (state, hi.1))))
}

/// A located point's kind. Where the path's load factor turns at the point
/// (it rises to it and falls after, or the reverse: `(start, point, end)`
/// of the step), a limit point; else by the critical mode's cosine with
/// the load, a bifurcation below [`BIFURCATION_COSINE`]. (The cosine alone
/// fails on fine meshes: a point load's share of a mode spread over many
/// nodes shrinks as the nodes multiply.)
fn classify((start, point, end): (f64, f64, f64), cosine: Option<f64>) -> CriticalKind {
    let noise = TURN_TOLERANCE * (start.abs() + point.abs() + end.abs()).max(f64::MIN_POSITIVE);
    let (rise, fall) = (point - start, end - point);
    if rise * fall < 0.0 && rise.abs() > noise && fall.abs() > noise {
        return CriticalKind::Limit;
    }
    match cosine {
        Some(c) if c < BIFURCATION_COSINE => CriticalKind::Bifurcation,
        _ => CriticalKind::Limit,
    }
}

/// The critical mode of the tangent now in `sys` (its assembled values):
/// inverse iteration with the factorised tangent converges to the
/// eigenvector of the eigenvalue nearest zero. `None` when a solve fails.
pub(crate) fn critical_mode(
    sys: &ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
) -> Option<Vec<f64>> {
    lu.factor(sys.tangent_values()).ok()?;
    let n = sys.topo.dofs.n_eq;
    // A start with a share of every unknown (deterministic).
    let mut x: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.1 * ((i * 7919) % 13) as f64)
        .collect();
    for _ in 0..MODE_ITERATIONS {
        lu.solve(&mut x).ok()?;
        let s = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        x.iter_mut().for_each(|v| *v /= s);
    }
    Some(x)
}

/// `|f·φ| / ‖f‖` of the critical mode `φ` (unit) of the tangent now in
/// `sys` and the reduced reference load `f_ref` (nodal).
pub(crate) fn load_cosine(
    sys: &ReducedSystem<'_, StaticTerms>,
    mode: &[f64],
    f_ref: &[f64],
) -> f64 {
    let mut f = vec![0.0; mode.len()];
    sys.reduce(f_ref, &mut f);
    let norm = f.iter().map(|v| v * v).sum::<f64>().sqrt();
    let dot: f64 = f.iter().zip(mode).map(|(a, b)| a * b).sum();
    dot.abs() / norm.max(f64::MIN_POSITIVE)
}

/// The cosine of the critical mode with the load, or `None`.
fn mode_cosine(
    sys: &ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
) -> Option<f64> {
    let mode = critical_mode(sys, lu)?;
    Some(load_cosine(sys, &mode, f_ref))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turning_load_factor_is_a_limit_point_whatever_the_cosine() {
        // Rises to the point and falls after: a limit point even where a
        // point load's cosine with a fine mesh's mode is small.
        assert_eq!(classify((0.9, 1.0, 0.95), Some(0.01)), CriticalKind::Limit);
        assert_eq!(
            classify((-0.4, -0.5, -0.45), Some(0.01)),
            CriticalKind::Limit
        );
        // A monotonic path: the cosine decides.
        assert_eq!(
            classify((0.9, 1.0, 1.1), Some(0.01)),
            CriticalKind::Bifurcation
        );
        assert_eq!(classify((0.9, 1.0, 1.1), Some(0.5)), CriticalKind::Limit);
        // A turn within the solves' noise is no turn.
        assert_eq!(
            classify((1.0, 1.0 + 1e-12, 1.0), Some(0.01)),
            CriticalKind::Bifurcation
        );
    }
}
