//! Static equilibrium paths past limit points: Crisfield's cylindrical
//! arc-length method (Crisfield 1981; *Non-linear Finite Element Analysis of
//! Solids and Structures*, vol. 1, §9.3). The load factor `λ` becomes an
//! unknown beside the reduced unknowns `q`, with the constraint that each
//! step advances a fixed length in `q`,
//!
//! ```text
//! r(q, λ) = g(q) − λ f_ref = 0,      ‖Δq‖² = Δl²
//! ```
//!
//! (`Δq` the step's accumulated increment). Each iteration solves
//! `K δq_r = −r` and `K δq_f = f_ref` with one factorisation and picks `δλ`
//! from the quadratic `‖Δq + δq_r + δλ δq_f‖² = Δl²`, the root whose new
//! increment turns least from the last one; the predictor follows the
//! previous step's direction, so the path turns round limit points (snap
//! through, snap back) instead of stopping there. The step length adapts to
//! the iterations a step took (√(desired/taken), between ½ and 2, never
//! beyond the first step's) and halves on failure. The run ends where the path reaches λ = 1 (that point solved
//! by load control) or after its step budget. Every converged step is
//! reported with its load factor as `time` and the tangent's negative
//! eigenvalues (the stability report).
//!
//! Loads must be proportional — `f(λ) = λ f_ref`: dead loads and gravity
//! ramped with `λ` — and nothing driven or following: those are refused.

use crate::error::{NewtonFailure, SolveError};
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::newton::{NewtonReport, NewtonSettings, NewtonSystem};
use crate::record::StepRecord;
use crate::rotation_guard::RotationGuard;
use crate::sensitivity::{Parameter, StaticSensitivities};
use crate::statics::{
    begin_step, converged_record, static_system, step_rejected, StaticOutcome, StaticTerms,
};
use crate::system::ReducedSystem;

/// Settings of an arc-length analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcLengthSettings {
    /// The first step's load increment is `1/load_steps` (it sets the arc
    /// length `Δl` of the path that follows).
    pub load_steps: usize,
    /// Newton settings (full Newton).
    pub newton: NewtonSettings,
    /// Consecutive halvings of the arc length allowed for one step.
    pub max_halvings: usize,
    /// Most steps the path may take before it must reach λ = 1.
    pub max_steps: usize,
    /// At the first bifurcation (a step after which the tangent has more
    /// negative eigenvalues, with a critical mode orthogonal to the load),
    /// leave the fundamental path along the critical mode.
    pub branch_switch: bool,
}

/// Iterations a step should take; the arc length adapts towards it.
const DESIRED_ITERATIONS: f64 = 5.0;
/// Relative tolerance of the proportionality check `f(½) = ½ f(1)`.
const PROPORTIONAL: f64 = 1e-12;
/// Inverse iterations for the critical mode at a bifurcation.
const MODE_ITERATIONS: usize = 30;
/// A critical mode whose cosine with the load stays below this is a
/// bifurcation (the load does no work on it); above, a limit point.
const BIFURCATION_COSINE: f64 = 0.1;

/// Traces the static path of `mech` under its proportional loads with the
/// arc-length method, calling `on_step` with every converged step.
pub fn solve_arc_length(
    mech: &Mechanism,
    settings: &ArcLengthSettings,
    on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    solve_arc_length_with(mech, settings, &[], on_step)
}

/// [`solve_arc_length`] with the exact sensitivities of every converged
/// step to `params` in its record, taken at the step's load factor
/// (`K dq/dp = −∂r/∂p` at fixed λ, as in
/// [`crate::statics::solve_static_with`]; the path's load factor is a result
/// of the arc constraint, the derivatives are those of the equilibrium at
/// that λ).
pub fn solve_arc_length_with(
    mech: &Mechanism,
    settings: &ArcLengthSettings,
    params: &[Parameter],
    mut on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    refuse_unless_proportional(mech, settings)?;
    let (mut sys, mut lu, mut inertia) = static_system(mech)?;
    let mut sensitivities = StaticSensitivities::new(&sys, params)?;
    let n = sys.topo.dofs.n_eq;
    let nodes = mech.mesh.node_count();
    let mut f_ref = vec![0.0; 6 * nodes];
    mech.external_forces(1.0, &mut f_ref);
    let mut guard = RotationGuard::new(mech, &sys.end);
    let mut work = Work::new(n);
    let (mut lambda, mut steps) = (0.0f64, 0usize);
    let mut arc = first_arc(&mut sys, &mut lu, &f_ref, &mut work, settings)?;
    // The arc grows back after halvings, never beyond the first one: the
    // path keeps the resolution load_steps asked for.
    let nominal = arc;
    let mut previous: Option<Vec<f64>> = None;
    let mut halvings = 0;
    let mut branch = BranchSwitch::default();
    while lambda < 1.0 {
        if steps >= settings.max_steps {
            return Err(out_of_budget(steps, lambda));
        }
        begin_step(&mut sys);
        let direction = branch.direction();
        let leaving = direction.is_some();
        match arc_step(
            &mut sys,
            &mut lu,
            &f_ref,
            &mut work,
            settings,
            (lambda, arc),
            previous.as_deref(),
            direction.as_deref(),
        ) {
            Ok((lambda_new, report)) => {
                if let Err(objection) = guard.accept(mech, &sys.end, lambda_new) {
                    let reason = step_rejected(&mut sys, objection)?;
                    halve(&mut arc, &mut halvings, settings, lambda, reason)?;
                    continue;
                }
                let crosses = lambda_new > 1.0 && lambda < 1.0;
                let (lambda_rec, report) = if crosses {
                    // The path passes λ = 1 in this step: solve that point
                    // by load control from the step's start.
                    let report = solve_at_one(&mut sys, &mut lu, &f_ref, &mut work, settings)
                        .map_err(|reason| SolveError::NoConvergence {
                            time: 1.0,
                            halvings,
                            reason,
                        })?;
                    (1.0, report)
                } else {
                    (lambda_new, report)
                };
                let dl = lambda_rec - lambda;
                let increment = work.acc.clone();
                lambda = lambda_rec;
                steps += 1;
                set_load(&mut sys, &f_ref, lambda);
                let step = converged_record(
                    &mut sys,
                    &mut inertia,
                    &mut work.r,
                    (lambda, dl),
                    &report,
                    None,
                );
                let mut step = step;
                step.sensitivities = sensitivities.at(&sys, lambda)?;
                on_step(&step);
                let grew = branch.count(step.negative_pivots);
                if settings.branch_switch && grew && !branch.switched && !leaving && lambda < 1.0 {
                    branch.switch = critical_mode(&mut sys, &mut lu, &f_ref, &mut work);
                }
                arc = adapted_arc(arc, nominal, report.iterations);
                previous = Some(increment);
                halvings = 0;
            }
            Err(reason) => {
                sys.end.clone_from(&sys.start);
                halve(&mut arc, &mut halvings, settings, lambda, reason)?;
            }
        }
    }
    Ok(StaticOutcome::reached(sys, steps))
}

/// The arc length `Δl` of the path, from the first load-controlled
/// predictor: `‖K⁻¹ f_ref‖ / load_steps` at the initial state (its tangent
/// evaluated with λ = 0). An error when the loads do nothing.
fn first_arc(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    settings: &ArcLengthSettings,
) -> Result<f64, SolveError> {
    // The arc length from the first load-controlled predictor.
    set_load(sys, f_ref, 0.0);
    sys.evaluate(&mut work.r);
    factor_and_solve_f(sys, lu, f_ref, work)?;
    let first = 1.0 / settings.load_steps.max(1) as f64;
    let arc = first * norm(&work.qf);
    if !(arc > 0.0 && arc.is_finite()) {
        return Err(SolveError::InvalidMechanism(
            "arc-length: the loads do nothing (f_ref = 0); give the model a load".into(),
        ));
    }
    Ok(arc)
}

/// The error of a path that used its step budget short of λ = 1.
fn out_of_budget(steps: usize, lambda: f64) -> SolveError {
    SolveError::InvalidMechanism(format!(
        "arc-length: {steps} steps taken (the model's budget) and the load factor \
         is {lambda:.6}, short of 1; raise load_steps (shorter first step) or \
         max_arc_steps"
    ))
}

/// Solves the path's point at λ = 1 by load control from the step's start,
/// for a step that passed it; Newton's report.
fn solve_at_one(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    settings: &ArcLengthSettings,
) -> Result<NewtonReport, NewtonFailure> {
    sys.end.clone_from(&sys.start);
    set_load(sys, f_ref, 1.0);
    crate::newton::solve(sys, lu, &settings.newton, &mut work.r, &mut work.dq)
}

/// The arc length of the next step after one that took `iterations`:
/// scaled by `√(desired/taken)`, between ½ and 2, never beyond `nominal`.
fn adapted_arc(arc: f64, nominal: f64, iterations: usize) -> f64 {
    let taken = iterations.max(1) as f64;
    (arc * (DESIRED_ITERATIONS / taken).sqrt().clamp(0.5, 2.0)).min(nominal)
}

/// Branch switching: the stability count of the last step, and the
/// critical mode to leave the path along (once) after a bifurcation.
struct BranchSwitch {
    /// Negative eigenvalues of the last converged step's tangent.
    last_count: Option<usize>,
    /// The critical mode found at a bifurcation, not yet left along.
    switch: Option<Vec<f64>>,
    /// Whether the path has left along a critical mode.
    switched: bool,
}

impl Default for BranchSwitch {
    /// The count of the unloaded state (none negative), no mode.
    fn default() -> Self {
        Self {
            last_count: Some(0),
            switch: None,
            switched: false,
        }
    }
}

impl BranchSwitch {
    /// The direction the next step leaves along: the critical mode, taken
    /// once (the path switches branches at most once).
    fn direction(&mut self) -> Option<Vec<f64>> {
        let direction = if self.switched {
            None
        } else {
            self.switch.take()
        };
        if direction.is_some() {
            self.switched = true;
        }
        direction
    }

    /// Takes a converged step's count of negative eigenvalues; whether it
    /// grew since the last step (both known).
    fn count(&mut self, negative_pivots: Option<usize>) -> bool {
        let grew = match (self.last_count, negative_pivots) {
            (Some(a), Some(b)) => b > a,
            _ => false,
        };
        self.last_count = negative_pivots;
        grew
    }
}

/// Scratch of the iterations: residual, Newton increment, the two
/// solutions and the step's accumulated increment.
struct Work {
    r: Vec<f64>,
    dq: Vec<f64>,
    qf: Vec<f64>,
    acc: Vec<f64>,
    fr: Vec<f64>,
}

impl Work {
    fn new(n: usize) -> Self {
        Self {
            r: vec![0.0; n],
            dq: vec![0.0; n],
            qf: vec![0.0; n],
            acc: vec![0.0; n],
            fr: vec![0.0; n],
        }
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn set_load(sys: &mut ReducedSystem<'_, StaticTerms>, f_ref: &[f64], lambda: f64) {
    for (f, r) in sys.fext.iter_mut().zip(f_ref) {
        *f = lambda * r;
    }
    sys.load_time = lambda;
}

/// Factorises the tangent of the last evaluation and solves `K q_f = f_ref`
/// (reduced at the current iterate) into `work.qf`.
fn factor_and_solve_f(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
) -> Result<(), SolveError> {
    lu.factor(sys.tangent_values())
        .map_err(SolveError::Singular)?;
    sys.reduce(f_ref, &mut work.fr);
    work.qf.copy_from_slice(&work.fr);
    lu.solve(&mut work.qf).map_err(SolveError::Singular)
}

/// One arc-length step from `sys.start` at `lambda`: predictor along the
/// previous direction, then corrector iterations on the cylinder of radius
/// `arc`. Returns the new load factor and Newton's report.
#[allow(clippy::too_many_arguments)]
fn arc_step(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    settings: &ArcLengthSettings,
    (lambda, arc): (f64, f64),
    previous: Option<&[f64]>,
    leave_along: Option<&[f64]>,
) -> Result<(f64, NewtonReport), NewtonFailure> {
    let mut dl = predict(sys, lu, f_ref, work, (lambda, arc), previous, leave_along)?;
    let mut history = Vec::new();
    for it in 1..=settings.newton.max_iterations {
        set_load(sys, f_ref, lambda + dl);
        let scale = sys.evaluate(&mut work.r);
        let rn = norm(&work.r);
        let res = rn / scale.max(f64::MIN_POSITIVE);
        history.push(res);
        if !res.is_finite() {
            return Err(NewtonFailure::NotFinite { iteration: it });
        }
        if res <= settings.newton.tolerance || rn <= sys.floor {
            return Ok((
                lambda + dl,
                NewtonReport {
                    iterations: it,
                    factorizations: it,
                    residual: res,
                    history,
                },
            ));
        }
        dl += correct(sys, lu, f_ref, work, arc)?;
    }
    Err(NewtonFailure::MaxIterations {
        iterations: settings.newton.max_iterations,
        residual: history.last().copied().unwrap_or(f64::NAN),
    })
}

/// The predictor of a step from `sys.start` at `lambda`: the tangent
/// direction `δλ q_f` of length `arc`, signed to continue the path along
/// `previous` — or, leaving the fundamental path at a bifurcation, the
/// critical mode `leave_along` at the same load. Applies it, keeps it as the
/// step's accumulated increment `work.acc` and returns its `δλ`.
fn predict(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    (lambda, arc): (f64, f64),
    previous: Option<&[f64]>,
    leave_along: Option<&[f64]>,
) -> Result<f64, NewtonFailure> {
    // Predictor: the tangent direction, signed to continue the path — or,
    // leaving the fundamental path at a bifurcation, the critical mode at
    // the same load.
    set_load(sys, f_ref, lambda);
    sys.evaluate(&mut work.r);
    factor_and_solve_f(sys, lu, f_ref, work)
        .map_err(|e| NewtonFailure::LinearSolve(e.to_string()))?;
    let mut dl = 0.0;
    match leave_along {
        Some(mode) => {
            let scale = arc / norm(mode);
            for (a, m) in work.acc.iter_mut().zip(mode) {
                *a = scale * m;
            }
        }
        None => {
            let sign = match previous {
                Some(p) if dot(&work.qf, p) < 0.0 => -1.0,
                _ => 1.0,
            };
            dl = sign * arc / norm(&work.qf);
            for (a, f) in work.acc.iter_mut().zip(&work.qf) {
                *a = dl * f;
            }
        }
    }
    work.dq.copy_from_slice(&work.acc);
    sys.apply(&work.dq);
    Ok(dl)
}

/// One corrector iteration on the cylinder of radius `arc` (the residual
/// of the iterate in `work.r`): solves `K q_f = f_ref` and `K q_r = −r` with
/// one factorisation, takes the increment `q_r + δλ q_f` with `δλ` the root
/// of `‖acc + q_r + δλ q_f‖² = arc²` whose new increment turns least from
/// the step's so far, applies it, adds it to `work.acc` and returns `δλ`.
fn correct(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    arc: f64,
) -> Result<f64, NewtonFailure> {
    factor_and_solve_f(sys, lu, f_ref, work)
        .map_err(|e| NewtonFailure::LinearSolve(e.to_string()))?;
    // K q_r = −r into work.dq.
    for (d, r) in work.dq.iter_mut().zip(&work.r) {
        *d = -r;
    }
    lu.solve(&mut work.dq).map_err(NewtonFailure::LinearSolve)?;
    // ‖acc + q_r + δλ q_f‖² = arc²: a δλ² + b δλ + c = 0.
    let base: Vec<f64> = work.acc.iter().zip(&work.dq).map(|(a, d)| a + d).collect();
    let (a, b, c) = (
        dot(&work.qf, &work.qf),
        2.0 * dot(&work.qf, &base),
        dot(&base, &base) - arc * arc,
    );
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return Err(NewtonFailure::Rejected(
            "arc-length: the constraint has no real root (complex roots); the arc is \
             shortened"
                .into(),
        ));
    }
    let roots = [
        (-b + disc.sqrt()) / (2.0 * a),
        (-b - disc.sqrt()) / (2.0 * a),
    ];
    // The root whose increment turns least from the step's so far.
    let turn = |x: f64| {
        let new: Vec<f64> = base.iter().zip(&work.qf).map(|(q, f)| q + x * f).collect();
        dot(&new, &work.acc) / (norm(&new) * norm(&work.acc)).max(f64::MIN_POSITIVE)
    };
    let dlam = if turn(roots[0]) >= turn(roots[1]) {
        roots[0]
    } else {
        roots[1]
    };
    for ((d, f), a) in work.dq.iter_mut().zip(&work.qf).zip(work.acc.iter_mut()) {
        *d += dlam * f;
        *a += *d;
    }
    sys.apply(&work.dq);
    Ok(dlam)
}

/// The critical mode at the converged state (its tangent in the solver's
/// values): inverse iteration with the factorised tangent converges to the
/// eigenvector of the eigenvalue nearest zero. `None` for a limit point
/// (the load does work on the mode) or a failed solve.
fn critical_mode(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
) -> Option<Vec<f64>> {
    lu.factor(sys.tangent_values()).ok()?;
    let n = work.r.len();
    // A start with a share of every unknown (deterministic).
    let mut x: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.1 * ((i * 7919) % 13) as f64)
        .collect();
    for _ in 0..MODE_ITERATIONS {
        lu.solve(&mut x).ok()?;
        let s = norm(&x);
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        x.iter_mut().for_each(|v| *v /= s);
    }
    sys.reduce(f_ref, &mut work.fr);
    let cosine = dot(&x, &work.fr).abs() / norm(&work.fr).max(f64::MIN_POSITIVE);
    (cosine < BIFURCATION_COSINE).then_some(x)
}

/// Halves the arc length after a failed step, or gives up after
/// `max_halvings` in a row.
fn halve(
    arc: &mut f64,
    halvings: &mut usize,
    settings: &ArcLengthSettings,
    lambda: f64,
    reason: NewtonFailure,
) -> Result<(), SolveError> {
    if *halvings >= settings.max_halvings {
        return Err(SolveError::NoConvergence {
            time: lambda,
            halvings: *halvings,
            reason,
        });
    }
    *halvings += 1;
    *arc *= 0.5;
    Ok(())
}

/// Arc-length needs `f(λ) = λ f_ref`: no drivers, no follower loads, and
/// external forces linear in `λ` (checked at λ = 0, ½, 1).
fn refuse_unless_proportional(
    mech: &Mechanism,
    settings: &ArcLengthSettings,
) -> Result<(), SolveError> {
    let refuse = |why: &str| {
        Err(SolveError::InvalidMechanism(format!(
            "arc-length control needs proportional loads (f = λ f_ref): {why}"
        )))
    };
    if settings.load_steps == 0 {
        return refuse("load_steps must be at least 1");
    }
    if mech.has_drivers() {
        return refuse(
            "driven joints and prescribed DOFs control the path themselves; use load control",
        );
    }
    if !mech.follower_loads.is_empty() {
        return refuse("follower loads change with the configuration");
    }
    let n = 6 * mech.mesh.node_count();
    let (mut f0, mut fh, mut f1) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    mech.external_forces(0.0, &mut f0);
    mech.external_forces(0.5, &mut fh);
    mech.external_forces(1.0, &mut f1);
    let scale = f1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let off = f0
        .iter()
        .zip(&fh)
        .zip(&f1)
        .map(|((a, h), b)| (a.abs()).max((h - 0.5 * b).abs()))
        .fold(0.0f64, f64::max);
    if off > PROPORTIONAL * scale.max(f64::MIN_POSITIVE) {
        return refuse(
            "a load's time function is not the load factor itself (give loads without a \
             `time` table)",
        );
    }
    Ok(())
}
