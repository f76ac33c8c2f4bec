//! Exact parameter sensitivities of the Newmark family (the trapezoidal
//! rule and generalized-α on SO(3)) by direct differentiation of the
//! discrete equations.
//!
//! A step solves `g(q₁; hₙ, p) = 0` (reduced through `N` at `q₁`), where
//! `hₙ` is every node's history — position `xₙ`, rotation `Rₙ`, velocity
//! `vₙ`, pseudo-acceleration `aₙ`, acceleration `q̈ₙ` and their angular
//! counterparts `Wₙ`, `αₙ`, `Ȧₙ` — and then updates the history from
//! `(q₁, hₙ)`. Differentiating both with respect to a parameter `p`:
//!
//! ```text
//! K · dq₁/dp = −Nᵀ (∂g/∂p + ∂g/∂hₙ · dhₙ/dp),     dhₙ₊₁/dp = ∂U/∂q₁ · dq₁/dp + ∂U/∂hₙ · dhₙ/dp,
//! ```
//!
//! with `K` the exact tangent at the converged state (evaluated and
//! factorised once more per step: derivatives from a stale or cheaper
//! tangent are not derivatives), `∂g/∂p` exact as in statics
//! ([`crate::sensitivity`]), and the history terms exact by one dual number
//! per node: the inertial force `M q̈₁` is linear in the translational
//! history, and the inertial moment `R₁(J₀Ȧ₁ + W₁ × J₀W₁)` and the angular
//! update are evaluated with `Rₙ ← exp(ε θ̂ₙ) Rₙ` (`θₙ` the spatial rotation
//! derivative), `Wₙ + ε dWₙ`, … in `Dual64`. At t = 0 the accelerations
//! come from the equations of motion; their derivative is the same solve
//! with `∂g/∂p` as its residual. Step sizes are held: where a step was
//! halved the derivatives are those of the path with the halved steps.

use nalgebra::{Matrix3, Vector3};
use num_dual::Dual64;

use super::joint_start::JointStart;
use super::newmark_terms::{initial_accelerations, Coefficients, NewmarkTerms};
use super::slave_velocities;
use crate::error::SolveError;
use crate::joint_parameter::JointShift;
use crate::linsolve::SparseLu;
use crate::record::Sensitivity;
use crate::sensitivity::{mass_derivative, Parameter};
use crate::start_shift::StartShift;
use crate::system::ReducedSystem;
use flexmech_core::rotation::{log, skew};
use flexmech_core::{Configuration, Inertia, MassKind};

/// The derivatives of every node's Newmark history by one parameter.
#[derive(Debug, Clone)]
struct History {
    x: Vec<Vector3<f64>>,
    /// Spatial: `dR/dp = θ̂ R`.
    theta: Vec<Vector3<f64>>,
    v: Vec<Vector3<f64>>,
    a: Vec<Vector3<f64>>,
    acc: Vec<Vector3<f64>>,
    w: Vec<Vector3<f64>>,
    alpha: Vec<Vector3<f64>>,
    ang_acc: Vec<Vector3<f64>>,
}

impl History {
    fn at_rest(nodes: usize) -> Self {
        let z = vec![Vector3::zeros(); nodes];
        Self {
            x: z.clone(),
            theta: z.clone(),
            v: z.clone(),
            a: z.clone(),
            acc: z.clone(),
            w: z.clone(),
            alpha: z.clone(),
            ang_acc: z,
        }
    }
}

/// `v + ε dv`.
pub(super) fn dual(v: &Vector3<f64>, dv: &Vector3<f64>) -> Vector3<Dual64> {
    Vector3::from_fn(|i, _| Dual64::new(v[i], dv[i]))
}

/// `exp(ε θ̂) R = R + ε θ̂ R` (exact in first order).
pub(super) fn dual_rotation(r: &Matrix3<f64>, theta: &Vector3<f64>) -> Matrix3<Dual64> {
    let d = skew(theta) * r;
    Matrix3::from_fn(|i, j| Dual64::new(r[(i, j)], d[(i, j)]))
}

fn eps(v: &Vector3<Dual64>) -> Vector3<f64> {
    v.map(|x| x.eps)
}

/// The angular update of one node: from `Rₙ, Wₙ, αₙ, Ȧₙ` and the end
/// rotation `R₁`, the pseudo-acceleration `α₁`, the velocity `W₁` and the
/// acceleration `Ȧ₁` (generic: evaluated in duals).
fn angular_update<T: flexmech_core::Scalar>(
    k: &Coefficients,
    r_n: &Matrix3<T>,
    r1: &Matrix3<T>,
    (w_n, alpha_n, ang_acc_n): (Vector3<T>, Vector3<T>, Vector3<T>),
    dt: f64,
) -> [Vector3<T>; 3] {
    let c = |x: f64| T::from_subset(&x);
    let omega = log(&(r1 * r_n.transpose()));
    let alpha1 = (r_n.transpose() * omega - w_n * c(dt) - alpha_n * c(dt * dt * (0.5 - k.beta)))
        / c(k.beta * dt * dt);
    let w1 = w_n + (alpha_n * c(1.0 - k.gamma) + alpha1 * c(k.gamma)) * c(dt);
    let ang_acc1 = (alpha1 * c(1.0 - k.alpha_m) + alpha_n * c(k.alpha_m)
        - ang_acc_n * c(k.alpha_f))
        / c(1.0 - k.alpha_f);
    [alpha1, w1, ang_acc1]
}

/// The sensitivities of a Newmark-family run: its parameters, the
/// derivatives of the history by each, and the factorisation of the exact
/// tangent at each converged step.
pub(crate) struct NewmarkSensitivities {
    params: Vec<Parameter>,
    /// Per parameter, `∂M/∂p` and `∂J/∂p` of a mass parameter.
    units: Vec<Option<Inertia>>,
    /// Per parameter, its re-placement of a carried body at t = 0.
    starts: Vec<StartShift>,
    /// The sensitivities of the state at t = 0.
    pub(crate) initial: Vec<Sensitivity>,
    lu: SparseLu,
    history: Vec<History>,
    nodal: Vec<f64>,
    r: Vec<f64>,
}

impl NewmarkSensitivities {
    /// At t = 0 (`sys` as set up, before any step): positions and rotations
    /// do not depend on the parameters; velocities by an initial velocity's
    /// value (the slaves' through `N`), the accelerations through the
    /// equations of motion.
    pub(crate) fn new(
        sys: &mut ReducedSystem<'_, NewmarkTerms>,
        params: &[Parameter],
        kind: MassKind,
    ) -> Result<Self, SolveError> {
        let mech = sys.mech;
        for p in params {
            p.check(mech)?;
        }
        if !sys.terms.damped.is_empty() {
            return Err(SolveError::InvalidMechanism(
                "sensitivities of a run with structural damping are not available yet".into(),
            ));
        }
        let nodes = mech.mesh.node_count();
        let mut lu = SparseLu::new(sys.asm.pattern().clone()).map_err(SolveError::Singular)?;
        let mut nodal = vec![0.0; 6 * nodes];
        let mut history = Vec::with_capacity(params.len());
        let mut starts = Vec::with_capacity(params.len());
        let units: Vec<Option<Inertia>> = (params.iter())
            .map(|p| mass_derivative(mech, p, kind))
            .collect();
        for (p, unit) in params.iter().zip(&units) {
            let mut h = History::at_rest(nodes);
            match p {
                Parameter::Geometry { stretch, loads, .. } => {
                    let config = &sys.end.config;
                    crate::geometry::initial_forces(mech, config, (stretch, loads), &mut nodal)
                }
                _ => {
                    p.nodal_derivative(mech, &sys.end.config, 0.0, &mut nodal);
                }
            }
            if let Some(unit) = unit {
                // M a₀ + g = 0: ∂M a₀ + M ∂a₀ + ∂g = 0 (rotations at t = 0: I).
                let prev = &sys.terms.prev;
                for (i, f) in unit.apply_mass(&prev.acc).iter().enumerate() {
                    let m = unit.rotational[i] * prev.ang_acc[i];
                    for c in 0..3 {
                        nodal[6 * i + c] += f[c];
                        nodal[6 * i + 3 + c] += m[c];
                    }
                }
            }
            let joint = match p {
                Parameter::Joint { joint, name } => {
                    Some(JointStart::new(sys, &mut lu, *joint, name)?)
                }
                _ => None,
            };
            let extra = joint.as_ref().and_then(|j| j.add_forces(sys, &mut nodal));
            let (a, alpha, _) = initial_accelerations(
                mech,
                &sys.topo,
                &sys.terms.inertia,
                &mut sys.asm,
                &mut lu,
                &sys.end,
                &nodal,
                extra,
            );
            (h.a, h.acc, h.alpha, h.ang_acc) = (a.clone(), a, alpha.clone(), alpha);
            if let Parameter::InitialMotion { motion } = p {
                (h.v, h.w) = slave_velocities(mech, &sys.topo, &sys.end, motion);
            }
            let start = p.start_shift(sys)?;
            for (n, x) in h.x.iter_mut().enumerate() {
                *x = start.of(n);
            }
            if let Some(joint) = &joint {
                joint_history(sys, joint, &start, &mut h)?;
            }
            history.push(h);
            starts.push(start);
        }
        let (v0, w0) = (&sys.terms.prev.v, &sys.terms.prev.w);
        let initial = (history.iter().zip(&units))
            .map(|(h, unit)| Sensitivity {
                displacement: vec![[0.0; 3]; nodes],
                energy: kinetic_derivative(&sys.terms.inertia, (v0, w0), (&h.v, &h.w))
                    + unit.as_ref().map_or(0.0, |u| u.kinetic_energy(v0, w0)),
            })
            .collect();
        let n_eq = sys.topo.dofs.n_eq;
        Ok(Self {
            params: params.to_vec(),
            units,
            starts,
            initial,
            lu,
            history,
            nodal,
            r: vec![0.0; n_eq],
        })
    }

    /// The sensitivities of the step `sys.start → sys.end` just converged
    /// (before the scheme's update: `sys.terms` still holds the start's
    /// kinematics), `fext_end` the external forces at its end; advances the
    /// history derivatives.
    pub(crate) fn step(
        &mut self,
        sys: &mut ReducedSystem<'_, NewmarkTerms>,
        fext_end: &[f64],
    ) -> Result<Vec<Sensitivity>, SolveError> {
        let t = sys.load_time;
        let failed = |why| SolveError::InvalidMechanism(format!("sensitivities at t = {t}: {why}"));
        sys.evaluate_with(&mut self.r, true);
        self.lu.factor(&sys.asm.values).map_err(failed)?;
        let mut out = Vec::with_capacity(self.params.len());
        for k in 0..self.params.len() {
            let partial =
                self.params[k].nodal_derivative(sys.mech, &sys.end.config, t, &mut self.nodal);
            history_forces(
                &sys.terms,
                &sys.start.config,
                &sys.end.config,
                &self.history[k],
                &mut self.nodal,
            );
            if let Some(unit) = &self.units[k] {
                unit_inertial_forces(sys, unit, &mut self.nodal);
            }
            // Moved nodes at fixed unknowns: q̈₁ changes by c δ.
            let kc = &sys.terms.coefficients;
            let c = (1.0 - kc.alpha_m) / ((1.0 - kc.alpha_f) * kc.beta * sys.terms.dt.powi(2));
            let inertia = Some((&sys.terms.inertia, c));
            let shift = self.params[k].shift(sys)?;
            let psi = shift.as_ref().and_then(|s| {
                s.add_stiffness(sys.mech, &sys.end.config, inertia, &mut self.nodal);
                s.add_transfer(&sys.nodal, &mut self.nodal)
            });
            let held = self.params[k].held_shift(sys.mech);
            held.add_stiffness(sys.mech, &sys.end.config, inertia, &mut self.nodal);
            let mut dq = vec![0.0; sys.topo.dofs.n_eq];
            sys.reduce(&self.nodal, &mut dq);
            if let Some((eq, share)) = psi {
                dq[eq] += share;
            }
            dq.iter_mut().for_each(|v| *v = -*v);
            self.lu.solve(&mut dq).map_err(failed)?;
            let moved = (shift.as_ref(), &held);
            let (next, v1, w1) = advance(sys, &self.history[k], &dq, moved);
            let mass = self.units[k]
                .as_ref()
                .map_or(0.0, |u| u.kinetic_energy(&v1, &w1));
            let start = &self.starts[k];
            let partial = partial + mass + start.work(fext_end);
            let energy = energy_derivative(sys, &next, (&v1, &w1), fext_end, partial);
            out.push(Sensitivity {
                displacement: start.displacements(&next.x),
                energy,
            });
            self.history[k] = next;
        }
        Ok(out)
    }
}

/// A joint parameter's history at t = 0 beyond its initial accelerations and
/// the carried body's positions `dX/dp` ([`StartShift`]): the subtree's
/// velocity terms ([`JointStart`]). A carried body given an initial spin is
/// refused: its velocity field `v₀ + ω × (x − origin)` depends on where the
/// body is, which the re-placement does not say.
fn joint_history(
    sys: &ReducedSystem<'_, NewmarkTerms>,
    joint: &JointStart,
    start: &StartShift,
    h: &mut History,
) -> Result<(), SolveError> {
    let spinning = (start.nodes())
        .find(|n| !joint.nodes().contains(n) && sys.terms.prev.w[*n] != Vector3::zeros());
    if let Some(n) = spinning {
        return Err(SolveError::InvalidMechanism(format!(
            "the body a joint parameter re-places at t = 0 (with node {n}) starts with an \
             angular velocity, whose velocity field depends on the body's position: \
             differentiate by this parameter from a start without spin"
        )));
    }
    let mut a = h.a.clone();
    joint.add_motion(&mut h.v, &mut a);
    (h.a, h.acc) = (a.clone(), a);
    Ok(())
}

/// `∂g/∂hₙ · dhₙ/dp` at fixed end configuration, added to `g`: the
/// inertial forces' dependence on the history.
fn history_forces(
    terms: &NewmarkTerms,
    start: &Configuration,
    end: &Configuration,
    h: &History,
    g: &mut [f64],
) {
    let (k, dt, prev) = (&terms.coefficients, terms.dt, &terms.prev);
    let c = k.beta * dt * dt;
    // Translational: q̈₁ is linear in the history; ∂u = −dxₙ.
    let dacc: Vec<Vector3<f64>> = (0..h.x.len())
        .map(|j| {
            let da1 = (-h.x[j] - h.v[j] * dt - h.a[j] * (dt * dt * (0.5 - k.beta))) / c;
            (da1 * (1.0 - k.alpha_m) + h.a[j] * k.alpha_m - h.acc[j] * k.alpha_f)
                / (1.0 - k.alpha_f)
        })
        .collect();
    for (i, f) in terms.inertia.apply_mass(&dacc).iter().enumerate() {
        for comp in 0..3 {
            g[6 * i + comp] += f[comp];
        }
    }
    for (i, j0) in terms.inertia.rotational.iter().enumerate() {
        if *j0 == Matrix3::zeros() {
            continue;
        }
        let r_n = dual_rotation(&start.rot[i], &h.theta[i]);
        let r1 = end.rot[i].map(Dual64::from);
        let hist = (
            dual(&prev.w[i], &h.w[i]),
            dual(&prev.alpha[i], &h.alpha[i]),
            dual(&prev.ang_acc[i], &h.ang_acc[i]),
        );
        let [_, w1, ang_acc1] = angular_update(k, &r_n, &r1, hist, dt);
        let jd = j0.map(Dual64::from);
        let m = r1 * (jd * ang_acc1 + w1.cross(&(jd * w1)));
        for comp in 0..3 {
            g[6 * i + 3 + comp] += m[comp].eps;
        }
    }
}

/// `∂g/∂p` of a mass parameter at the converged step, added to `g`: the
/// inertial forces `∂M q̈₁` and `R₁(∂J Ȧ₁ + W₁ × ∂J W₁)` of its unit inertia
/// `unit`, with the step's accelerations and velocities.
fn unit_inertial_forces(sys: &ReducedSystem<'_, NewmarkTerms>, unit: &Inertia, g: &mut [f64]) {
    let terms = &sys.terms;
    let (k, dt, prev) = (&terms.coefficients, terms.dt, &terms.prev);
    let (start, end) = (&sys.start.config, &sys.end.config);
    let c = k.beta * dt * dt;
    let acc1: Vec<Vector3<f64>> = (0..end.x.len())
        .map(|j| {
            let u = end.x[j] - start.x[j];
            let a1 = (u - prev.v[j] * dt - prev.a[j] * (dt * dt * (0.5 - k.beta))) / c;
            (a1 * (1.0 - k.alpha_m) + prev.a[j] * k.alpha_m - prev.acc[j] * k.alpha_f)
                / (1.0 - k.alpha_f)
        })
        .collect();
    for (i, f) in unit.apply_mass(&acc1).iter().enumerate() {
        for comp in 0..3 {
            g[6 * i + comp] += f[comp];
        }
    }
    for (i, j0) in unit.rotational.iter().enumerate() {
        if *j0 == Matrix3::zeros() {
            continue;
        }
        let hist = (prev.w[i], prev.alpha[i], prev.ang_acc[i]);
        let [_, w1, ang_acc1] = angular_update(k, &start.rot[i], &end.rot[i], hist, dt);
        let m = end.rot[i] * (j0 * ang_acc1 + w1.cross(&(j0 * w1)));
        for comp in 0..3 {
            g[6 * i + 3 + comp] += m[comp];
        }
    }
}

/// The history derivatives at the step's end for the reduced `dq = dq₁/dp`,
/// with the end velocities `v₁`, `W₁` (real parts, for the energy).
fn advance(
    sys: &ReducedSystem<'_, NewmarkTerms>,
    h: &History,
    dq: &[f64],
    (shift, held): (Option<&JointShift>, &StartShift),
) -> (History, Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let terms = &sys.terms;
    let (k, dt, prev) = (&terms.coefficients, terms.dt, &terms.prev);
    let (start, end) = (&sys.start.config, &sys.end.config);
    let nodes = h.x.len();
    let mut next = History::at_rest(nodes);
    let (mut v1, mut w1s) = (Vec::with_capacity(nodes), Vec::with_capacity(nodes));
    for i in 0..nodes {
        let d = sys.topo.dofs.node_increment(i, dq);
        let direct = shift.map_or(Vector3::zeros(), |s| s.of(i)) + held.of(i);
        let (dx1, dth1) = (
            d.fixed_rows::<3>(0).into_owned() + direct,
            d.fixed_rows::<3>(3).into_owned(),
        );
        // Translational: the update is linear.
        let u = end.x[i] - start.x[i];
        let c = k.beta * dt * dt;
        let a1 = (u - prev.v[i] * dt - prev.a[i] * (dt * dt * (0.5 - k.beta))) / c;
        let da1 = (dx1 - h.x[i] - h.v[i] * dt - h.a[i] * (dt * dt * (0.5 - k.beta))) / c;
        v1.push(prev.v[i] + (prev.a[i] * (1.0 - k.gamma) + a1 * k.gamma) * dt);
        next.v[i] = h.v[i] + (h.a[i] * (1.0 - k.gamma) + da1 * k.gamma) * dt;
        next.acc[i] = (da1 * (1.0 - k.alpha_m) + h.a[i] * k.alpha_m - h.acc[i] * k.alpha_f)
            / (1.0 - k.alpha_f);
        next.a[i] = da1;
        next.x[i] = dx1;
        next.theta[i] = dth1;
        // Angular: in duals, both ends and the history perturbed.
        let r_n = dual_rotation(&start.rot[i], &h.theta[i]);
        let r1 = dual_rotation(&end.rot[i], &dth1);
        let hist = (
            dual(&prev.w[i], &h.w[i]),
            dual(&prev.alpha[i], &h.alpha[i]),
            dual(&prev.ang_acc[i], &h.ang_acc[i]),
        );
        let [alpha1, w1, ang_acc1] = angular_update(k, &r_n, &r1, hist, dt);
        (next.alpha[i], next.w[i], next.ang_acc[i]) = (eps(&alpha1), eps(&w1), eps(&ang_acc1));
        w1s.push(w1.map(|x| x.re));
    }
    (next, v1, w1s)
}

/// `dK/dp = Σ (M v)·dv + Σ J₀W·dW` of the kinetic energy at velocities
/// `v`, `W` with derivatives `dv`, `dW` (at fixed mass).
pub(super) fn kinetic_derivative(
    inertia: &Inertia,
    (v, w): (&[Vector3<f64>], &[Vector3<f64>]),
    (dv, dw): (&[Vector3<f64>], &[Vector3<f64>]),
) -> f64 {
    let mv = inertia.apply_mass(v);
    (0..v.len())
        .map(|i| mv[i].dot(&dv[i]) + (inertia.rotational[i] * w[i]).dot(&dw[i]))
        .sum()
}

/// `dE/dp` of the record's total energy `K + U − Σ fₑₓₜ·u` at the step's
/// end: `Σ (M v₁)·dv₁ + Σ J₀W₁·dW₁ + Σ f_int·dx − Σ fₑₓₜ·du + ∂E/∂p`
/// (`sys.asm.nodal`: the internal forces at the end, from the last
/// evaluation).
fn energy_derivative(
    sys: &ReducedSystem<'_, NewmarkTerms>,
    h: &History,
    (v1, w1): (&[Vector3<f64>], &[Vector3<f64>]),
    fext: &[f64],
    partial: f64,
) -> f64 {
    let mut de = partial + kinetic_derivative(&sys.terms.inertia, (v1, w1), (&h.v, &h.w));
    for i in 0..v1.len() {
        for c in 0..3 {
            de +=
                sys.asm.nodal[6 * i + c] * h.x[i][c] + sys.asm.nodal[6 * i + 3 + c] * h.theta[i][c];
            de -= fext[6 * i + c] * h.x[i][c];
        }
    }
    if !sys.mech.follower_loads.is_empty() {
        de = f64::NAN;
    }
    de
}
