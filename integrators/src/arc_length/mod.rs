//! Static equilibrium paths past limit points: Crisfield's cylindrical
//! arc-length method (Crisfield 1981; *Non-linear Finite Element Analysis of
//! Solids and Structures*, vol. 1, §9.3). The load factor `λ` becomes an
//! unknown beside the reduced unknowns `q`, with the constraint that each
//! step advances a fixed length in `q`,
//!
//! ```text
//! r(q, λ) = g(q) − λ f_ref = 0,      ‖Δq‖_W² = Δl²
//! ```
//!
//! (`Δq` the step's accumulated increment, `‖·‖_W` the scaled norm of
//! FORMULATION §4.6, in which rotations count times the model's size). Each
//! iteration solves `K δq_r = −r` and `K δq_f = f_ref` with one
//! factorisation and picks `δλ` from the quadratic
//! `‖Δq + δq_r + δλ δq_f‖²_W = Δl²`, the root whose new increment turns
//! least from the last one; the predictor follows the previous step's
//! direction, so the path turns round limit points (snap through, snap
//! back) instead of stopping there.
//!
//! **Step length.** The first step's `Δl` is that of the load increment
//! `1/load_steps`. After each step it adapts to the iterations the step took
//! (`√(desired/taken)`, between ½ and 2), grows only where the path is
//! smooth (successive increments within `SMOOTH_TURN` of each other), never
//! beyond `MAX_ARC_GROWTH` first steps, and halves on failure.
//!
//! **Critical points.** A step after which the tangent has a different
//! number of negative eigenvalues crossed a limit point or a bifurcation:
//! [`crate::critical`] locates it by bisection on the step's arc
//! length and the step's record carries it. With `branch_switch`, the step
//! that crossed the first bifurcation ends at the converged state just past
//! the located point, and the path leaves the fundamental path there along
//! the critical mode.
//!
//! **End.** The path ends where it reaches the stop's load factor (1, the
//! model's loads, unless `stop.load_factor` says otherwise; that point
//! solved by load control), after the first step whose node displacement
//! reaches `stop.displacement`, or at its step budget — each a completed
//! path with its [`PathEnd`]. A step that fails at the smallest arc ends it
//! with an error.
//!
//! Loads must be proportional — `f(λ) = λ f_ref`: dead loads and gravity
//! ramped with `λ` — and nothing driven or following: those are refused.

mod branch;
mod step;

use crate::critical::{self, CriticalKind};
use crate::error::{NewtonFailure, SolveError};
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::newton::{NewtonReport, NewtonSettings, NewtonSystem};
use crate::record::StepRecord;
use crate::rotation_guard::RotationGuard;
use crate::sensitivity::{Parameter, StaticSensitivities};
use crate::stability::InertiaCount;
use crate::statics::{
    begin_step, converged_record, static_system, step_rejected, PathEnd, StaticOutcome, StaticTerms,
};
use crate::system::ReducedSystem;
use branch::BranchSwitch;
use step::{arc_step, factor_and_solve_f, set_load, solve_at_load, Heading, Work};

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
    /// Most steps the path takes (its budget: the path ends there,
    /// [`PathEnd::Budget`]).
    pub max_steps: usize,
    /// At the first bifurcation (a step after which the tangent has more
    /// negative eigenvalues, with a critical mode orthogonal to the load),
    /// leave the fundamental path along the critical mode.
    pub branch_switch: bool,
    /// Where the path ends before its budget.
    pub stop: PathStop,
}

/// Where an arc-length path ends (`[solver] stop = { … }`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathStop {
    /// The path ends where the load factor first reaches this value (that
    /// point solved exactly); 1 — the model's loads — by default.
    pub load_factor: f64,
    /// `(node, max)`: the path ends after the first step at which the
    /// node's displacement `|x − X|` reaches `max`.
    pub displacement: Option<(usize, f64)>,
}

impl Default for PathStop {
    /// At the model's loads (λ = 1), no displacement limit.
    fn default() -> Self {
        Self {
            load_factor: 1.0,
            displacement: None,
        }
    }
}

/// Iterations a step should take; the arc length adapts towards it.
const DESIRED_ITERATIONS: f64 = 5.0;
/// The arc length grows to at most this many first steps.
const MAX_ARC_GROWTH: f64 = 1e3;
/// The arc grows only when the step's increment turned from the last by
/// less than this (cosine of 8°): where the path is smooth.
const SMOOTH_TURN: f64 = 0.99;
/// Relative tolerance of the proportionality check `f(½) = ½ f(1)`.
const PROPORTIONAL: f64 = 1e-12;

/// Traces the static path of `mech` under its proportional loads with the
/// arc-length method, calling `on_step` with every converged step.
pub fn solve_arc_length(
    mech: &Mechanism,
    settings: &ArcLengthSettings,
    on_step: impl FnMut(&StepRecord),
) -> Result<StaticOutcome, SolveError> {
    solve_arc_length_with(mech, settings, &[], on_step)
}

/// The loop's state: the system with its solvers, the path so far.
struct Tracer<'m, 's> {
    mech: &'m Mechanism,
    settings: &'s ArcLengthSettings,
    sys: ReducedSystem<'m, StaticTerms>,
    lu: SparseLu,
    inertia: InertiaCount,
    work: Work,
    f_ref: Vec<f64>,
    lambda: f64,
    steps: usize,
    /// The arc length of the next step, and the largest it may grow to.
    arc: f64,
    max_arc: f64,
    /// The last step's increment (the path's sense).
    previous: Option<Vec<f64>>,
    halvings: usize,
    branch: BranchSwitch,
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
    let mut t = Tracer::new(mech, settings)?;
    let mut sensitivities = StaticSensitivities::new(&t.sys, params)?;
    let mut guard = RotationGuard::new(mech, &t.sys.end);
    loop {
        if let Some(end) = t.ended() {
            return Ok(StaticOutcome::reached(t.sys, t.steps, end));
        }
        begin_step(&mut t.sys);
        let start = t.sys.start.clone();
        let direction = t.branch.direction();
        let heading = Heading {
            previous: t.previous.as_deref(),
            leave_along: direction.as_deref(),
        };
        let arc = t.arc;
        let solved = arc_step(
            &mut t.sys,
            &mut t.lu,
            &t.f_ref,
            &mut t.work,
            &settings.newton,
            (t.lambda, arc),
            heading,
        );
        let (lambda_new, report) = match solved {
            Ok(done) => done,
            Err(reason) => {
                t.sys.end.clone_from(&t.sys.start);
                t.halve(reason)?;
                continue;
            }
        };
        if let Err(objection) = guard.accept(mech, &t.sys.end, lambda_new) {
            let reason = step_rejected(&mut t.sys, objection)?;
            t.halve(reason)?;
            continue;
        }
        let (lambda_rec, report) = t.at_stop(lambda_new, report)?;
        let increment = t.work.acc.clone();
        let mut step = t.record(lambda_rec, &report);
        if direction.is_none() {
            step = t.locate(&start, step, arc, &report);
        }
        step.sensitivities = sensitivities.at(&t.sys, step.time)?;
        on_step(&step);
        t.advance(&increment, &step, direction.is_some(), report.iterations);
    }
}

impl<'m, 's> Tracer<'m, 's> {
    /// The system of `mech` at its initial state, the first arc length.
    fn new(mech: &'m Mechanism, settings: &'s ArcLengthSettings) -> Result<Self, SolveError> {
        let (sys, lu, inertia) = static_system(mech)?;
        let mut f_ref = vec![0.0; 6 * mech.mesh.node_count()];
        mech.external_forces(1.0, &mut f_ref);
        let work = Work::new(&sys);
        let mut t = Self {
            mech,
            settings,
            sys,
            lu,
            inertia,
            work,
            f_ref,
            lambda: 0.0,
            steps: 0,
            arc: 0.0,
            max_arc: 0.0,
            previous: None,
            halvings: 0,
            branch: BranchSwitch::default(),
        };
        let count = crate::statics::initial_count(&mut t.sys, &mut t.inertia, &mut t.work.r);
        t.branch = BranchSwitch::starting_with(count);
        t.arc = t.first_arc()?;
        t.max_arc = MAX_ARC_GROWTH * t.arc;
        Ok(t)
    }

    /// The arc length `Δl` of the path, from the first load-controlled
    /// predictor: `‖K⁻¹ f_ref‖_W / load_steps` at the initial state (its
    /// tangent evaluated with λ = 0). An error when the loads do nothing.
    fn first_arc(&mut self) -> Result<f64, SolveError> {
        set_load(&mut self.sys, &self.f_ref, 0.0);
        self.sys.evaluate(&mut self.work.r);
        factor_and_solve_f(&mut self.sys, &mut self.lu, &self.f_ref, &mut self.work)
            .map_err(SolveError::Singular)?;
        let first = 1.0 / self.settings.load_steps.max(1) as f64;
        let arc = first * self.work.norm(&self.work.qf);
        if !(arc > 0.0 && arc.is_finite()) {
            return Err(SolveError::InvalidMechanism(
                "arc-length: the loads do nothing (f_ref = 0); give the model a load".into(),
            ));
        }
        Ok(arc)
    }

    /// Why the path ends now, if it does.
    fn ended(&self) -> Option<PathEnd> {
        let (lambda, stop) = (self.lambda, &self.settings.stop);
        if lambda >= stop.load_factor {
            return Some(PathEnd::Reached {
                load_factor: lambda,
            });
        }
        if let Some((node, max)) = stop.displacement {
            let x = self.sys.end.config.x[node];
            let displacement = (x - self.mech.mesh.positions[node]).norm();
            if displacement >= max {
                return Some(PathEnd::Displacement {
                    node,
                    displacement,
                    load_factor: lambda,
                });
            }
        }
        (self.steps >= self.settings.max_steps).then_some(PathEnd::Budget {
            steps: self.steps,
            load_factor: lambda,
        })
    }

    /// The step's load factor and report: the arc-length solution, or —
    /// when the step passed the stop's load factor — that point, solved by
    /// load control from the step's start.
    fn at_stop(
        &mut self,
        lambda_new: f64,
        report: NewtonReport,
    ) -> Result<(f64, NewtonReport), SolveError> {
        let target = self.settings.stop.load_factor;
        if !(lambda_new > target && self.lambda < target) {
            return Ok((lambda_new, report));
        }
        let newton = &self.settings.newton;
        let report = solve_at_load(
            &mut self.sys,
            &mut self.lu,
            &self.f_ref,
            &mut self.work,
            (newton, target),
        )
        .map_err(|reason| SolveError::NoConvergence {
            time: target,
            halvings: self.halvings,
            reason,
        })?;
        Ok((target, report))
    }

    /// The record of the converged step to `lambda` (the loads set there).
    fn record(&mut self, lambda: f64, report: &NewtonReport) -> StepRecord {
        set_load(&mut self.sys, &self.f_ref, lambda);
        let dl = lambda - self.lambda;
        converged_record(
            &mut self.sys,
            &mut self.inertia,
            &mut self.work.r,
            (lambda, dl),
            report,
            None,
        )
    }

    /// The step from `start` to `step` with the critical point it crossed,
    /// if the count changed: bisection on the fraction of the step's `arc`
    /// (of the load increment, for a step ended at the stop's load factor).
    /// At a bifurcation the path is to leave by (`branch_switch`, not yet
    /// switched), the step ends at the converged state just past the point
    /// instead, so the path leaves there.
    fn locate(
        &mut self,
        start: &crate::constraints::MechanismState,
        mut step: StepRecord,
        arc: f64,
        report: &NewtonReport,
    ) -> StepRecord {
        let (Some(before), Some(after)) = (self.branch.last_count(), step.negative_pivots) else {
            return step;
        };
        if before == after {
            return step;
        }
        let (lambda0, newton) = (self.lambda, self.settings.newton);
        let previous = self.previous.clone();
        let at_stop = step.time == self.settings.stop.load_factor;
        let f_ref = self.f_ref.clone();
        let work = &mut self.work;
        let mut scratch = vec![0.0; work.r.len()];
        let located = critical::locate(
            &mut self.sys,
            (&mut self.inertia, &mut self.lu, &mut scratch),
            (start, lambda0, before),
            (step.time, after),
            &f_ref,
            |sys, lu, s| {
                if at_stop {
                    let lambda = lambda0 + s * (step.time - lambda0);
                    solve_at_load(sys, lu, &f_ref, work, (&newton, lambda)).map(|_| lambda)
                } else {
                    let heading = Heading {
                        previous: previous.as_deref(),
                        leave_along: None,
                    };
                    arc_step(sys, lu, &f_ref, work, &newton, (lambda0, s * arc), heading)
                        .map(|(lambda, _)| lambda)
                }
            },
            |sys, lambda| set_load(sys, &f_ref, lambda),
        );
        let Some((point, past)) = located else {
            return step;
        };
        let leave = self.settings.branch_switch
            && !self.branch.switched()
            && point.kind == CriticalKind::Bifurcation;
        if let (true, Some((state, lambda))) = (leave, past) {
            self.sys.end = state;
            step = self.record(lambda, report);
        }
        step.critical = Some(point);
        step
    }

    /// After a step (its record reported): the path's state, the branch
    /// switch's count and mode, the next arc length.
    fn advance(&mut self, increment: &[f64], step: &StepRecord, left: bool, iterations: usize) {
        let turned = self.previous.as_deref().map_or(1.0, |p| {
            self.work.dot(p, increment)
                / (self.work.norm(p) * self.work.norm(increment)).max(f64::MIN_POSITIVE)
        });
        self.lambda = step.time;
        self.steps += 1;
        let grew = self.branch.count(step.negative_pivots);
        if self.settings.branch_switch
            && grew
            && !self.branch.switched()
            && !left
            && self.lambda < self.settings.stop.load_factor
        {
            self.branch.found(&self.sys, &mut self.lu, &self.f_ref);
        }
        let taken = iterations.max(1) as f64;
        let mut factor = (DESIRED_ITERATIONS / taken).sqrt().clamp(0.5, 2.0);
        if turned < SMOOTH_TURN {
            factor = factor.min(1.0);
        }
        self.arc = (self.arc * factor).min(self.max_arc);
        self.previous = Some(increment.to_vec());
        self.halvings = 0;
    }

    /// Halves the arc length after a failed step, or gives up after
    /// `max_halvings` in a row.
    fn halve(&mut self, reason: NewtonFailure) -> Result<(), SolveError> {
        if self.halvings >= self.settings.max_halvings {
            return Err(SolveError::NoConvergence {
                time: self.lambda,
                halvings: self.halvings,
                reason,
            });
        }
        self.halvings += 1;
        self.arc *= 0.5;
        Ok(())
    }
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
