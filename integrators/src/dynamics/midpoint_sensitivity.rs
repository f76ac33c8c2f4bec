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

use flexmech_core::{Inertia, MassKind};
use flexmech_joints::MAX_RELEASED;
use nalgebra::Vector3;

use super::bordered::Border;
use super::midpoint::{end_motion, MidpointTerms};
use super::midpoint_history::{
    end_internal_forces, end_spin, history_forces, inertial_forces, unit_forces,
};
use super::newmark_sensitivity::{dual, dual_rotation, kinetic_derivative};
use super::{midpoint_geometry, midpoint_joint};
use super::{slave_velocities, Scheme};
use crate::error::SolveError;
use crate::joint_parameter::JointShift;
use crate::linsolve::SparseLu;
use crate::record::Sensitivity;
use crate::sensitivity::{mass_derivative, Parameter};
use crate::start_shift::StartShift;
use crate::system::ReducedSystem;

/// The derivatives of every node's start state by one parameter.
#[derive(Debug, Clone)]
pub(super) struct History {
    pub(super) x: Vec<Vector3<f64>>,
    /// Spatial: `dR/dp = θ̂ R`.
    pub(super) theta: Vec<Vector3<f64>>,
    pub(super) v: Vec<Vector3<f64>>,
    pub(super) w: Vec<Vector3<f64>>,
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
        let geometry = params
            .iter()
            .any(|p| matches!(p, Parameter::Geometry { .. }));
        if geometry && sys.terms.scheme == Scheme::EnergyMomentumPaper {
            return Err(SolveError::InvalidMechanism(
                "sensitivities by a beam's end coordinates with the paper's energy-momentum \
                 scheme are not available (they disagree with differences late in a run, for \
                 a reason not found yet): use \"energy-momentum\" or \"momentum\""
                    .into(),
            ));
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
            for (n, x) in h.x.iter_mut().enumerate() {
                *x = start.of(n);
            }
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
        let border = match sys.terms.scheme {
            Scheme::EnergyMomentumPaper if sys.terms.bordered => {
                Some(Border::at(sys, &mut self.lu, sys.terms.beta).map_err(failed)?)
            }
            _ => None,
        };
        let end_state = EndState::of(sys);
        let mut out = Vec::with_capacity(self.params.len());
        for k in 0..self.params.len() {
            let (mut dq, (shift, held), partial, e_p) = self.residual_derivative(sys, k)?;
            dq.iter_mut().for_each(|v| *v = -*v);
            self.lu.solve(&mut dq).map_err(failed)?;
            if let Some(border) = &border {
                // A joint's value moves the slave's end pose, a beam's end
                // its held translations: `∂e/∂x · δ`.
                let mut moved = shift.as_ref().map_or(Vec::new(), |s| {
                    s.nodes.iter().map(|&n| (n, s.delta)).collect()
                });
                moved.extend_from_slice(held.shifts());
                border.correct(&mut dq, e_p + border.along(&moved));
            }
            let next = advance(sys, &self.history[k], &dq, (shift.as_ref(), &held));
            out.push(end_state.sensitivity(sys, &next, &self.starts[k], fext_end, partial));
            self.history[k] = next;
        }
        Ok(out)
    }

    /// Parameter `k`'s reduced `∂r/∂p + ∂r/∂hₙ · dhₙ/dp` at the converged
    /// step, its joint shift, `∂E/∂p` of the total energy at the step's end
    /// (with a mass's kinetic share) and the paper's energy equation's
    /// `∂e/∂p + ∂e/∂hₙ · dhₙ/dp`.
    #[allow(clippy::type_complexity)]
    fn residual_derivative(
        &mut self,
        sys: &ReducedSystem<'_, MidpointTerms>,
        k: usize,
    ) -> Result<(Vec<f64>, (Option<JointShift>, StartShift), f64, f64), SolveError> {
        let (mech, dt, t) = (sys.mech, sys.terms.dt, sys.load_time);
        let (start, end) = (&sys.start.config, &sys.end.config);
        let p = &self.params[k];
        let mut partial = p.nodal_derivative(mech, end, t + 0.5 * dt, &mut self.nodal);
        let mut e_p = 0.0;
        let held = p.held_shift(mech);
        match p {
            Parameter::Stiffness {
                elements,
                component,
            } => {
                self.nodal.iter_mut().for_each(|v| *v = 0.0);
                e_p += unit_forces(sys, elements, *component, &mut self.nodal);
            }
            Parameter::Geometry {
                stretch,
                spin,
                loads,
                ..
            } => {
                self.nodal.iter_mut().for_each(|v| *v = 0.0);
                let geometry = (stretch.as_slice(), spin, loads.as_slice());
                e_p += midpoint_geometry::forces(sys, geometry, &held, &mut self.nodal);
            }
            _ => {
                p.nodal_derivative(mech, end, t, &mut self.nodal);
            }
        }
        let h = &self.history[k];
        e_p += history_forces(&sys.terms, start, end, h, &mut self.nodal, mech);
        let mut extra = joint_history(sys, h, &mut self.nodal)?;
        let shift = match p {
            Parameter::Joint { joint, name } => {
                let shift = midpoint_joint::shift(sys, *joint, name)?;
                let at = (*joint, name.as_str());
                extra.extend(midpoint_joint::forces(sys, at, &shift, &mut self.nodal)?);
                Some(shift)
            }
            _ => None,
        };
        if let Some(unit) = &self.units[k] {
            let (v_n, w_n) = (&sys.terms.v_n, &sys.terms.w_n);
            inertial_forces(unit, start, end, (v_n, w_n), dt, &mut self.nodal);
            let (v1, w1) = end_motion(start, end, v_n, w_n, dt);
            partial += unit.kinetic_energy(&v1, &w1);
        }
        let mut dq = vec![0.0; sys.topo.dofs.n_eq];
        sys.reduce(&self.nodal, &mut dq);
        for (eq, value) in extra {
            dq[eq] += value;
        }
        Ok((dq, (shift, held), partial, e_p))
    }
}

/// What the records' derivatives need of a converged step's end: the
/// internal forces and the velocities there.
struct EndState {
    f_int: Vec<f64>,
    v1: Vec<Vector3<f64>>,
    w1: Vec<Vector3<f64>>,
}

impl EndState {
    fn of(sys: &ReducedSystem<'_, MidpointTerms>) -> Self {
        let (start, end) = (&sys.start.config, &sys.end.config);
        let (v1, w1) = end_motion(start, end, &sys.terms.v_n, &sys.terms.w_n, sys.terms.dt);
        Self {
            f_int: end_internal_forces(sys.mech, end),
            v1,
            w1,
        }
    }

    /// The displacements' derivatives (from each model's own initial
    /// positions, `start`) and the total energy's,
    /// `Σ (M v)·dv + Σ J₀W·dW + Σ f_int·dx − Σ f_ext·du + ∂E/∂p`.
    fn sensitivity(
        &self,
        sys: &ReducedSystem<'_, MidpointTerms>,
        next: &History,
        start: &StartShift,
        fext_end: &[f64],
        partial: f64,
    ) -> Sensitivity {
        let inertia = &sys.terms.inertia;
        let mut energy = partial + start.work(fext_end);
        energy += kinetic_derivative(inertia, (&self.v1, &self.w1), (&next.v, &next.w));
        for n in 0..self.v1.len() {
            for c in 0..3 {
                energy += self.f_int[6 * n + c] * next.x[n][c]
                    + self.f_int[6 * n + 3 + c] * next.theta[n][c];
                energy -= fext_end[6 * n + c] * next.x[n][c];
            }
        }
        Sensitivity {
            displacement: start.displacements(&next.x),
            energy,
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
    (shift, held): (Option<&JointShift>, &StartShift),
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
        let direct = shift.map_or(Vector3::zeros(), |s| s.of(i)) + held.of(i);
        next.x[i] = d.fixed_rows::<3>(0) + direct;
        next.theta[i] = d.fixed_rows::<3>(3).into_owned();
        next.v[i] = (next.x[i] - h.x[i]) * (2.0 / dt) - h.v[i];
        let r_n = dual_rotation(&start.rot[i], &h.theta[i]);
        let r1 = dual_rotation(&end.rot[i], &next.theta[i]);
        let w1 = end_spin(&r_n, &r1, &dual(&sys.terms.w_n[i], &h.w[i]), dt);
        next.w[i] = w1.map(|x| x.eps);
    }
    next
}
