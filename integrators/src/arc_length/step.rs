//! One arc-length step: the predictor along the path's tangent (or a
//! critical mode), the corrector iterations on the cylinder
//! `‖Δq‖_W = Δl`, and the scaled norm they measure with.
//!
//! **The norm.** The reduced unknowns mix translations (model lengths) and
//! rotations (radians, the joints' released angles): in a model measured in
//! millimetres a rotation of one radian would count as much as one
//! millimetre. The path's norm weighs each unknown by the largest nodal
//! motion it causes, rotations times the model's size `L` (the diagonal of
//! the nodes' bounding box):
//!
//! ```text
//! ‖Δq‖²_W = Σₑ wₑ Δqₑ²,   wₑ = maxₙ (|cᵤ|² + L² |c_φ|²)
//! ```
//!
//! with `(cᵤ, c_φ)` the column of unknown `e` in node `n`'s increment
//! ([`crate::dofs::NodeMap`]): 1 for a node's own translation, `L²` for its
//! rotation, `L² + |f′(ψ)|²` for a screw's released angle. A turn of the
//! whole model by `θ` then weighs as a displacement of `θL`.

use crate::error::NewtonFailure;
use crate::linsolve::SparseLu;
use crate::newton::{NewtonReport, NewtonSettings, NewtonSystem};
use crate::statics::StaticTerms;
use crate::system::ReducedSystem;

/// Scratch of the iterations: residual, Newton increment, the two
/// solutions, the step's accumulated increment and the norm's weights.
pub(super) struct Work {
    pub(super) r: Vec<f64>,
    pub(super) dq: Vec<f64>,
    pub(super) qf: Vec<f64>,
    pub(super) acc: Vec<f64>,
    fr: Vec<f64>,
    /// The weight `wₑ` of every unknown in the path's norm.
    weights: Vec<f64>,
}

impl Work {
    /// Scratch for `sys`, with the weights of its unknowns at its state.
    pub(super) fn new(sys: &ReducedSystem<'_, StaticTerms>) -> Self {
        let n = sys.topo.dofs.n_eq;
        Self {
            r: vec![0.0; n],
            dq: vec![0.0; n],
            qf: vec![0.0; n],
            acc: vec![0.0; n],
            fr: vec![0.0; n],
            weights: weights(sys),
        }
    }

    /// `‖v‖_W`.
    pub(super) fn norm(&self, v: &[f64]) -> f64 {
        self.dot(v, v).sqrt()
    }

    /// `aᵀ W b`.
    pub(super) fn dot(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| w * x * y)
            .sum()
    }
}

/// The weights of the path's norm (see the module docs).
fn weights(sys: &ReducedSystem<'_, StaticTerms>) -> Vec<f64> {
    let x = &sys.end.config.x;
    let (mut lo, mut hi) = (x[0], x[0]);
    for p in x {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let size = (hi - lo).norm();
    let l2 = if size > 0.0 { size * size } else { 1.0 };
    let mut w = vec![0.0f64; sys.topo.dofs.n_eq];
    for node in &sys.topo.dofs.nodes {
        for (&e, c) in node.eqs.iter().zip(&node.cols) {
            let u = c.fixed_rows::<3>(0).norm_squared();
            let phi = c.fixed_rows::<3>(3).norm_squared();
            w[e] = w[e].max(u + l2 * phi);
        }
    }
    // An unknown no node moves with (none today) counts as a length.
    w.iter_mut().filter(|v| **v == 0.0).for_each(|v| *v = 1.0);
    w
}

/// The loads at the load factor `lambda`.
pub(super) fn set_load(sys: &mut ReducedSystem<'_, StaticTerms>, f_ref: &[f64], lambda: f64) {
    for (f, r) in sys.fext.iter_mut().zip(f_ref) {
        *f = lambda * r;
    }
    sys.load_time = lambda;
}

/// Factorises the tangent of the last evaluation and solves `K q_f = f_ref`
/// (reduced at the current iterate) into `work.qf`.
pub(super) fn factor_and_solve_f(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
) -> Result<(), String> {
    lu.factor(sys.tangent_values())?;
    sys.reduce(f_ref, &mut work.fr);
    work.qf.copy_from_slice(&work.fr);
    lu.solve(&mut work.qf)
}

/// Solves the path's point at the load factor `lambda` by load control
/// from the step's start (`sys.start`); Newton's report.
pub(super) fn solve_at_load(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    (newton, lambda): (&NewtonSettings, f64),
) -> Result<NewtonReport, NewtonFailure> {
    sys.end.clone_from(&sys.start);
    set_load(sys, f_ref, lambda);
    crate::newton::solve(sys, lu, newton, &mut work.r, &mut work.dq)
}

/// The predictor and the corrector's directions of one step: the previous
/// step's increment (the path's sense) and, leaving the fundamental path
/// at a bifurcation, the critical mode.
#[derive(Clone, Copy, Default)]
pub(super) struct Heading<'a> {
    pub(super) previous: Option<&'a [f64]>,
    pub(super) leave_along: Option<&'a [f64]>,
}

/// One arc-length step from `sys.start` at `lambda`: predictor along the
/// previous direction, then corrector iterations on the cylinder of radius
/// `arc`. Returns the new load factor and Newton's report.
pub(super) fn arc_step(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    newton: &NewtonSettings,
    (lambda, arc): (f64, f64),
    heading: Heading<'_>,
) -> Result<(f64, NewtonReport), NewtonFailure> {
    let mut dl = predict(sys, lu, f_ref, work, (lambda, arc), heading)?;
    let mut history = Vec::new();
    for it in 1..=newton.max_iterations {
        set_load(sys, f_ref, lambda + dl);
        let scale = sys.evaluate(&mut work.r);
        let rn = work.r.iter().map(|x| x * x).sum::<f64>().sqrt();
        let res = rn / scale.max(f64::MIN_POSITIVE);
        history.push(res);
        if !res.is_finite() {
            return Err(NewtonFailure::NotFinite { iteration: it });
        }
        if res <= newton.tolerance || rn <= sys.floor {
            let report = NewtonReport {
                iterations: it,
                factorizations: it,
                residual: res,
                history,
            };
            return Ok((lambda + dl, report));
        }
        dl += correct(sys, lu, f_ref, work, arc)?;
    }
    Err(NewtonFailure::MaxIterations {
        iterations: newton.max_iterations,
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
    heading: Heading<'_>,
) -> Result<f64, NewtonFailure> {
    set_load(sys, f_ref, lambda);
    sys.evaluate(&mut work.r);
    factor_and_solve_f(sys, lu, f_ref, work).map_err(NewtonFailure::LinearSolve)?;
    let mut dl = 0.0;
    match heading.leave_along {
        Some(mode) => {
            let scale = arc / work.norm(mode);
            for (a, m) in work.acc.iter_mut().zip(mode) {
                *a = scale * m;
            }
        }
        None => {
            let sign = match heading.previous {
                Some(p) if work.dot(&work.qf, p) < 0.0 => -1.0,
                _ => 1.0,
            };
            dl = sign * arc / work.norm(&work.qf);
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
/// of `‖acc + q_r + δλ q_f‖²_W = arc²` whose new increment turns least from
/// the step's so far, applies it, adds it to `work.acc` and returns `δλ`.
fn correct(
    sys: &mut ReducedSystem<'_, StaticTerms>,
    lu: &mut SparseLu,
    f_ref: &[f64],
    work: &mut Work,
    arc: f64,
) -> Result<f64, NewtonFailure> {
    factor_and_solve_f(sys, lu, f_ref, work).map_err(NewtonFailure::LinearSolve)?;
    // K q_r = −r into work.dq.
    for (d, r) in work.dq.iter_mut().zip(&work.r) {
        *d = -r;
    }
    lu.solve(&mut work.dq).map_err(NewtonFailure::LinearSolve)?;
    // ‖acc + q_r + δλ q_f‖² = arc²: a δλ² + b δλ + c = 0.
    let base: Vec<f64> = work.acc.iter().zip(&work.dq).map(|(a, d)| a + d).collect();
    let (a, b, c) = (
        work.dot(&work.qf, &work.qf),
        2.0 * work.dot(&work.qf, &base),
        work.dot(&base, &base) - arc * arc,
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
        work.dot(&new, &work.acc) / (work.norm(&new) * work.norm(&work.acc)).max(f64::MIN_POSITIVE)
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
