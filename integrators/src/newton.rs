//! Newton's method with the exact tangent (or a system's cheaper one while it
//! contracts fast), shared by every solver.
//!
//! Convergence is measured on the *scaled* residual
//! `‖r‖₂ / max(‖f_ext‖₂, ‖Σₑ|rₑ|‖₂)`: the residual relative to the larger of
//! the applied loads and the magnitude of the internal forces that cancel in
//! it, so the tolerance means the same thing for any units and stays above
//! round-off when large internal forces balance. A residual whose norm is at
//! the system's round-off floor ([`NewtonSystem::floor`]) and has stopped
//! falling also counts as converged: no iteration can improve on it (this matters when the loads
//! are tiny, e.g. the first steps of a ramp, and stiff internal forces round).
//!
//! An iterate at the floor reached from an iterate within
//! [`FLOOR_ACCEPT_FROM`] by an exact full-Newton correction is closed: one
//! more correction with the factorisation at hand, accepted without
//! evaluating its residual (see `floor_end`: the floor bounds the round-off
//! from above, so such an iterate is not yet at the noise, and accepting it
//! as it stood made the solution jump by up to the floor where a parameter
//! moved it across). Reached from farther, an iterate at the floor that is still falling gets one more correction,
//! with the factorisation already made in this solve (at an iterate within
//! [`FLOOR_REUSE_RESIDUAL`]) rather than a new tangent: a correction of round-off size gains nothing from the exact
//! tangent there (the old one is off by terms of the size of the last
//! increment), and a new tangent and factorisation were a third of a
//! typical dynamic step (the 512-element cantilever under Newmark converges
//! as `0.88, 4e-5, 2.8e-10 (floor), 3.1e-10 (stalled)`).
//!
//! Above the floor, a chord step whose measured contraction promises a
//! residual well within the tolerance (see `promised_end`) is made and
//! accepted without evaluating its residual: the test on a vanishing
//! correction that implicit codes make alongside the residual's.

use crate::error::NewtonFailure;
use crate::free_motion::FreeMotion;
use crate::linsolve::{SparseLu, TangentRef};
use crate::tolerances::TOLERANCES;

/// Condition number (of the equilibrated tangent, see
/// [`SparseLu::condition_estimate`]) above which a converged tangent is
/// singular: `1/(100 ε)`. A mechanism's null direction gives `κ ≳ 1/ε`; a
/// well-posed model stays orders of magnitude below (a slender cantilever of
/// a thousand elements with `EA/EI = 10⁵` has `κ ≈ 10¹⁰`), and one above
/// it cannot be solved to more than two digits anyway.
pub const SINGULAR_CONDITION: f64 = TOLERANCES.singular_condition;

/// Newton's default tolerance on the scaled residual (model files'
/// `solver.tolerance` when left out).
pub const DEFAULT_TOLERANCE: f64 = 1e-10;

/// Newton's default iteration limit per step (`solver.max_iterations`).
pub const DEFAULT_MAX_ITERATIONS: usize = 25;

/// Iteration limits; [`Default`]: [`DEFAULT_TOLERANCE`],
/// [`DEFAULT_MAX_ITERATIONS`], full Newton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonSettings {
    /// Tolerance on the scaled residual.
    pub tolerance: f64,
    /// Maximum number of linear solves.
    pub max_iterations: usize,
    /// Modified Newton: keep a factorised tangent across iterations and
    /// steps, and refactor only when it converges too slowly (a residual
    /// not below [`MODIFIED_CONTRACTION`] times the previous one), when the
    /// system's tangent changed form ([`NewtonSystem::tangent_key`], e.g. a
    /// new step size) or at the first solve. The solution satisfies the same
    /// tolerance; only the path to it differs. `false`: the exact tangent at
    /// every iterate (quadratic convergence).
    pub modified: bool,
    /// The exact tangent from the first iteration even where the system
    /// offers a cheaper one ([`NewtonSystem::tangent_is_exact`]; the
    /// energy–momentum scheme's 2-node elements), and a new one at every
    /// iterate (no chord steps, [`CHORD_CONTRACTION`]): quadratic convergence
    /// at every iterate. `false`: the cheap tangent first, the exact one once
    /// it contracts slowly. Either way the solution meets the same
    /// tolerance.
    pub exact_tangent: bool,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            modified: false,
            exact_tangent: false,
        }
    }
}

/// Largest ratio of successive residuals modified Newton accepts before it
/// refactors the tangent at the current iterate.
pub const MODIFIED_CONTRACTION: f64 = TOLERANCES.modified_contraction;

/// Largest ratio of successive residuals Newton accepts from an approximate
/// tangent ([`NewtonSystem::tangent_is_exact`]) before it switches to the
/// exact one for the rest of the solve.
pub const INEXACT_CONTRACTION: f64 = TOLERANCES.inexact_contraction;

/// First iteration whose contraction judges an approximate tangent: the
/// second. The first correction starts from the step's predictor, and how
/// far it gets is set by the residual's curvature over that distance, not
/// by the tangent: on the four-bar of `data/benchmarks` it cuts the residual
/// less than 20-fold in 38 % of the energy–momentum steps with the exact
/// tangent and with the cheap one alike (whose later iterations contract
/// about 10⁴-fold), so judging it switched those steps for nothing.
pub const INEXACT_JUDGED_FROM: usize = 2;

/// Largest scaled residual of the iterate whose tangent was factorised for
/// that factorisation to correct a later iterate at the round-off floor: it
/// then differs from the exact tangent there by terms of that order (the
/// size of the increment since), so the correction still gains about three
/// orders, which is all the floor allows. (A tumbling free body whose floor
/// sits at 1e-7 of its scaled residual reaches it straight from residuals
/// of 0.5; corrected there with the tangent of that far iterate, its
/// energy–momentum run lost energy at 7e-7 in 10 s instead of 2e-13.)
pub const FLOOR_REUSE_RESIDUAL: f64 = 1e-3;

/// A nonlinear system `r(q) = 0` in the reduced unknowns.
pub trait NewtonSystem {
    /// Evaluates the reduced residual into `r` and the tangent into the
    /// solver's value array at the current iterate; returns the force scale.
    fn evaluate(&mut self, r: &mut [f64]) -> f64;
    /// The residual only, at the current iterate (into `r`; returns the
    /// force scale). Newton calls it at every iterate after the first of a
    /// full-Newton solve (which takes [`NewtonSystem::evaluate`]: a
    /// factorisation all but certainly follows) and brings the tangent up to
    /// date ([`NewtonSystem::update_tangent`]) only where a factorisation
    /// follows — not at the converged iterate. Default: the whole
    /// [`NewtonSystem::evaluate`].
    fn residual(&mut self, r: &mut [f64]) -> f64 {
        self.evaluate(r)
    }
    /// Computes the tangent at the current iterate after a
    /// [`NewtonSystem::residual`] that left it out (default: nothing to do).
    /// `scratch` (length `n_eq`) receives the residual the evaluation
    /// computes alongside.
    fn update_tangent(&mut self, _scratch: &mut [f64]) {}
    /// [`NewtonSystem::update_tangent`] at an iterate whose residual
    /// ([`NewtonSystem::residual`]) was just evaluated, the iterate not
    /// moved since — as Newton calls it: the system may keep that
    /// evaluation's residual and compute the tangent alone. Default:
    /// [`NewtonSystem::update_tangent`].
    fn update_tangent_at_residual(&mut self, scratch: &mut [f64]) {
        self.update_tangent(scratch);
    }
    /// CSC values of the tangent from the last evaluation that computed it.
    fn tangent_values(&self) -> &[f64];
    /// Applies the increment `dq` to the current iterate.
    fn apply(&mut self, dq: &[f64]);
    /// What the tangent's form depends on besides the iterate (the step size
    /// of a dynamic step): modified Newton reuses a factorisation from an
    /// earlier solve only when the key is the same. `NaN` (the default)
    /// never matches, so such systems refactor at every solve.
    fn tangent_key(&self) -> f64 {
        f64::NAN
    }
    /// Whether the tangent the system computes now is the exact derivative
    /// of its residual (default `true`). A system may offer a cheaper
    /// approximate tangent (the energy–momentum scheme: see
    /// `dynamics::midpoint_kernels::element_kernel`); [`solve`] starts every
    /// solve with it and switches to the exact one at the first iteration
    /// from the second on ([`INEXACT_JUDGED_FROM`]) above the round-off
    /// floor that contracts the residual by less than [`INEXACT_CONTRACTION`]
    /// (modified Newton: at the first refactorisation after the first). The
    /// solution satisfies the same tolerance; only the path to it differs.
    fn tangent_is_exact(&self) -> bool {
        true
    }
    /// Whether an iterate within the tolerance is closed like one at the
    /// round-off floor (closed: one more correction with the
    /// factorisation at hand, its residual not evaluated) where a
    /// correction has been made (default `false`: accepted as it stands).
    /// The conserving schemes ask for it: they conserve energy and momenta
    /// to what the step converged to, and the correction takes a step
    /// accepted at the tolerance about as far again below it for a solve.
    fn closes_converged(&self) -> bool {
        false
    }
    /// Whether a closing correction's result is evaluated after all (its
    /// residual only, into `r`; default `false`): where something the
    /// system reports after the solve is taken from the last evaluation and
    /// must match the state exactly (the energy–momentum scheme's drivers'
    /// work; see [`NewtonSystem::evaluate_closing`] for what is evaluated).
    /// The result is accepted whatever its residual, unless it is not
    /// finite.
    fn evaluates_closing(&self) -> bool {
        false
    }
    /// Evaluates a closing correction's result for
    /// [`NewtonSystem::evaluates_closing`]: its scaled residual where the
    /// system computes it (the default: [`NewtonSystem::residual`] into
    /// `r`), which ends the history; `None` where it evaluates only what it
    /// reports after the solve and found it finite. A non-finite result is
    /// a non-finite value (`NaN`) either way.
    fn evaluate_closing(&mut self, r: &mut [f64]) -> Option<f64> {
        let scale = self.residual(r);
        let norm = self.residual_norm(r);
        Some(scaled_norm(norm, scale).1)
    }
    /// `‖r‖₂` of the residual the last [`NewtonSystem::evaluate`] or
    /// [`NewtonSystem::residual`] wrote into `r`, its squares summed in the
    /// unknowns' order. Default: [`residual_norm`] of `r`; a system that
    /// formed the same sum alongside the residual returns it.
    fn residual_norm(&mut self, r: &[f64]) -> f64 {
        residual_norm(r)
    }
    /// Asks for the exact tangent (`true`) or the system's cheaper one
    /// (`false`) at the next tangent evaluation. Default: nothing to switch.
    fn set_exact_tangent(&mut self, _exact: bool) {}
    /// Absolute residual norm below which the residual is round-off.
    fn floor(&self) -> f64 {
        0.0
    }
    /// The null direction `mode` of a singular tangent (reduced unknowns) in
    /// the mechanism's terms.
    fn free_motion(&self, mode: &[f64], tangent: TangentRef) -> FreeMotion;
}

/// Outcome of a converged solve.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonReport {
    /// Linear solves performed.
    pub iterations: usize,
    /// Tangent factorisations among them.
    pub factorizations: usize,
    /// Final scaled residual.
    pub residual: f64,
    /// Scaled residual before each solve and at the end — except after a
    /// closing correction (an iterate at the round-off floor corrected once
    /// more, its result not evaluated: FORMULATION §4) of a system that
    /// does not ask for its evaluation
    /// ([`NewtonSystem::evaluates_closing`]) or evaluates it without its
    /// scaled residual ([`NewtonSystem::evaluate_closing`]), where the
    /// history has one entry per solve.
    pub history: Vec<f64>,
}

/// Runs Newton's method from the system's current iterate. `r` and `dq` are
/// caller-owned scratch vectors of length `n_eq`. A singular tangent at the
/// converged iterate ends it in [`NewtonFailure::Singular`] (two triangular
/// solves estimate its condition number — left out where the last
/// factorisation's pivots are all of a healthy size,
/// [`SparseLu::pivots_healthy`]: a null direction leaves a round-off
/// pivot), and so does one at the start of
/// the solve — checked unless `lu` holds a factorisation checked regular
/// by the previous solve ([`SparseLu::checked_regular`]: the solution it
/// starts from was regular, and a tangent that turned singular since then
/// fails the solve, whose retry from a smaller step is checked). One met
/// on the way (a wild iterate) is left to the failure it causes, which step
/// control can cure.
pub fn solve<S: NewtonSystem>(
    sys: &mut S,
    lu: &mut SparseLu,
    settings: &NewtonSettings,
    r: &mut [f64],
    dq: &mut [f64],
) -> Result<NewtonReport, NewtonFailure> {
    let mut factored = false;
    sys.set_exact_tangent(settings.exact_tangent);
    let start_checked = lu.checked_regular();
    let report = iterate(sys, lu, settings, start_checked, r, dq, &mut factored)?;
    if !settings.modified {
        check_regular(sys, lu, factored, true)?;
    }
    Ok(report)
}

fn iterate<S: NewtonSystem>(
    sys: &mut S,
    lu: &mut SparseLu,
    settings: &NewtonSettings,
    start_checked: bool,
    r: &mut [f64],
    dq: &mut [f64],
    factored: &mut bool,
) -> Result<NewtonReport, NewtonFailure> {
    let mut history = Vec::with_capacity(settings.max_iterations + 1);
    let mut previous_norm = f64::INFINITY;
    let mut factorizations = 0;
    // The licence of the reused factorisation that made the current
    // iterate, if one did.
    let mut chord: Option<Licence> = None;
    for it in 0..=settings.max_iterations {
        // At the start of a full-Newton solve a factorisation all but
        // certainly follows: residual and tangent in one pass.
        let with_tangent = it == 0 && !settings.modified;
        let scale = if with_tangent {
            sys.evaluate(r)
        } else {
            sys.residual(r)
        };
        let (norm, res) = scaled_norm(sys.residual_norm(r), scale);
        history.push(res);
        if !res.is_finite() {
            return Err(NewtonFailure::NotFinite { iteration: it });
        }
        let end = if at_floor(norm, &mut previous_norm, sys.floor()) {
            Some(End::Accept)
        } else {
            floor_end(it, norm, &history, sys, settings, chord)
                .or_else(|| promised_end(norm, &history, sys, settings, *factored))
        };
        if res <= settings.tolerance || end.is_some() {
            let iterations = if closes(res, end, it, sys, settings) {
                factorizations += usize::from(settings.exact_tangent);
                close(sys, lu, r, dq, it, &mut history, settings.exact_tangent)?
            } else {
                it
            };
            let residual = reported_residual(end, &history[it..], norm, scale, sys.floor());
            return Ok(NewtonReport {
                iterations,
                factorizations,
                residual,
                history,
            });
        }
        if let Some(failure) = diverged(it, res, &history, settings) {
            return Err(failure);
        }
        if it == settings.max_iterations {
            break;
        }
        let mut reuse = if settings.modified {
            if it == 0 {
                lu.key() == Some(sys.tangent_key())
            } else {
                res < MODIFIED_CONTRACTION * history[it - 1]
            }
        } else if *factored && it > 0 {
            chord = licence(sys, norm, &history, settings);
            chord.is_some()
        } else {
            false
        };
        let slow = if settings.modified {
            !reuse
        } else {
            res > INEXACT_CONTRACTION * history[it.saturating_sub(1)]
        };
        // At the round-off floor a slow contraction says nothing about the
        // tangent.
        if it >= INEXACT_JUDGED_FROM && slow && norm > sys.floor() && !sys.tangent_is_exact() {
            sys.set_exact_tangent(true);
            reuse = false;
        }
        if !reuse {
            chord = None;
            // Full Newton checks the start of the solve (unless the previous
            // solution was checked) and the converged iterate (in `solve`);
            // modified Newton every tangent it keeps.
            let check = (it == 0 && !start_checked) || settings.modified;
            refactor(sys, lu, !with_tangent, check, dq)?;
            factorizations += 1;
        }
        *factored = true;
        for (d, v) in dq.iter_mut().zip(r.iter()) {
            *d = -v;
        }
        lu.solve(dq).map_err(NewtonFailure::LinearSolve)?;
        sys.apply(dq);
    }
    Err(NewtonFailure::MaxIterations {
        iterations: settings.max_iterations,
        residual: *history.last().unwrap_or(&f64::NAN),
    })
}

/// `‖r‖₂`, the squares summed in order.
pub fn residual_norm(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// The residual's norm `norm` and its scaled norm `norm / scale` (0 for a
/// zero residual, whatever the scale).
fn scaled_norm(norm: f64, scale: f64) -> (f64, f64) {
    let res = if norm == 0.0 {
        0.0
    } else {
        norm / scale.max(f64::MIN_POSITIVE)
    };
    (norm, res)
}

/// Factorises the tangent at the current iterate (brought up to date
/// first where `update` — at an iterate whose residual was just evaluated,
/// [`NewtonSystem::update_tangent_at_residual`]: `dq` is scratch until the
/// solve), checking its regularity where `check`.
fn refactor<S: NewtonSystem>(
    sys: &mut S,
    lu: &mut SparseLu,
    update: bool,
    check: bool,
    dq: &mut [f64],
) -> Result<(), NewtonFailure> {
    if update {
        sys.update_tangent_at_residual(dq);
    }
    lu.factor(sys.tangent_values())
        .map_err(NewtonFailure::LinearSolve)?;
    lu.set_key(sys.tangent_key());
    if check {
        check_regular(sys, lu, true, false)?;
    }
    Ok(())
}

/// Whether full Newton corrects the iterate with the factorisation this
/// solve has made rather than a new tangent at the floor: still falling, a
/// round-off correction with a factorisation made close to the solution
/// (see the module's notes and [`FLOOR_REUSE_RESIDUAL`]). Elsewhere a chord
/// step ([`chord_licence`]) may.
fn floor_reuse<S: NewtonSystem>(sys: &S, norm: f64, previous: f64) -> bool {
    norm <= sys.floor() && previous <= FLOOR_REUSE_RESIDUAL
}

/// The contraction of the last correction, `history[k] / history[k − 1]`,
/// where it licenses a chord step (see [`CHORD_CONTRACTION`]): the expected
/// contraction of that step. Licensed where it is at most
/// `CHORD_CONTRACTION`, or where two chord steps contracting as much are
/// expected to reach the `tolerance` (`res ρ² ≤ tol`): the chord path then
/// costs at most two residuals and solves where a new tangent costs its
/// evaluation and factorisation besides, and a chord that contracts less
/// than measured loses its licence at the next iterate. (On the
/// 512-element cantilever of `benches/` the steps that end near the
/// tolerance `0.5, 4e-4, 5e-7` then end by chord steps: 108 factorisations
/// in 100 steps instead of 118, for 313 solves instead of 310 and the
/// positions within 7e-14.) Only in a solve that has contracted at every
/// iteration (Newton's quadratic regime: a correction from far off may
/// contract a thousandfold by chance where the tangent still changes fast),
/// and where [`floor_reuse`] does not already correct the iterate.
fn chord_licence<S: NewtonSystem>(
    sys: &S,
    norm: f64,
    history: &[f64],
    tolerance: f64,
) -> Option<f64> {
    let [.., previous, res] = *history else {
        return None;
    };
    let ratio = res / previous;
    ((res <= CHORD_CONTRACTION * previous || res * ratio * ratio <= tolerance)
        && history.windows(2).all(|w| w[1] < w[0])
        && !floor_reuse(sys, norm, previous))
    .then_some(ratio)
}

/// Largest ratio of successive scaled residuals at which full Newton makes
/// its next correction with the factorisation it has — a chord step —
/// instead of a new tangent: `10⁻³`. A Newton correction from the step's
/// predictor that cuts the residual a thousandfold comes from a tangent
/// that is off at the new iterate by terms of the size of that correction
/// (its contraction is the same order), so the chord step cuts the residual
/// about as much again — the slider-crank of `data/benchmarks` goes `1,
/// 1.6e-6`, then to its floor at `2e-9` by the chord as by a new tangent —
/// for a solve instead of a tangent and a factorisation. A chord that
/// contracts less is followed by a new tangent, unless two chord steps
/// contracting as much reach the tolerance (`chord_licence`). The energy–momentum
/// scheme's cheaper tangent takes chord steps on the same terms (its own
/// contraction licenses them); an iterate a chord step brings to the floor
/// is accepted without the stall test only where the chord's expected
/// residual is within the tolerance (the floor test of this module). The
/// slider-crank's generalized-α run makes 1 112 factorisations in 1 000
/// steps with them, 2 098 without.
pub const CHORD_CONTRACTION: f64 = 1e-3;

/// Largest scaled residual of the previous iterate from which an exact
/// Newton correction lands near the solution: its error is of the order of
/// that residual squared (1e-6 here), so an iterate it brings to the
/// round-off floor ends the solve there without the stall test's extra
/// evaluation (accepted or closed, see `floor_end`; on the slider-crank of
/// `data/benchmarks` that test was a third of every step's solves: `1,
/// 1.6e-6, 2.1e-9 (floor), 2.1e-9 (stalled)`). From farther the floor may
/// have been reached by a correction still short of the solution (a floor
/// that overestimates the round-off), and the stall test stays.
pub const FLOOR_ACCEPT_FROM: f64 = 1e-3;

/// How an iterate above the tolerance ends the solve.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// At the round-off floor: the iterate is the solution.
    Accept,
    /// At the round-off floor: one more correction with the factorisation
    /// at hand (a new one under `newton = "exact"`), accepted without
    /// evaluating its residual ([`close`]).
    Close,
    /// Above the floor: a chord step whose measured contraction promises
    /// a scaled residual (this one) well within the tolerance, made and
    /// accepted without evaluating its residual ([`promised_end`],
    /// [`close`]).
    Promise(f64),
}

/// The share of the tolerance (or of the round-off floor, where that is
/// above it) a chord step's promised residual — its last measured
/// contraction times the residual — must be within for its result to be
/// accepted unevaluated (`promised_end`): `0.01`. The promise is a
/// bound on the correction's effect, not on the noise: the residuals these
/// results turn out to have (evaluated for the check, every such step of
/// the models of `data/benchmarks` and the 512-element cantilever of
/// `benches/`) are 3 to 6 000 times the promise, but at most 0.64 of the
/// tolerance or floor with this share; with `0.1` one step of the lateral
/// buckling run ended at 1.9 times its tolerance. (The cantilever makes 323
/// residual evaluations in 100 steps with it, 379 without.)
pub const PROMISE_SHARE: f64 = 0.01;

/// How an iterate above the floor and the tolerance ends a full-Newton
/// solve: by a chord step ([`chord_licence`] with the factorisation at hand,
/// made this solve: `factored`) whose contraction — the last one measured
/// with that factorisation — times the scaled residual is within
/// [`PROMISE_SHARE`] of the tolerance. The chord step is made
/// ([`close`]) and its result accepted without evaluating its residual:
/// the convergence test on a vanishing correction that implicit codes make
/// alongside the residual's, measured here in the residual the correction
/// leaves. The contraction must have been measured near the solution (from
/// an iterate within [`FLOOR_ACCEPT_FROM`]); the iterate is above the
/// floor, since one at the floor corrected from there has no chord licence
/// ([`floor_reuse`] takes over, and the floor's own tests end the solve: a
/// chord there promises nothing — the residual is noise). It is the same
/// correction the chord step would make from the iterate, so the solution
/// is the one the evaluation would have accepted wherever the promise
/// holds. `/solver/residual` reports the promised residual (an estimate:
/// the result's own is not evaluated; see [`PROMISE_SHARE`] for how the
/// results' residuals compare).
fn promised_end<S: NewtonSystem>(
    norm: f64,
    history: &[f64],
    sys: &S,
    settings: &NewtonSettings,
    factored: bool,
) -> Option<End> {
    let [.., previous, res] = *history else {
        return None;
    };
    let full = !settings.modified && !settings.exact_tangent;
    if !full || !factored || previous > FLOOR_ACCEPT_FROM || res <= settings.tolerance {
        return None;
    }
    // The tolerance as a norm, or the floor where that is above it.
    let bound = (settings.tolerance * norm / res).max(sys.floor());
    match licence(sys, norm, history, settings) {
        Some(Licence::Chord(c)) if c * norm <= PROMISE_SHARE * bound => Some(End::Promise(c * res)),
        _ => None,
    }
}

/// How the iterate `it`, at the round-off floor from an iterate within
/// [`FLOOR_ACCEPT_FROM`], ends a full-Newton solve (none: it does not).
///
/// - Reached by a chord step (`chord`: its licence, [`chord_licence`])
///   whose expected residual, the licence times the scaled residual it
///   started from, is within the tolerance: accepted (the chord converges
///   linearly: from farther, the stall test stays). The licence is the
///   contraction measured with the factorisation the chord reuses, so it
///   bounds a chord of the cheaper tangent as it does one of the exact; a
///   cheaper tangent's correction from an iterate already at the floor
///   ([`floor_reuse`]) is judged the same way, by the contraction that
///   brought that iterate there, and an exact one's is accepted.
/// - Reached by a correction with a new factorisation — the exact tangent
///   (quadratic convergence), or a cheaper one
///   ([`NewtonSystem::tangent_is_exact`] `false`) whose correction contracted
///   the scaled residual at least as a quadratic one would (to the square of
///   the residual it started from or below) — or by any correction whose
///   contraction, repeated from this iterate, promises a residual within the
///   tolerance: closed ([`End::Close`]).
///   Such an iterate is not yet at the noise: the floor is a bound on the
///   round-off, and sits one to two orders above the noise the iterates
///   reach (the four-bar and the slider-crank of `data/benchmarks`). Accepted
///   as it is, a solution would jump by up to the floor where a parameter's
///   small change moves the iterate across it; closed, it is the same
///   correction either way — the one the chord step or the stall test would
///   have made from it.
fn floor_end<S: NewtonSystem>(
    it: usize,
    norm: f64,
    history: &[f64],
    sys: &S,
    settings: &NewtonSettings,
    chord: Option<Licence>,
) -> Option<End> {
    let previous = history[it.saturating_sub(1)];
    if it == 0 || settings.modified || norm > sys.floor() || previous > FLOOR_ACCEPT_FROM {
        return None;
    }
    let promised = |c: f64| c * previous <= settings.tolerance;
    let res = history[it];
    let accepted = match chord {
        Some(Licence::Chord(c)) => promised(c),
        Some(Licence::FloorReuse(c)) => sys.tangent_is_exact() || promised(c),
        None => false,
    };
    let quadratic = chord.is_none() && (sys.tangent_is_exact() || res <= previous * previous);
    if accepted {
        Some(End::Accept)
    } else if quadratic || (res / previous) * res <= settings.tolerance {
        Some(End::Close)
    } else {
        None
    }
}

/// Whether the accepted iterate `it` (scaled residual `res`, ended by
/// `end` where it is above the tolerance) is closed ([`close`]): at the
/// floor by [`floor_end`], within the tolerance where the system asks for
/// it ([`NewtonSystem::closes_converged`]) and a correction has been made
/// by full Newton.
fn closes<S: NewtonSystem>(
    res: f64,
    end: Option<End>,
    it: usize,
    sys: &S,
    settings: &NewtonSettings,
) -> bool {
    if res > settings.tolerance {
        matches!(end, Some(End::Close | End::Promise(_)))
    } else {
        it > 0 && !settings.modified && sys.closes_converged()
    }
}

/// The closing correction of an iterate at the round-off floor
/// ([`End::Close`]) — or the promised chord step of one above it
/// ([`End::Promise`], with the factorisation at hand): `r` is its residual, `lu` the factorisation that
/// brought it there, at an iterate within [`FLOOR_ACCEPT_FROM`] — or, with
/// `exact` (`newton = "exact"`: a new tangent at every iterate), a new
/// factorisation at this iterate, made here. The correction contracts
/// about as much as the last one, so its result is at the noise (the
/// tolerance where the floor is below it); its residual is not evaluated —
/// the stall test would evaluate it only to find it there. Returns the
/// solves made, `it + 1`; where the system asks for it
/// ([`NewtonSystem::evaluates_closing`]) the result is evaluated
/// ([`NewtonSystem::evaluate_closing`]); its scaled residual, where that is
/// computed, ends the `history`.
fn close<S: NewtonSystem>(
    sys: &mut S,
    lu: &mut SparseLu,
    r: &mut [f64],
    dq: &mut [f64],
    it: usize,
    history: &mut Vec<f64>,
    exact: bool,
) -> Result<usize, NewtonFailure> {
    let not_finite = NewtonFailure::NotFinite { iteration: it + 1 };
    if exact {
        refactor(sys, lu, true, false, dq)?;
    }
    for (d, v) in dq.iter_mut().zip(r.iter()) {
        *d = -v;
    }
    lu.solve(dq).map_err(NewtonFailure::LinearSolve)?;
    if !dq.iter().all(|d| d.is_finite()) {
        return Err(not_finite);
    }
    sys.apply(dq);
    if sys.evaluates_closing() {
        if let Some(res) = sys.evaluate_closing(r) {
            history.push(res);
            if !res.is_finite() {
                return Err(not_finite);
            }
        }
    }
    Ok(it + 1)
}

/// Whether full Newton corrects the last iterate of `history` (of norm
/// `norm`) with the factorisation it has, and why: a chord step
/// ([`chord_licence`], not under `newton = "exact"`) or a correction from
/// the round-off floor ([`floor_reuse`]), with the contraction last
/// measured with that factorisation.
fn licence<S: NewtonSystem>(
    sys: &S,
    norm: f64,
    history: &[f64],
    settings: &NewtonSettings,
) -> Option<Licence> {
    let [.., previous, res] = *history else {
        return None;
    };
    chord_licence(sys, norm, history, settings.tolerance)
        .filter(|_| !settings.exact_tangent)
        .map(Licence::Chord)
        .or_else(|| floor_reuse(sys, norm, previous).then(|| Licence::FloorReuse(res / previous)))
}

/// Why full Newton reused its factorisation for the correction that made
/// the current iterate, with the contraction last measured with it.
#[derive(Debug, Clone, Copy)]
enum Licence {
    /// A chord step ([`chord_licence`]).
    Chord(f64),
    /// A correction from an iterate already at the round-off floor
    /// ([`floor_reuse`]). With the exact tangent its result is judged as a
    /// new tangent's would be; with a cheaper one as a chord's.
    FloorReuse(f64),
}

/// A force scale at most this many round-off floors is itself round-off:
/// the loads vanish (a zero load, or only drivers moving the mechanism
/// rigidly) and the forces that cancel in the residual are noise.
const DEGENERATE_SCALE: f64 = 1e3;

/// The residual an accepted iterate reports (`/solver/residual`): its
/// scaled residual `res = ‖r‖/scale`, except where the scale degenerates
/// (below [`DEGENERATE_SCALE`] round-off floors), where `res` is round-off
/// over round-off (≈ 1) and says nothing; there the norm is measured
/// against the structure's own force scale, the one the round-off floor
/// `4 ε ‖force scales‖` is made of. `after`: the scaled residuals from the
/// accepted iterate's on (`res` first, then the closing's where the system
/// evaluates it). A solve ended by a promised chord step (`end`) reports
/// the promise, or the chord's residual where it was evaluated. Newton's
/// decisions never use it.
fn reported_residual(end: Option<End>, after: &[f64], norm: f64, scale: f64, floor: f64) -> f64 {
    let res = after[0];
    if let Some(End::Promise(promised)) = end {
        after.get(1).copied().unwrap_or(promised)
    } else if floor > 0.0 && scale <= DEGENERATE_SCALE * floor {
        norm * 4.0 * f64::EPSILON / floor
    } else {
        res
    }
}

/// Refuses a converged iterate whose tangent is singular (its solution is
/// one of infinitely many: a mechanism). `factored`: whether `lu` holds a
/// factorisation from this solve (otherwise the current tangent is
/// factorised first); `converged`: whether the iterate is the solution (or
/// the start of the step). Costs two triangular solves, none where the
/// factorisation's pivots are all of a healthy size
/// ([`SparseLu::pivots_healthy`]).
pub(crate) fn check_regular<S: NewtonSystem>(
    sys: &mut S,
    lu: &mut SparseLu,
    factored: bool,
    converged: bool,
) -> Result<(), NewtonFailure> {
    if sys.tangent_values().is_empty() {
        return Ok(());
    }
    if !factored {
        sys.update_tangent(&mut vec![0.0; lu.pattern().nrows()]);
        lu.factor(sys.tangent_values())
            .map_err(NewtonFailure::LinearSolve)?;
    }
    // Pivots of a healthy size rule out the null direction the estimate
    // looks for (see `PIVOT_ALARM`): its solves are saved.
    if lu.pivots_healthy() {
        lu.set_regular();
        return Ok(());
    }
    let (condition, mode) = lu.condition_estimate(sys.tangent_values());
    if condition <= SINGULAR_CONDITION {
        lu.set_regular();
    } else {
        return Err(NewtonFailure::Singular {
            condition,
            motion: Box::new(sys.free_motion(
                &mode,
                TangentRef {
                    pattern: lu.pattern(),
                    values: sys.tangent_values(),
                },
            )),
            converged,
        });
    }
    Ok(())
}

/// Whether a residual of norm `norm` sits at the round-off floor and has
/// stopped falling (less than halved since the previous iterate, whose norm
/// `previous` is updated); while it still drops fast, one more iteration is
/// cheap accuracy.
pub(crate) fn at_floor(norm: f64, previous: &mut f64, floor: f64) -> bool {
    let stalled = norm >= TOLERANCES.stall_ratio * *previous;
    *previous = norm;
    norm <= floor && (stalled || norm == 0.0)
}

/// A divergence failure when the scaled residual has grown by 10⁸ over the
/// first iterate's (or the tolerance).
pub(crate) fn diverged(
    it: usize,
    res: f64,
    history: &[f64],
    settings: &NewtonSettings,
) -> Option<NewtonFailure> {
    (it > 0 && res > TOLERANCES.divergence_growth * history[0].max(settings.tolerance)).then(|| {
        NewtonFailure::Diverged {
            iteration: it,
            residual: res,
            initial: history[0],
        }
    })
}

#[cfg(test)]
#[path = "newton_tests.rs"]
mod tests;
