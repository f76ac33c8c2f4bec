//! The midpoint schemes' residual derivatives for exact sensitivities
//! ([`super::midpoint_sensitivity`]): by a stiffness (the scheme's force of
//! the unit-stiffness element), along the step's start state (the force
//! with the start pose in dual numbers, the midpoint inertia), by a mass
//! (its unit inertia's forces), and for the paper's scheme the energy
//! equation's (eq. 18) along the same directions.

use flexmech_core::conserving::{MidRotation, Pose, Pose3};
use flexmech_core::rotation::cayley_inverse;
use flexmech_core::{cst, BeamElement, Configuration, Element, Inertia, Scalar};
use nalgebra::{Matrix3, SVector, Vector3};
use num_dual::Dual64;

use super::midpoint::MidpointTerms;
use super::midpoint_kernels::{element_force, CorrectionTally};
use super::midpoint_sensitivity::History;
use super::newmark_sensitivity::{dual, dual_rotation};
use super::Scheme;
use crate::mechanism::Mechanism;
use crate::sensitivity::with_unit_stiffness;
use crate::system::ReducedSystem;

/// The paper's scheme's element force `q_k(N̄, M̄) + β q_k(N_d, 0)` (algebraic
/// mid rotation) and its energy residual `Σᵢ pᵢ·q − (Πₙ₊₁ − Πₙ)` (eq. 18),
/// for any scalar.
fn paper_force_energy<T: Scalar>(
    e: &BeamElement<2>,
    sd: &Pose<T>,
    ed: &Pose<T>,
    beta: f64,
) -> (SVector<T, 12>, T) {
    let (n0, m0) = e.resultants(&sd.0, &sd.1);
    let (n1, m1) = e.resultants(&ed.0, &ed.1);
    let half = cst::<T>(0.5);
    let (nbar, mbar) = ((n0 + n1) * half, (m0 + m1) * half);
    let qk = e.midpoint_force(sd, ed, &nbar, &mbar, MidRotation::Algebraic);
    let nd = (nbar - n0) * cst::<T>(2.0);
    let qd = e.midpoint_force(sd, ed, &nd, &Vector3::zeros(), MidRotation::Algebraic);
    let q = qk + qd * cst::<T>(beta);
    let mut work = T::zero();
    for i in 0..2 {
        let u = ed.0[i] - sd.0[i];
        let th = cayley_inverse(&(ed.1[i] * sd.1[i].transpose()));
        work += u.dot(&q.fixed_rows::<3>(6 * i)) + th.dot(&q.fixed_rows::<3>(6 * i + 3));
    }
    (q, work - (e.energy(&ed.0, &ed.1) - e.energy(&sd.0, &sd.1)))
}

/// The beams' internal forces `∂U/∂(x, φ)` at `config` (6 per node).
pub(super) fn end_internal_forces(mech: &Mechanism, config: &Configuration) -> Vec<f64> {
    let mut f = vec![0.0; 6 * mech.mesh.node_count()];
    let mut r = Vec::new();
    for e in &mech.mesh.elements {
        r.resize(e.dofs(), 0.0);
        e.internal_force_into(&config.x, &config.rot, &mut r);
        for (k, &n) in e.nodes().iter().enumerate() {
            for c in 0..6 {
                f[6 * n + c] += r[6 * k + c];
            }
        }
    }
    f
}

/// `∂q/∂C` of a stiffness: the scheme's force of the unit-stiffness
/// elements between the step's ends, added to `g`; returns the paper's
/// energy residual's `∂e/∂C` (zero for the other schemes). Both are linear
/// in each stiffness.
pub(super) fn unit_forces(
    sys: &ReducedSystem<'_, MidpointTerms>,
    elements: &[usize],
    component: usize,
    g: &mut [f64],
) -> f64 {
    let (start, end) = (&sys.start.config, &sys.end.config);
    let (scheme, beta) = (sys.terms.scheme, sys.terms.beta);
    let tally = CorrectionTally::default();
    let mut r = Vec::new();
    let mut energy = 0.0;
    for &e in elements {
        let unit = with_unit_stiffness(&sys.mech.mesh.elements[e], component);
        r.resize(unit.dofs(), 0.0);
        element_force(&unit, start, end, scheme, beta, &tally, &mut r);
        for (k, &n) in unit.nodes().iter().enumerate() {
            for c in 0..6 {
                g[6 * n + c] += r[6 * k + c];
            }
        }
        if let (Scheme::EnergyMomentumPaper, Element::Linear(u)) = (scheme, &unit) {
            let n = u.nodes;
            let pose = |c: &Configuration| (n.map(|i| c.x[i]), n.map(|i| c.rot[i]));
            energy += paper_force_energy(u, &pose(start), &pose(end), beta).1;
        }
    }
    energy
}

/// The scheme's element force with the start pose seeded by `h` (the end
/// held): its derivative along the history; with the paper's energy
/// residual's (zero for the other schemes).
fn element_history(
    el: &Element,
    scheme: (Scheme, f64),
    start: &Configuration,
    end: &Configuration,
    h: &History,
) -> (Vec<f64>, f64) {
    let zero = |_: usize| (Vector3::zeros(), Vector3::zeros());
    let from = |i: usize| (h.x[i], h.theta[i]);
    element_seeded(el, scheme, (start, end), (&from, &zero))
}

/// Node `i`'s seed: a translation and a spatial spin.
pub(super) type Seed<'a> = &'a dyn Fn(usize) -> (Vector3<f64>, Vector3<f64>);

/// The scheme's element force and the paper's energy residual (zero for the
/// other schemes) with both ends seeded in one dual number
/// (`x ← x + ε dx`, `R ← exp(ε θ̂)R`): their derivative along the seeds.
pub(super) fn element_seeded(
    el: &Element,
    (scheme, beta): (Scheme, f64),
    (start, end): (&Configuration, &Configuration),
    (from, to): (Seed<'_>, Seed<'_>),
) -> (Vec<f64>, f64) {
    type D = Dual64;
    let s = |i: usize| {
        let (dx, th) = from(i);
        (dual(&start.x[i], &dx), dual_rotation(&start.rot[i], &th))
    };
    let e = |i: usize| {
        let (dx, th) = to(i);
        (dual(&end.x[i], &dx), dual_rotation(&end.rot[i], &th))
    };
    let (q, energy) = match el {
        Element::Linear(el) => {
            let n = el.nodes;
            let sd: Pose<D> = (n.map(|i| s(i).0), n.map(|i| s(i).1));
            let ed: Pose<D> = (n.map(|i| e(i).0), n.map(|i| e(i).1));
            match scheme {
                Scheme::Momentum => {
                    let (n0, m0) = el.resultants(&sd.0, &sd.1);
                    let (n1, m1) = el.resultants(&ed.0, &ed.1);
                    let half = D::from(0.5);
                    let (nbar, mbar) = ((n0 + n1) * half, (m0 + m1) * half);
                    let q = el.midpoint_force(&sd, &ed, &nbar, &mbar, MidRotation::Geodesic);
                    (q.as_slice().to_vec(), 0.0)
                }
                Scheme::EnergyMomentum => {
                    (el.energy_momentum_force(&sd, &ed).as_slice().to_vec(), 0.0)
                }
                Scheme::EnergyMomentumPaper => {
                    let (q, energy) = paper_force_energy(el, &sd, &ed, beta);
                    (q.as_slice().to_vec(), energy.eps)
                }
            }
        }
        Element::Quadratic(el) => {
            let n = el.nodes;
            let sd: Pose3<D> = (n.map(|i| s(i).0), n.map(|i| s(i).1));
            let ed: Pose3<D> = (n.map(|i| e(i).0), n.map(|i| e(i).1));
            let q = el.discrete_gradient_force(&sd, &ed);
            (q.as_slice().to_vec(), 0.0)
        }
    };
    (q.iter().map(|v| v.eps).collect(), energy)
}

/// The scheme's element force and the paper's energy residual between the
/// step's ends (plain numbers).
pub(super) fn element_value(
    el: &Element,
    (scheme, beta): (Scheme, f64),
    (start, end): (&Configuration, &Configuration),
) -> (Vec<f64>, f64) {
    let mut r = vec![0.0; el.dofs()];
    element_force(
        el,
        start,
        end,
        scheme,
        beta,
        &CorrectionTally::default(),
        &mut r,
    );
    let energy = match (scheme, el) {
        (Scheme::EnergyMomentumPaper, Element::Linear(u)) => {
            let n = u.nodes;
            let pose = |c: &Configuration| (n.map(|i| c.x[i]), n.map(|i| c.rot[i]));
            paper_force_energy(u, &pose(start), &pose(end), beta).1
        }
        _ => 0.0,
    };
    (r, energy)
}

/// `Wₙ₊₁ = 2Rₙᵀ cay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ` (generic, for dual numbers).
pub(super) fn end_spin<T: Scalar>(
    r_n: &Matrix3<T>,
    r1: &Matrix3<T>,
    w_n: &Vector3<T>,
    dt: f64,
) -> Vector3<T> {
    let theta = cayley_inverse(&(r1 * r_n.transpose()));
    r_n.transpose() * theta * T::from_subset(&(2.0 / dt)) - w_n
}

/// `∂g/∂hₙ · dhₙ/dp` at fixed end configuration, added to `g`: the
/// elements' and the inertial forces' dependence on the start state;
/// returns the paper's energy residual's (zero for the other schemes).
pub(super) fn history_forces(
    terms: &MidpointTerms,
    start: &Configuration,
    end: &Configuration,
    h: &History,
    g: &mut [f64],
    mech: &Mechanism,
) -> f64 {
    let mut energy = 0.0;
    for el in &mech.mesh.elements {
        let (q, e) = element_history(el, (terms.scheme, terms.beta), start, end, h);
        energy += e;
        for (k, &n) in el.nodes().iter().enumerate() {
            for c in 0..6 {
                g[6 * n + c] += q[6 * k + c];
            }
        }
    }
    let dt = terms.dt;
    // M(vₙ₊₁ − vₙ)/Δt = M(2(xₙ₊₁ − xₙ)/Δt − 2vₙ)/Δt: linear in the history.
    let dv: Vec<Vector3<f64>> = (0..h.x.len())
        .map(|j| (h.x[j] * (-2.0 / dt) - h.v[j] * 2.0) / dt)
        .collect();
    for (i, f) in terms.inertia.apply_mass(&dv).iter().enumerate() {
        for c in 0..3 {
            g[6 * i + c] += f[c];
        }
    }
    for (i, j0) in terms.inertia.rotational.iter().enumerate() {
        if *j0 == Matrix3::zeros() {
            continue;
        }
        let r_n = dual_rotation(&start.rot[i], &h.theta[i]);
        let r1 = end.rot[i].map(Dual64::from);
        let w_n = dual(&terms.w_n[i], &h.w[i]);
        let jd = j0.map(Dual64::from);
        let m = (r1 * (jd * end_spin(&r_n, &r1, &w_n, dt)) - r_n * (jd * w_n)) / Dual64::from(dt);
        for c in 0..3 {
            g[6 * i + 3 + c] += m[c].eps;
        }
    }
    energy
}

/// `∂g/∂p` of a mass parameter's unit inertia `unit`: its inertial forces
/// over the step, added to `g`.
pub(super) fn inertial_forces(
    unit: &Inertia,
    start: &Configuration,
    end: &Configuration,
    (v_n, w_n): (&[Vector3<f64>], &[Vector3<f64>]),
    dt: f64,
    g: &mut [f64],
) {
    let dv: Vec<Vector3<f64>> = (0..v_n.len())
        .map(|j| ((end.x[j] - start.x[j]) * (2.0 / dt) - v_n[j] * 2.0) / dt)
        .collect();
    for (i, f) in unit.apply_mass(&dv).iter().enumerate() {
        for c in 0..3 {
            g[6 * i + c] += f[c];
        }
    }
    for (i, j0) in unit.rotational.iter().enumerate() {
        let w1 = end_spin(&start.rot[i], &end.rot[i], &w_n[i], dt);
        let m = (end.rot[i] * (j0 * w1) - start.rot[i] * (j0 * w_n[i])) / dt;
        for c in 0..3 {
            g[6 * i + 3 + c] += m[c];
        }
    }
}
