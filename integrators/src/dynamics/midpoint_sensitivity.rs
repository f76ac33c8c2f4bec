//! Exact parameter sensitivities of the midpoint schemes — the
//! momentum-conserving scheme and the energy–momentum discrete gradient —
//! by direct differentiation of the discrete equations.
//!
//! A step solves `g(q₁; hₙ, p) = 0`, `hₙ` every node's start state
//! `(xₙ, Rₙ, vₙ, Wₙ)`: the scheme's element force `q(start, end)`, the
//! inertial forces `M(vₙ₊₁ − vₙ)/Δt` with `vₙ₊₁ = 2(xₙ₊₁ − xₙ)/Δt − vₙ` and
//! `(πₙ₊₁ − πₙ)/Δt` with `Wₙ₊₁ = 2Rₙᵀ cay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ`, loads at
//! `tₙ₊½`. Differentiating,
//!
//! ```text
//! K · dq₁/dp = −(∂g/∂p + ∂g/∂hₙ · dhₙ/dp),    dvₙ₊₁ = 2(dxₙ₊₁ − dxₙ)/Δt − dvₙ,
//! ```
//!
//! `dWₙ₊₁` likewise, with `K` the exact tangent at the converged state (for
//! the energy–momentum scheme the exact derivative of the discrete
//! gradient, factorised once more even where Newton ended on the cheap
//! one). `∂g/∂hₙ · dhₙ/dp` is exact by one dual number: the element force
//! with the start pose `xₙ + ε dxₙ`, `Rₙ ← exp(ε θ̂ₙ)Rₙ`, the inertial moment
//! likewise. The forces are linear in each stiffness (the discrete gradient
//! of an energy linear in it is linear in it), so `∂q/∂C` is the scheme's
//! force of the unit-stiffness element. Joints enter through the reduction
//! `Σ Ñᵀ g`, whose incremental map `Ñ` depends on the step's start: its
//! derivative along the start (the masters' start poses and the released
//! start coordinates, with their derivatives) comes by dual numbers through
//! `Ñ` ([`crate::constraints::Topology::incremental_start_terms`]); the
//! slaves' end poses follow `dq` through `N`. A joint's own value enters as
//! in [`super::midpoint_joint`]. The paper's scheme (its bordered β) is not
//! differentiated yet.

use flexmech_core::conserving::{MidRotation, Pose, Pose3};
use flexmech_core::rotation::cayley_inverse;
use flexmech_core::{Configuration, Element, Inertia, MassKind, Scalar};
use flexmech_joints::MAX_RELEASED;
use nalgebra::{Matrix3, Vector3};
use num_dual::Dual64;

use super::midpoint::{end_motion, MidpointTerms};
use super::midpoint_joint;
use super::midpoint_kernels::{element_force, CorrectionTally};
use super::newmark_sensitivity::{dual, dual_rotation, kinetic_derivative};
use super::{slave_velocities, Scheme};
use crate::error::SolveError;
use crate::joint_parameter::{JointShift, StartShift};
use crate::linsolve::SparseLu;
use crate::record::Sensitivity;
use crate::sensitivity::{mass_derivative, with_unit_stiffness, Parameter};
use crate::system::ReducedSystem;

/// The derivatives of every node's start state by one parameter.
#[derive(Debug, Clone)]
pub(super) struct History {
    pub(super) x: Vec<Vector3<f64>>,
    /// Spatial: `dR/dp = θ̂ R`.
    theta: Vec<Vector3<f64>>,
    pub(super) v: Vec<Vector3<f64>>,
    w: Vec<Vector3<f64>>,
    /// Per joint, its released coordinates' (increments).
    released: Vec<[f64; MAX_RELEASED]>,
}

impl History {
    fn at_rest(nodes: usize, joints: usize) -> Self {
        let z = vec![Vector3::zeros(); nodes];
        Self {
            x: z.clone(),
            theta: z.clone(),
            v: z.clone(),
            w: z,
            released: vec![[0.0; MAX_RELEASED]; joints],
        }
    }
}

/// The sensitivities of a midpoint-scheme run.
pub(crate) struct MidpointSensitivities {
    params: Vec<Parameter>,
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

impl MidpointSensitivities {
    /// At t = 0: positions and rotations do not depend on the parameters;
    /// velocities by an initial velocity's value.
    pub(crate) fn new(
        sys: &mut ReducedSystem<'_, MidpointTerms>,
        params: &[Parameter],
        kind: MassKind,
    ) -> Result<Self, SolveError> {
        let mech = sys.mech;
        let refuse = |why: &str| Err(SolveError::InvalidMechanism(why.into()));
        if sys.terms.scheme == Scheme::EnergyMomentumPaper {
            return refuse(
                "sensitivities with the paper's energy-momentum scheme (its bordered β) are not \
                 available yet: use \"energy-momentum\" or \"momentum\"",
            );
        }
        let nodes = mech.mesh.node_count();
        let mut history = Vec::with_capacity(params.len());
        let mut units = Vec::with_capacity(params.len());
        let mut starts = Vec::with_capacity(params.len());
        for p in params {
            p.check(mech)?;
            let mut h = History::at_rest(nodes, mech.joints.len());
            if let Parameter::InitialMotion { motion } = p {
                (h.v, h.w) = slave_velocities(mech, &sys.topo, &sys.end, motion);
            }
            let start = p.start_shift(sys)?;
            if let Parameter::Joint { joint, name } = p {
                midpoint_joint::start_history(sys, (*joint, name), &start, &mut h)?;
            }
            history.push(h);
            starts.push(start);
            units.push(mass_derivative(mech, p, kind));
        }
        let (v0, w0) = (&sys.terms.v_n, &sys.terms.w_n);
        let initial = (history.iter().zip(&units))
            .map(|(h, unit)| Sensitivity {
                displacement: vec![[0.0; 3]; nodes],
                energy: kinetic_derivative(&sys.terms.inertia, (v0, w0), (&h.v, &h.w))
                    + unit.as_ref().map_or(0.0, |u| u.kinetic_energy(v0, w0)),
            })
            .collect();
        Ok(Self {
            params: params.to_vec(),
            units,
            starts,
            initial,
            lu: SparseLu::new(sys.asm.pattern().clone()).map_err(SolveError::Singular)?,
            history,
            nodal: vec![0.0; 6 * nodes],
            r: vec![0.0; sys.topo.dofs.n_eq],
        })
    }

    /// The sensitivities of the step `sys.start → sys.end` just converged
    /// (before the scheme's update), `fext_end` the external forces at its
    /// end; advances the history derivatives.
    pub(crate) fn step(
        &mut self,
        sys: &mut ReducedSystem<'_, MidpointTerms>,
        fext_end: &[f64],
    ) -> Result<Vec<Sensitivity>, SolveError> {
        let t = sys.load_time;
        let failed = |why| SolveError::InvalidMechanism(format!("sensitivities at t = {t}: {why}"));
        let cheap = !sys.terms.exact_tangent;
        sys.terms.exact_tangent = true;
        sys.evaluate_with(&mut self.r, true);
        sys.terms.exact_tangent = !cheap;
        self.lu.factor(&sys.asm.values).map_err(failed)?;
        let (mech, dt) = (sys.mech, sys.terms.dt);
        let (start, end) = (&sys.start.config, &sys.end.config);
        let f_int = end_internal_forces(mech, end);
        let (v1, w1) = end_motion(start, end, &sys.terms.v_n, &sys.terms.w_n, dt);
        let mut out = Vec::with_capacity(self.params.len());
        for k in 0..self.params.len() {
            let p = &self.params[k];
            let partial = p.nodal_derivative(mech, end, t + 0.5 * dt, &mut self.nodal);
            if let Parameter::Stiffness {
                elements,
                component,
            } = p
            {
                self.nodal.iter_mut().for_each(|v| *v = 0.0);
                unit_forces(sys, elements, *component, &mut self.nodal);
            } else {
                p.nodal_derivative(mech, end, t, &mut self.nodal);
            }
            history_forces(
                &sys.terms,
                start,
                end,
                &self.history[k],
                &mut self.nodal,
                mech,
            );
            let mut extra = joint_history(sys, &self.history[k], &mut self.nodal)?;
            let shift = match p {
                Parameter::Joint { joint, name } => {
                    let shift = midpoint_joint::shift(sys, *joint, name)?;
                    let at = (*joint, name.as_str());
                    extra.extend(midpoint_joint::forces(sys, at, &shift, &mut self.nodal)?);
                    Some(shift)
                }
                _ => None,
            };
            let mut mass = 0.0;
            if let Some(unit) = &self.units[k] {
                inertial_forces(
                    unit,
                    start,
                    end,
                    (&sys.terms.v_n, &sys.terms.w_n),
                    dt,
                    &mut self.nodal,
                );
                mass = unit.kinetic_energy(&v1, &w1);
            }
            let mut dq = vec![0.0; sys.topo.dofs.n_eq];
            sys.reduce(&self.nodal, &mut dq);
            for (eq, value) in extra {
                dq[eq] += value;
            }
            dq.iter_mut().for_each(|v| *v = -*v);
            self.lu.solve(&mut dq).map_err(failed)?;
            let next = advance(sys, &self.history[k], &dq, shift.as_ref());
            let mut energy = partial + mass;
            energy += kinetic_derivative(&sys.terms.inertia, (&v1, &w1), (&next.v, &next.w));
            for n in 0..v1.len() {
                for c in 0..3 {
                    energy +=
                        f_int[6 * n + c] * next.x[n][c] + f_int[6 * n + 3 + c] * next.theta[n][c];
                    energy -= fext_end[6 * n + c] * next.x[n][c];
                }
            }
            let start = &self.starts[k];
            energy += start.work(fext_end);
            let displacement = (next.x.iter().enumerate())
                .map(|(n, d)| {
                    let d = d - start.of(n);
                    [d.x, d.y, d.z]
                })
                .collect();
            out.push(Sensitivity {
                displacement,
                energy,
            });
            self.history[k] = next;
        }
        Ok(out)
    }
}

/// The beams' internal forces `∂U/∂(x, φ)` at `config` (6 per node).
fn end_internal_forces(mech: &crate::mechanism::Mechanism, config: &Configuration) -> Vec<f64> {
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
/// elements between the step's ends, added to `g`.
fn unit_forces(
    sys: &ReducedSystem<'_, MidpointTerms>,
    elements: &[usize],
    component: usize,
    g: &mut [f64],
) {
    let (start, end) = (&sys.start.config, &sys.end.config);
    let tally = CorrectionTally::default();
    let mut r = Vec::new();
    for &e in elements {
        let unit = with_unit_stiffness(&sys.mech.mesh.elements[e], component);
        r.resize(unit.dofs(), 0.0);
        element_force(&unit, start, end, sys.terms.scheme, 0.0, &tally, &mut r);
        for (k, &n) in unit.nodes().iter().enumerate() {
            for c in 0..6 {
                g[6 * n + c] += r[6 * k + c];
            }
        }
    }
}

/// The scheme's element force with the start pose seeded by `h` (the end
/// held): its derivative along the history.
fn element_history(
    el: &Element,
    scheme: Scheme,
    start: &Configuration,
    end: &Configuration,
    h: &History,
) -> Vec<f64> {
    type D = Dual64;
    let s = |i: usize| {
        (
            dual(&start.x[i], &h.x[i]),
            dual_rotation(&start.rot[i], &h.theta[i]),
        )
    };
    let e = |i: usize| (end.x[i].map(D::from), end.rot[i].map(D::from));
    let q = match el {
        Element::Linear(el) => {
            let n = el.nodes;
            let sd: Pose<D> = (n.map(|i| s(i).0), n.map(|i| s(i).1));
            let ed: Pose<D> = (n.map(|i| e(i).0), n.map(|i| e(i).1));
            if scheme == Scheme::Momentum {
                let (n0, m0) = el.resultants(&sd.0, &sd.1);
                let (n1, m1) = el.resultants(&ed.0, &ed.1);
                let half = D::from(0.5);
                let (nbar, mbar) = ((n0 + n1) * half, (m0 + m1) * half);
                el.midpoint_force(&sd, &ed, &nbar, &mbar, MidRotation::Geodesic)
                    .as_slice()
                    .to_vec()
            } else {
                el.energy_momentum_force(&sd, &ed).as_slice().to_vec()
            }
        }
        Element::Quadratic(el) => {
            let n = el.nodes;
            let sd: Pose3<D> = (n.map(|i| s(i).0), n.map(|i| s(i).1));
            let ed: Pose3<D> = (n.map(|i| e(i).0), n.map(|i| e(i).1));
            el.discrete_gradient_force(&sd, &ed).as_slice().to_vec()
        }
    };
    q.iter().map(|v| v.eps).collect()
}

/// `Wₙ₊₁ = 2Rₙᵀ cay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ` (generic, for dual numbers).
fn end_spin<T: Scalar>(r_n: &Matrix3<T>, r1: &Matrix3<T>, w_n: &Vector3<T>, dt: f64) -> Vector3<T> {
    let theta = cayley_inverse(&(r1 * r_n.transpose()));
    r_n.transpose() * theta * T::from_subset(&(2.0 / dt)) - w_n
}

/// `∂g/∂hₙ · dhₙ/dp` at fixed end configuration, added to `g`: the
/// elements' and the inertial forces' dependence on the start state.
fn history_forces(
    terms: &MidpointTerms,
    start: &Configuration,
    end: &Configuration,
    h: &History,
    g: &mut [f64],
    mech: &crate::mechanism::Mechanism,
) {
    for el in &mech.mesh.elements {
        let q = element_history(el, terms.scheme, start, end, h);
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
}

/// `∂g/∂p` of a mass parameter's unit inertia `unit`: its inertial forces
/// over the step, added to `g`.
fn inertial_forces(
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

/// `∂(Σ Ñᵀ g)/∂hₙ · dhₙ/dp` of the joints' incremental maps (the step's
/// end held, `g` the converged nodal residual): master parts into the nodal
/// `g_out`, the released equations' shares returned.
fn joint_history(
    sys: &ReducedSystem<'_, MidpointTerms>,
    h: &History,
    g_out: &mut [f64],
) -> Result<Vec<(usize, f64)>, SolveError> {
    if sys.mech.joints.is_empty() {
        return Ok(Vec::new());
    }
    let ends = (&sys.start, &sys.end);
    let (nodal, history) = (&sys.nodal, (h.x.as_slice(), h.theta.as_slice()));
    (sys.topo)
        .incremental_start_terms(sys.mech, ends, nodal, history, &h.released, g_out)
        .map_err(|j| {
            SolveError::InvalidMechanism(format!(
                "joint `{}`: its kind's released coordinates give no derivative of the \
                 incremental map along the step's start, which sensitivities with the momentum \
                 and energy-momentum schemes need: use \"newmark\" or \"generalized-alpha\"",
                sys.mech.joints[j].name
            ))
        })
}

/// The history derivatives at the step's end for the solved `dq = dq₁/dp`.
fn advance(
    sys: &ReducedSystem<'_, MidpointTerms>,
    h: &History,
    dq: &[f64],
    shift: Option<&JointShift>,
) -> History {
    let (start, end, dt) = (&sys.start.config, &sys.end.config, sys.terms.dt);
    let mut next = History::at_rest(h.x.len(), h.released.len());
    for (j, eqs) in sys.topo.released_eqs.iter().enumerate() {
        for (c, eq) in eqs.iter().enumerate() {
            // A driven coordinate does not depend on the parameters.
            next.released[j][c] = eq.map_or(0.0, |e| dq[e]);
        }
    }
    for i in 0..h.x.len() {
        let d = sys.topo.dofs.node_increment(i, dq);
        next.x[i] = d.fixed_rows::<3>(0) + shift.map_or(Vector3::zeros(), |s| s.of(i));
        next.theta[i] = d.fixed_rows::<3>(3).into_owned();
        next.v[i] = (next.x[i] - h.x[i]) * (2.0 / dt) - h.v[i];
        let r_n = dual_rotation(&start.rot[i], &h.theta[i]);
        let r1 = dual_rotation(&end.rot[i], &next.theta[i]);
        let w1 = end_spin(&r_n, &r1, &dual(&sys.terms.w_n[i], &h.w[i]), dt);
        next.w[i] = w1.map(|x| x.eps);
    }
    next
}
