//! Newton's switch from a cheap tangent to the exact one, on a small system
//! with a known root.

use super::*;
use faer::sparse::SymbolicSparseColMat;

/// `rᵢ(q) = qᵢ³ + qᵢ − 2` (root `qᵢ = 1`), two uncoupled unknowns; the
/// cheap tangent is the exact one times `factor`.
struct Cubic {
    q: [f64; 2],
    factor: f64,
    exact: bool,
    values: Vec<f64>,
    /// Tangent evaluations with the exact and the cheap tangent.
    exact_count: usize,
    cheap_count: usize,
    /// Round-off stand-in: added to `r₀` with alternating signs (so a
    /// converged iterate's residual is about twice it), and the floor set
    /// to `floor_noises` times it.
    noise: f64,
    floor_noises: f64,
    /// A floor set outright (0: none).
    floor_at: f64,
    /// [`NewtonSystem::evaluates_closing`], and whether the closing's
    /// evaluation computes the scaled residual (`Some(true)`) or only what
    /// the system reports (`Some(false)`).
    closing: Option<bool>,
}

impl Cubic {
    fn new(factor: f64) -> Self {
        Self {
            q: [1.02, 0.99],
            factor,
            exact: true,
            values: vec![0.0; 2],
            exact_count: 0,
            cheap_count: 0,
            noise: 0.0,
            floor_noises: 4.0,
            floor_at: 0.0,
            closing: None,
        }
    }
}

impl NewtonSystem for Cubic {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        let factor = if self.exact { 1.0 } else { self.factor };
        for ((ri, vi), &q) in r.iter_mut().zip(&mut self.values).zip(&self.q) {
            *ri = q * q * q + q - 2.0;
            *vi = factor * (3.0 * q * q + 1.0);
        }
        let sign = if (self.exact_count + self.cheap_count).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        r[0] += sign * self.noise;
        if self.exact {
            self.exact_count += 1;
        } else {
            self.cheap_count += 1;
        }
        2.0
    }
    fn tangent_values(&self) -> &[f64] {
        &self.values
    }
    fn apply(&mut self, dq: &[f64]) {
        self.q[0] += dq[0];
        self.q[1] += dq[1];
    }
    fn tangent_is_exact(&self) -> bool {
        self.exact || self.factor == 1.0
    }
    /// Round-off of `q³ + q − 2` near the root: a few ε.
    fn floor(&self) -> f64 {
        (16.0 * f64::EPSILON)
            .max(self.floor_noises * self.noise)
            .max(self.floor_at)
    }
    fn set_exact_tangent(&mut self, exact: bool) {
        self.exact = exact;
    }
    fn evaluates_closing(&self) -> bool {
        self.closing.is_some()
    }
    fn evaluate_closing(&mut self, r: &mut [f64]) -> Option<f64> {
        let scale = self.residual(r);
        let (_, res) = scaled_norm(residual_norm(r), scale);
        (self.closing == Some(true) || !res.is_finite()).then_some(res)
    }
    fn free_motion(&self, _mode: &[f64], _tangent: TangentRef) -> FreeMotion {
        FreeMotion::default()
    }
}

fn run(sys: &mut Cubic, exact_tangent: bool) -> NewtonReport {
    run_to(sys, exact_tangent, 1e-12)
}

fn run_to(sys: &mut Cubic, exact_tangent: bool, tolerance: f64) -> NewtonReport {
    let pattern = SymbolicSparseColMat::new_checked(2, 2, vec![0, 1, 2], None, vec![0, 1]);
    let mut lu = SparseLu::new(pattern).expect("pattern");
    let settings = NewtonSettings {
        tolerance,
        max_iterations: 40,
        modified: false,
        exact_tangent,
    };
    let (mut r, mut dq) = (vec![0.0; 2], vec![0.0; 2]);
    let report = solve(sys, &mut lu, &settings, &mut r, &mut dq).expect("converges");
    // The noise shifts the root of r₀ by about itself over r₀′ = 4.
    let near = 1e-10 + sys.noise;
    assert!((sys.q[0] - 1.0).abs() < near && (sys.q[1] - 1.0).abs() < near);
    report
}

#[test]
fn a_good_cheap_tangent_is_kept_to_the_end() {
    // 1 % off the exact derivative: linear contraction ≈ 0.01 < 1/20.
    let mut sys = Cubic::new(1.01);
    run(&mut sys, false);
    assert!(sys.cheap_count > 0);
    assert_eq!(sys.exact_count, 0, "switched although it contracted fast");
}

#[test]
fn a_poor_cheap_tangent_is_replaced_by_the_exact_one() {
    // Twice the exact derivative: contraction ≈ ½ near the root, so Newton
    // switches and converges quadratically from there. (A slow contraction
    // far from the root switches too, even where the exact tangent would
    // contract as slowly: the safe choice.)
    let mut sys = Cubic::new(2.0);
    let report = run(&mut sys, false);
    assert!(sys.exact_count > 0, "never switched");
    let slow = report
        .history
        .windows(2)
        .filter(|w| w[1] > INEXACT_CONTRACTION * w[0])
        .count();
    // The first correction is not judged (INEXACT_JUDGED_FROM), the second
    // switches, and this system's tangent comes with its residual, so the
    // switch shows one correction later: at most three slow ones.
    assert!(
        slow <= INEXACT_JUDGED_FROM + 1,
        "history {:?}",
        report.history
    );
    // The same solve with the exact tangent throughout never uses the
    // cheap one.
    let mut exact = Cubic::new(2.0);
    run(&mut exact, true);
    assert_eq!(exact.cheap_count, 0);
}

#[test]
fn full_newton_takes_chord_steps_once_a_correction_contracts_a_thousandfold() {
    // The exact tangent: corrections contract quadratically, 0.03, 4e-4,
    // then a thousandfold and more — from there the factorisation is kept
    // and the same root is reached to the tolerance.
    let mut sys = Cubic::new(1.0);
    let report = run(&mut sys, false);
    assert!(
        report.factorizations < report.iterations,
        "no chord step: {report:?}"
    );
    // Every correction after the last factorisation was licensed by the
    // one before it.
    let h = &report.history;
    let first_chord = report.factorizations;
    for k in first_chord..report.iterations {
        assert!(h[k] <= CHORD_CONTRACTION * h[k - 1], "{h:?}");
    }
    // `newton = "exact"`: a new tangent at every iterate.
    let mut exact = Cubic::new(1.0);
    let report = run(&mut exact, true);
    assert_eq!(report.factorizations, report.iterations, "{report:?}");
}

/// `rᵢ(q) = qᵢ² − 1`, two uncoupled unknowns: the tangent `2qᵢ` is singular
/// where an unknown is zero.
struct Square {
    q: [f64; 2],
    values: Vec<f64>,
}

impl NewtonSystem for Square {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        for ((ri, vi), &q) in r.iter_mut().zip(&mut self.values).zip(&self.q) {
            *ri = q * q - 1.0;
            *vi = 2.0 * q;
        }
        1.0
    }
    fn tangent_values(&self) -> &[f64] {
        &self.values
    }
    fn apply(&mut self, dq: &[f64]) {
        self.q[0] += dq[0];
        self.q[1] += dq[1];
    }
    fn free_motion(&self, _mode: &[f64], _tangent: TangentRef) -> FreeMotion {
        FreeMotion::default()
    }
}

#[test]
fn the_start_check_is_skipped_only_after_a_checked_solution() {
    let pattern = SymbolicSparseColMat::new_checked(2, 2, vec![0, 1, 2], None, vec![0, 1]);
    let settings = NewtonSettings {
        tolerance: 1e-12,
        max_iterations: 40,
        modified: false,
        exact_tangent: true,
    };
    let (mut r, mut dq) = (vec![0.0; 2], vec![0.0; 2]);
    let singular_start = |lu: &mut SparseLu, r: &mut [f64], dq: &mut [f64]| {
        let mut sys = Square {
            q: [0.0, 2.0],
            values: vec![0.0; 2],
        };
        solve(&mut sys, lu, &settings, r, dq)
    };
    // A first solve from a singular start: refused as singular at the start.
    let mut lu = SparseLu::new(pattern.clone()).expect("pattern");
    assert!(!lu.checked_regular());
    let first = singular_start(&mut lu, &mut r, &mut dq);
    assert!(
        matches!(
            first,
            Err(NewtonFailure::Singular {
                converged: false,
                ..
            })
        ),
        "{first:?}"
    );
    // A regular solve leaves its factorisation checked ...
    let mut lu = SparseLu::new(pattern).expect("pattern");
    let mut sys = Square {
        q: [0.5, 2.0],
        values: vec![0.0; 2],
    };
    solve(&mut sys, &mut lu, &settings, &mut r, &mut dq).expect("converges");
    assert!(lu.checked_regular());
    // ... so the next solve does not check its start: a tangent turned
    // singular fails it (a zero pivot), and the retry, whose start is
    // checked again, names the singularity.
    let next = singular_start(&mut lu, &mut r, &mut dq);
    assert!(
        matches!(
            next,
            Err(NewtonFailure::LinearSolve(_) | NewtonFailure::NotFinite { .. })
        ),
        "{next:?}"
    );
    assert!(!lu.checked_regular());
    let retry = singular_start(&mut lu, &mut r, &mut dq);
    assert!(
        matches!(
            retry,
            Err(NewtonFailure::Singular {
                converged: false,
                ..
            })
        ),
        "{retry:?}"
    );
}

#[test]
fn a_cheap_tangents_chord_to_the_floor_ends_the_solve_as_the_exact_ones_does() {
    // Residual noise of 1e-12 and a tolerance below it: every solve ends
    // at the floor. The cheap tangent 1e-4 off contracts linearly, at about
    // 5e-4 with the quadratic terms, so its corrections license chord
    // steps; the first iterate at the floor ends the solve (accepted where
    // its chord's licence says it is within the tolerance, else closed),
    // with no stall test's extra evaluation.
    let tolerance = 1e-13;
    let mut sys = Cubic::new(1.0001);
    sys.noise = 1e-12;
    let report = run_to(&mut sys, false, tolerance);
    assert_eq!(sys.exact_count, 0, "{report:?}");
    assert!(report.factorizations < report.iterations, "{report:?}");
    let h = &report.history;
    let floor = sys.floor() / 2.0;
    let last = h.len() - 1;
    assert!(h[last] <= floor, "{h:?}");
    assert!(h[last - 1] > floor, "the floor reached twice: {h:?}");
}

#[test]
fn a_cheap_tangents_landing_at_the_floor_is_closed_when_its_contraction_promises_the_tolerance() {
    // A cheap tangent 3e-3 off: its corrections contract less than a
    // thousandfold, `4.5e-2, 7.1e-4, 2.3e-6`; from there two chord steps
    // at the last contraction (3.3e-3) reach the tolerance, so the third
    // correction is a chord step, which lands at 7.2e-9, inside a floor of
    // 8e-9 but not within the tolerance it was expected to miss. Its
    // contraction repeated from there promises 2.3e-11, within the
    // tolerance: the solve ends with one more correction by that
    // factorisation, its residual not evaluated (before: evaluated, to find
    // it at the noise).
    let mut sys = Cubic::new(1.003);
    sys.noise = 1e-9;
    sys.floor_noises = 16.0;
    let report = run_to(&mut sys, false, 1e-10);
    let h = &report.history;
    let floor = sys.floor() / 2.0;
    assert_eq!(sys.exact_count, 0, "{report:?}");
    assert_eq!(h.len(), report.iterations, "closed: {report:?}");
    let last = h.len() - 1;
    assert!(h[last] <= floor && h[last - 1] > floor, "{h:?}");
    // Two factorisations: the chord step and the closing correction reuse
    // the second.
    assert_eq!(report.factorizations, report.iterations - 2, "{report:?}");
}

#[test]
fn a_closing_evaluated_for_what_the_system_reports_ends_the_history_only_with_its_residual() {
    // The closing of the test above, not evaluated, evaluated with its
    // scaled residual, and evaluated for what the system reports alone
    // (the energy–momentum scheme's nodal residual for the drivers' work):
    // the same iterates and solution to the bit; the residual ends the
    // history only where it was computed, and the evaluation is made where
    // it is asked for.
    let solve = |closing: Option<bool>| {
        let mut sys = Cubic::new(1.003);
        sys.noise = 1e-9;
        sys.floor_noises = 16.0;
        sys.closing = closing;
        let report = run_to(&mut sys, false, 1e-10);
        (sys.q, sys.cheap_count, report)
    };
    let (q, evaluations, report) = solve(None);
    assert_eq!(report.history.len(), report.iterations, "{report:?}");
    let (q_res, evaluations_res, with_res) = solve(Some(true));
    assert_eq!(
        with_res.history.len(),
        report.iterations + 1,
        "{with_res:?}"
    );
    assert_eq!(&with_res.history[..report.iterations], &report.history[..]);
    let (q_own, evaluations_own, own) = solve(Some(false));
    assert_eq!(own.history, report.history, "{own:?}");
    assert_eq!((q_res, q_own), (q, q), "the same solution");
    assert_eq!(
        (evaluations_res, evaluations_own),
        (evaluations + 1, evaluations + 1)
    );
}

#[test]
fn the_solution_is_the_same_whether_an_iterate_lands_just_inside_the_floor_or_just_outside() {
    // The exact tangent from (1.02, 0.99): scaled residuals 4.5e-2, 6e-4,
    // 1.3e-7, ... With the floor set a hair above the third iterate's
    // residual, the solve closes there (one more correction by the
    // factorisation that brought it, not evaluated); a hair below, that
    // iterate is outside the floor and the same factorisation makes the
    // same correction as a chord step, whose result is evaluated and within
    // the tolerance (1e-10). Either way the solution is the same to the bit: a
    // parameter that moves an iterate across the floor does not move the
    // solution by the floor (accepted as it was, it would move by 7e-8).
    let mut probe = Cubic::new(1.0);
    let h = run(&mut probe, true).history;
    let norm = 2.0 * h[2];
    assert!(h[1] <= FLOOR_ACCEPT_FROM && h[2] > 1e-9, "{h:?}");
    // With `newton = "exact"` the closing and the correction from outside
    // both take a new tangent at that iterate: the same again, and as many
    // factorisations as solves.
    for exact in [false, true] {
        let solve_with_floor = |floor: f64| {
            let mut sys = Cubic::new(1.0);
            sys.floor_at = floor;
            let report = run_to(&mut sys, exact, 1e-10);
            (sys.q, report)
        };
        let (inside, closed) = solve_with_floor(norm * (1.0 + 1e-9));
        let (outside, other) = solve_with_floor(norm * (1.0 - 1e-9));
        assert_eq!(closed.history.len(), 3, "closed at the third: {closed:?}");
        assert_eq!(closed.iterations, 3, "{closed:?}");
        // Outside the floor the chord step's contraction (2e-4 of 1.3e-7)
        // promises the tolerance: made and accepted unevaluated too
        // (`promised_end`); under `newton = "exact"` evaluated.
        let evaluated = if exact { 4 } else { 3 };
        assert_eq!(other.history.len(), evaluated, "{other:?}");
        assert_eq!(inside, outside, "{closed:?} {other:?}");
        if exact {
            assert_eq!(closed.factorizations, 3, "{closed:?}");
            assert_eq!(other.factorizations, 3, "{other:?}");
        }
    }
}

#[test]
fn a_chord_step_that_promises_the_tolerance_ends_the_solve_unevaluated() {
    // The exact tangent from (1.02, 0.99): scaled residuals 4.5e-2, 6e-4,
    // 1.3e-7 (no floor to speak of). The chord step from the third
    // contracts about as the correction before it, 2.2e-4: it promises
    // 2.8e-11. Against a tolerance of 1e-8 that is within its hundredth,
    // so the chord step is made and accepted without an evaluation: three
    // evaluations, three solves, two factorisations, and the root within
    // the tolerance (checked by evaluating it here).
    let mut sys = Cubic::new(1.0);
    let report = run_to(&mut sys, false, 1e-8);
    assert_eq!(report.history.len(), 3, "{report:?}");
    assert_eq!(report.iterations, 3, "{report:?}");
    assert_eq!(report.factorizations, 2, "{report:?}");
    let mut r = vec![0.0; 2];
    let scale = sys.evaluate(&mut r);
    let res = r.iter().map(|v| v * v).sum::<f64>().sqrt() / scale;
    assert!(res <= PROMISE_SHARE * 1e-8, "{res:e} {report:?}");
    // The report gives the promise: the last contraction times the last
    // residual evaluated.
    let h = &report.history;
    assert_eq!(report.residual, h[2] / h[1] * h[2], "{report:?}");
    // Against 1e-10 the promise is not within the tolerance's hundredth:
    // the chord step's result is evaluated.
    let mut strict = Cubic::new(1.0);
    let report = run_to(&mut strict, false, 1e-10);
    assert_eq!(report.history.len(), 4, "{report:?}");
    // Under `newton = "exact"` (a new tangent at every iterate) no chord
    // step, so no promise: the last iterate is evaluated.
    let mut exact = Cubic::new(1.0);
    let report = run_to(&mut exact, true, 1e-8);
    assert_eq!(report.history.len(), report.iterations + 1, "{report:?}");
}

#[test]
fn a_promise_needs_a_contraction_measured_near_the_solution_and_an_iterate_above_the_floor() {
    // Scale 2: the norm is twice the scaled residual. From 1e-3 to 1e-7 the
    // contraction 1e-4 promises 1e-11, within a hundredth of 1e-8.
    let settings = NewtonSettings {
        tolerance: 1e-8,
        max_iterations: 40,
        modified: false,
        exact_tangent: false,
    };
    let mut sys = Cubic::new(1.0);
    let promise = |sys: &Cubic, history: &[f64], factored: bool| {
        promised_end(
            2.0 * history[history.len() - 1],
            history,
            sys,
            &settings,
            factored,
        )
    };
    assert_eq!(
        promise(&sys, &[1e-3, 1e-7], true),
        Some(End::Promise(1e-4 * 1e-7))
    );
    // A contraction measured from farther promises nothing (far off, a
    // correction may contract a lot by chance).
    assert_eq!(promise(&sys, &[0.5, 1e-7], true), None);
    // Nor one without a factorisation of this solve, nor a contraction
    // that promises too little (1e-2 of 1e-7: 1e-9 is not within 1e-10).
    assert_eq!(promise(&sys, &[1e-3, 1e-7], false), None);
    assert_eq!(promise(&sys, &[1e-5, 1e-7], true), None);
    // At the floor the residual is noise: no chord licence there (the
    // correction is a floor reuse), and the floor's own tests end it.
    sys.floor_at = 1e-6;
    assert_eq!(promise(&sys, &[1e-3, 1e-7], true), None);
    // A floor below the norm but above the tolerance's norm (2e-8) sets
    // the bound: from 1e-3 to 5e-7 the promise, 5e-10 as a norm, is not
    // within a hundredth of the tolerance but is within one of a floor of
    // 1e-7.
    sys.floor_at = 0.0;
    assert_eq!(promise(&sys, &[1e-3, 5e-7], true), None);
    sys.floor_at = 1e-7;
    assert!(matches!(
        promise(&sys, &[1e-3, 5e-7], true),
        Some(End::Promise(_))
    ));
    let modified = NewtonSettings {
        modified: true,
        ..settings
    };
    let history = [1e-3, 1e-7];
    assert_eq!(
        promised_end(2e-7, &history, &Cubic::new(1.0), &modified, true),
        None
    );
}
