//! Newton on `(q, β)` for the paper's energy–momentum scheme
//! ([`super::energy_momentum_paper`], eq. 18): the bordered tangent
//! `[K b; cᵀ d]`, `b = ∂g/∂β`, `c = ∂e/∂q`, `d = ∂e/∂β`, solved by two
//! solves with one factorisation, so that Newton stays quadratic.

use super::midpoint_kernels::{midpoint_forces, seeded_poses, Dual12};
use crate::error::NewtonFailure;
use crate::linsolve::SparseLu;
use crate::newton::{
    at_floor, check_regular, diverged, NewtonReport, NewtonSettings, NewtonSystem,
};
use crate::system::{ReducedSystem, StepTerms};
use crate::threads::map_each;
use crate::tolerances::TOLERANCES;
use flexmech_core::conserving::MidRotation;
use flexmech_core::rotation::cayley_inverse;
use flexmech_core::{Configuration, Element};
use nalgebra::{Const, SVector, U1};

/// Terms whose element force carries the correction `β q_k(N_d, 0)`.
pub(crate) trait Bordered: StepTerms {
    /// Sets the correction's factor β for the next evaluation.
    fn set_beta(&mut self, beta: f64);
}

/// Per element: the energy residual `e = p·q_k(N̄, M̄) − ΔΠ`, the correction's
/// work `c = p·q_k(N_d, 0)` and `q_k(N_d, 0)` itself, with the gradients of
/// `e` and `c` with respect to spatial increments of the end pose (AD).
struct EnergyTerms {
    e: f64,
    de: SVector<f64, 12>,
    c: f64,
    dc: SVector<f64, 12>,
    qd: SVector<f64, 12>,
}

fn energy_terms(el: &Element, start: &Configuration, end: &Configuration) -> EnergyTerms {
    let Element::Linear(e) = el else {
        unreachable!("the midpoint schemes are checked to run on 2-node elements")
    };
    type D = Dual12;
    let (s, sd, ed) = seeded_poses(e, start, end);
    let (qk, qd) = midpoint_forces(e, &s, &sd, &ed, MidRotation::Algebraic, true);
    let qd = qd.expect("the correction was asked for");
    // The step's increments: uᵢ and the tangent-scaled θᵢ with Rₙ₊₁ = cay(θᵢ)Rₙ.
    let mut work_k = D::from_re(0.0);
    let mut work_d = D::from_re(0.0);
    for i in 0..2 {
        let u = ed.0[i] - sd.0[i];
        let th = cayley_inverse(&(ed.1[i] * sd.1[i].transpose()));
        work_k += u.dot(&qk.fixed_rows::<3>(6 * i)) + th.dot(&qk.fixed_rows::<3>(6 * i + 3));
        work_d += u.dot(&qd.fixed_rows::<3>(6 * i)) + th.dot(&qd.fixed_rows::<3>(6 * i + 3));
    }
    let de_pi = e.energy(&ed.0, &ed.1) - D::from_re(e.energy(&s.0, &s.1));
    let ee = work_k - de_pi;
    EnergyTerms {
        e: ee.re,
        de: ee.eps.unwrap_generic(Const::<12>, U1),
        c: work_d.re,
        dc: work_d.eps.unwrap_generic(Const::<12>, U1),
        qd: qd.map(|x| x.re),
    }
}

/// Scratch of the bordered iterations: the residual `r`, the border
/// `b = ∂(Ñᵀg)/∂β`, the reduced gradients `∇E`, `∇C` of the energy terms, and
/// the two solutions `y₁ = −K⁻¹r`, `y₂ = K⁻¹b` of one factorisation.
struct BorderedWork {
    r: Vec<f64>,
    b: Vec<f64>,
    ge: Vec<f64>,
    gc: Vec<f64>,
    y1: Vec<f64>,
    y2: Vec<f64>,
}

impl BorderedWork {
    /// Buffers for `n_eq` reduced unknowns.
    fn new(n_eq: usize) -> Self {
        Self {
            r: vec![0.0; n_eq],
            b: vec![0.0; n_eq],
            ge: vec![0.0; n_eq],
            gc: vec![0.0; n_eq],
            y1: vec![0.0; n_eq],
            y2: vec![0.0; n_eq],
        }
    }
}

/// The energy equation's sums over the elements: `E = Σ e`, `C = Σ c` (the
/// residual is `E + βC`) and its scale `Σ |e| + |c|`.
struct EnergySums {
    e_tot: f64,
    c_tot: f64,
    e_scale: f64,
}

/// Newton on `(q, β)` with the bordered tangent. Returns the report and β
/// (NaN when the correction had no effect on the energy).
pub(super) fn solve_step<T: Bordered>(
    sys: &mut ReducedSystem<'_, T>,
    lu: &mut SparseLu,
    settings: &NewtonSettings,
) -> Result<(NewtonReport, f64), NewtonFailure> {
    let mut work = BorderedWork::new(sys.topo.dofs.n_eq);
    let mut history = Vec::with_capacity(settings.max_iterations + 1);
    let mut beta = 0.0;
    let mut determined = true;
    let mut previous_norm = f64::INFINITY;
    for it in 0..=settings.max_iterations {
        sys.terms.set_beta(beta);
        let scale = sys.evaluate(&mut work.r);
        let sums = energy_equation(sys, &mut work);
        let energy = sums.e_tot + beta * sums.c_tot;
        let norm = work.r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let res_g = if norm == 0.0 {
            0.0
        } else {
            norm / scale.max(f64::MIN_POSITIVE)
        };
        let res_e = energy.abs() / sums.e_scale.max(f64::MIN_POSITIVE);
        let res = if determined { res_g.max(res_e) } else { res_g };
        history.push(res);
        if !res.is_finite() {
            return Err(NewtonFailure::NotFinite { iteration: it });
        }
        let g_ok = res_g <= settings.tolerance || at_floor(norm, &mut previous_norm, sys.floor());
        // The energy residual's own round-off floor: forces rounded at the
        // system's force floor, times the size of the step's increments.
        let increments = step_increments(sys);
        let e_ok = !determined
            || res_e <= settings.tolerance
            || energy.abs()
                <= TOLERANCES.energy_round_off * sums.e_scale + sys.floor() * increments;
        if g_ok && e_ok {
            check_regular(sys, lu, it > 0, true)?;
            let beta_out = if determined { beta } else { f64::NAN };
            return Ok((
                NewtonReport {
                    iterations: it,
                    factorizations: it,
                    residual: res,
                    history,
                },
                beta_out,
            ));
        }
        if let Some(failure) = diverged(it, res, &history, settings) {
            return Err(failure);
        }
        if it == settings.max_iterations {
            break;
        }
        solve_both(sys, lu, &mut work)?;
        let dbeta = match beta_increment(&work, sums.c_tot, energy, beta) {
            Some(dbeta) => {
                determined = true;
                dbeta
            }
            None => {
                // β has no lever on the energy in this step: solve without it.
                determined = false;
                beta = 0.0;
                0.0
            }
        };
        beta += dbeta;
        let dq: Vec<f64> = work
            .y1
            .iter()
            .zip(&work.y2)
            .map(|(a, b)| a - b * dbeta)
            .collect();
        sys.apply(&dq);
    }
    Err(NewtonFailure::MaxIterations {
        iterations: settings.max_iterations,
        residual: *history.last().unwrap_or(&f64::NAN),
    })
}

/// The energy equation and its border at the iterate: every element's
/// [`EnergyTerms`] (in parallel), summed in element order (deterministic)
/// into the returned sums and the nodal vectors, which are reduced into
/// `work.b` (a residual, through `Ñ`), `work.ge` and `work.gc` (derivatives,
/// through the end-point maps).
fn energy_equation<T: Bordered>(sys: &ReducedSystem<'_, T>, work: &mut BorderedWork) -> EnergySums {
    energy_equation_nodal(sys, work).0
}

/// [`energy_equation`] with its nodal vectors (`q_k(N_d, 0)`, `∇e`, `∇c`).
fn energy_equation_nodal<T: Bordered>(
    sys: &ReducedSystem<'_, T>,
    work: &mut BorderedWork,
) -> (EnergySums, [Vec<f64>; 3]) {
    let nodes = sys.end.config.x.len();
    // Energy equation and its border, element by element (in order: deterministic).
    let (mut e_tot, mut c_tot, mut e_scale) = (0.0, 0.0, 0.0);
    let mut nodal = [
        vec![0.0; 6 * nodes],
        vec![0.0; 6 * nodes],
        vec![0.0; 6 * nodes],
    ];
    // Element terms in parallel, summed in element order (deterministic).
    let (start, end) = (&sys.start.config, &sys.end.config);
    let elements = &sys.mech.mesh.elements;
    let terms = map_each(elements.len(), |e| energy_terms(&elements[e], start, end));
    for (el, t) in sys.mech.mesh.elements.iter().zip(&terms) {
        e_tot += t.e;
        c_tot += t.c;
        e_scale += t.e.abs() + t.c.abs();
        for (a, &nd) in el.nodes().iter().enumerate() {
            for d in 0..6 {
                nodal[0][6 * nd + d] += t.qd[6 * a + d];
                nodal[1][6 * nd + d] += t.de[6 * a + d];
                nodal[2][6 * nd + d] += t.dc[6 * a + d];
            }
        }
    }
    // b = ∂(Ñᵀg)/∂β is a residual (through Ñ); the gradients of the
    // energy terms are derivatives (through the end-point maps).
    sys.reduce(&nodal[0], &mut work.b);
    sys.topo.dofs.reduce(&nodal[1], &mut work.ge);
    sys.topo.dofs.reduce(&nodal[2], &mut work.gc);
    let sums = EnergySums {
        e_tot,
        c_tot,
        e_scale,
    };
    (sums, nodal)
}

/// The size of the step's increments, `(Σᵢ |uᵢ|² + |θᵢ|²)^½` with
/// `uᵢ = xᵢ,ₙ₊₁ − xᵢ,ₙ` and `Rᵢ,ₙ₊₁ = cay(θᵢ) Rᵢ,ₙ`.
fn step_increments<T: Bordered>(sys: &ReducedSystem<'_, T>) -> f64 {
    let nodes = sys.end.config.x.len();
    (0..nodes)
        .map(|i| {
            let (s0, s1) = (&sys.start.config, &sys.end.config);
            let u = s1.x[i] - s0.x[i];
            let th = cayley_inverse(&(s1.rot[i] * s0.rot[i].transpose()));
            u.norm_squared() + th.norm_squared()
        })
        .sum::<f64>()
        .sqrt()
}

/// Factorises the tangent `K` and solves, with that one factorisation,
/// `K y₁ = −r` and `K y₂ = b` into `work.y1`, `work.y2`.
fn solve_both<T: Bordered>(
    sys: &ReducedSystem<'_, T>,
    lu: &mut SparseLu,
    work: &mut BorderedWork,
) -> Result<(), NewtonFailure> {
    lu.factor(sys.tangent_values())
        .map_err(NewtonFailure::LinearSolve)?;
    for (y, v) in work.y1.iter_mut().zip(&work.r) {
        *y = -v;
    }
    lu.solve(&mut work.y1).map_err(NewtonFailure::LinearSolve)?;
    work.y2.copy_from_slice(&work.b);
    lu.solve(&mut work.y2).map_err(NewtonFailure::LinearSolve)
}

/// The increment of β from the bordered system's last row, with the border
/// `c = ∂e/∂q = ∇E + β∇C`, `d = ∂e/∂β = C`:
/// `δβ = (−e − c·y₁)/(d − c·y₂)` — or `None` when the pivot `d − c·y₂` is
/// negligible against `|d| + |c||y₂|` (or not finite): β has no lever on
/// the energy in this step.
fn beta_increment(work: &BorderedWork, c_tot: f64, energy: f64, beta: f64) -> Option<f64> {
    // Border: c = ∂e/∂q = ∇E + β∇C, d = ∂e/∂β = C.
    let c: Vec<f64> = work
        .ge
        .iter()
        .zip(&work.gc)
        .map(|(a, g)| a + beta * g)
        .collect();
    let cy1: f64 = c.iter().zip(&work.y1).map(|(a, b)| a * b).sum();
    let cy2: f64 = c.iter().zip(&work.y2).map(|(a, b)| a * b).sum();
    let pivot = c_tot - cy2;
    let size = c_tot.abs()
        + c.iter().map(|v| v * v).sum::<f64>().sqrt()
            * work.y2.iter().map(|v| v * v).sum::<f64>().sqrt();
    (pivot.abs() > TOLERANCES.border_pivot * size && pivot.is_finite())
        .then(|| (-energy - cy1) / pivot)
}

/// The border of a converged step of the paper's scheme, for exact
/// sensitivities: `y₂ = K⁻¹b`, the energy equation's reduced gradient
/// `c = ∇E + β∇C` and the pivot `d − c·y₂` (`d = C`).
pub(super) struct Border {
    y2: Vec<f64>,
    c: Vec<f64>,
    pivot: f64,
    /// The energy residual's nodal gradient `∂e/∂(x, φ)` (6 per node).
    nodal: Vec<f64>,
}

impl Border {
    /// At the converged state of a step [`solve_step`] solved with β, `lu`
    /// holding its factorised exact tangent.
    pub(super) fn at<T: Bordered>(
        sys: &ReducedSystem<'_, T>,
        lu: &mut SparseLu,
        beta: f64,
    ) -> Result<Self, String> {
        let mut work = BorderedWork::new(sys.topo.dofs.n_eq);
        let (sums, [_, de, dc]) = energy_equation_nodal(sys, &mut work);
        let nodal = de.iter().zip(&dc).map(|(a, b)| a + beta * b).collect();
        let mut y2 = work.b.clone();
        lu.solve(&mut y2)?;
        let c: Vec<f64> = (work.ge.iter().zip(&work.gc))
            .map(|(a, g)| a + beta * g)
            .collect();
        let cy2: f64 = c.iter().zip(&y2).map(|(a, b)| a * b).sum();
        let pivot = sums.c_tot - cy2;
        let size = sums.c_tot.abs()
            + c.iter().map(|v| v * v).sum::<f64>().sqrt()
                * y2.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(pivot.is_finite() && pivot != 0.0) || size == 0.0 {
            return Err("the energy equation's border has no pivot".into());
        }
        Ok(Self {
            y2,
            c,
            pivot,
            nodal,
        })
    }

    /// `∂e/∂x · δ` for nodes moved by `moved` (node, `δ`).
    pub(super) fn along(&self, moved: &[(usize, nalgebra::Vector3<f64>)]) -> f64 {
        (moved.iter())
            .map(|(n, d)| (0..3).map(|c| self.nodal[6 * n + c] * d[c]).sum::<f64>())
            .sum()
    }

    /// `dq = y₁ − y₂ dβ` from `y₁ = −K⁻¹ r_p` and the energy equation's
    /// `e_p`, with `dβ = (−e_p − c·y₁)/(d − c·y₂)` (the bordered system's
    /// last row); returns `dβ`.
    pub(super) fn correct(&self, y1: &mut [f64], e_p: f64) -> f64 {
        let cy1: f64 = self.c.iter().zip(y1.iter()).map(|(a, b)| a * b).sum();
        let dbeta = (-e_p - cy1) / self.pivot;
        for (y, z) in y1.iter_mut().zip(&self.y2) {
            *y -= z * dbeta;
        }
        dbeta
    }
}
