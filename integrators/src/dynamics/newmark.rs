//! Newmark's trapezoidal rule (β = ¼, γ = ½) on SO(3) (Simo & Vu-Quoc):
//! equilibrium at `tₙ₊₁` with the internal force of the beam (the exact
//! gradient of the strain energy), translations by the standard Newmark
//! relations and rotations through the material incremental rotation
//! `Ω = Rₙᵀ log(Rₙ₊₁Rₙᵀ)`:
//!
//! ```text
//! Aₙ₊₁ = (Ω − Δt Wₙ − Δt²(½ − β) Aₙ)/(β Δt²),   Wₙ₊₁ = Wₙ + Δt((1 − γ)Aₙ + γ Aₙ₊₁)
//! ```
//!
//! with the spatial inertial moment `Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)`. It
//! conserves neither energy nor angular momentum in general; the paper's
//! screw example shows its energy growing until it fails.

use super::mass_slots::MassSlots;
use super::midpoint::dynamic_record;
use super::{slave_velocities, DynamicSettings, Motion, StepControl, GROW_AFTER};
use crate::assembly::Assembler;
use crate::constraints::{initial_state, joint_records, MechanismState, Topology};
use crate::error::SolveError;
use crate::free_motion::FreeMotion;
use crate::linsolve::{SparseLu, TangentRef};
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonReport, NewtonSystem};
use crate::record::StepRecord;
use crate::rotation_guard::{as_step_failure, RotationGuard};
use flexmech_core::rotation::{exp, log};
use flexmech_core::{Configuration, Inertia};
use nalgebra::{Const, Matrix3, Vector3, U1};
use num_dual::DualSVec64;

const BETA: f64 = 0.25;
const GAMMA: f64 = 0.5;

/// Velocities and accelerations at the end of a step.
struct Kinematics {
    v: Vec<Vector3<f64>>,
    a: Vec<Vector3<f64>>,
    w: Vec<Vector3<f64>>,
    alpha: Vec<Vector3<f64>>,
}

/// Body angular acceleration at `n+1` for the end rotation `r1` (generic, for AD).
fn angular_acceleration<T: flexmech_core::Scalar>(
    r_n: &Matrix3<f64>,
    r1: &Matrix3<T>,
    w_n: &Vector3<f64>,
    a_n: &Vector3<f64>,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let omega = log(&(r1 * r_n.map(c).transpose()));
    let big_omega = r_n.map(c).transpose() * omega;
    (big_omega - w_n.map(c) * c(dt) - a_n.map(c) * c(dt * dt * (0.5 - BETA))) / c(BETA * dt * dt)
}

/// Inertial moment `Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)` of node `i` for the end
/// rotation `r1` (generic, for AD).
fn inertial_moment<T: flexmech_core::Scalar>(
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r1: &Matrix3<T>,
    prev: &Kinematics,
    i: usize,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let a1 = angular_acceleration(r_n, r1, &prev.w[i], &prev.alpha[i], dt);
    let w1 = (prev.w[i] + prev.alpha[i] * (dt * (1.0 - GAMMA))).map(c) + a1 * c(dt * GAMMA);
    let jd = j0.map(c);
    *r1 * (jd * a1 + w1.cross(&(jd * w1)))
}

struct NewmarkStep<'a> {
    mech: &'a Mechanism,
    topo: &'a mut Topology,
    inertia: &'a Inertia,
    asm: &'a mut Assembler,
    start: &'a Configuration,
    prev: &'a Kinematics,
    /// The current iterate at `tₙ₊₁` (slaves placed exactly).
    end: MechanismState,
    dt: f64,
    fext: Vec<f64>,
    nodal: Vec<f64>,
    abs: Vec<f64>,
    scratch: Vec<f64>,
    /// Tangent positions of the mass blocks (see [`MassSlots`]).
    slots: &'a MassSlots,
    floor: f64,
}

impl NewmarkStep<'_> {
    /// The residual into `r` (returns the force scale) and, if `tangent`,
    /// the tangent values.
    fn evaluate_with(&mut self, r: &mut [f64], tangent: bool) -> f64 {
        self.topo.refresh(self.mech, &self.end);
        if tangent {
            self.asm
                .assemble(&self.mech.mesh, &self.topo.dofs, &self.end.config);
        } else {
            self.asm
                .assemble_residual(&self.mech.mesh, &self.end.config);
        }
        let (dt, start, prev) = (self.dt, self.start, self.prev);
        for (g, (fi, fe)) in self
            .nodal
            .iter_mut()
            .zip(self.asm.nodal.iter().zip(&self.fext))
        {
            *g = fi - fe;
        }
        self.abs.copy_from_slice(&self.asm.nodal_abs);
        // Translational inertia M aₙ₊₁, aₙ₊₁ = (u − Δt vₙ − Δt²(½−β)aₙ)/(βΔt²).
        for k in 0..self.inertia.mass.len() {
            let (i, j, m) = self.inertia.mass[k];
            let u = self.end.config.x[j] - start.x[j];
            let a1 = (u - prev.v[j] * dt - prev.a[j] * (dt * dt * (0.5 - BETA))) / (BETA * dt * dt);
            for c in 0..3 {
                self.nodal[6 * i + c] += m * a1[c];
                self.abs[6 * i + c] += (m * a1[c]).abs();
            }
            if tangent {
                let block = Matrix3::identity() * (m / (BETA * dt * dt));
                self.slots
                    .add_translational(self.asm, &self.topo.dofs, k, (i, j), &block);
            }
        }
        // Rotational inertia Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁), and its tangent by
        // AD in a spin of Rₙ₊₁.
        for i in 0..self.inertia.rotational.len() {
            let j0 = self.inertia.rotational[i];
            if j0 == Matrix3::zeros() {
                continue;
            }
            let (m, k) = if tangent {
                type D = DualSVec64<3>;
                let eta = Vector3::new(
                    D::from_re(0.0).derivative(0),
                    D::from_re(0.0).derivative(1),
                    D::from_re(0.0).derivative(2),
                );
                let r1 = exp(&eta) * self.end.config.rot[i].map(D::from_re);
                let m = inertial_moment(&j0, &start.rot[i], &r1, prev, i, dt);
                let mut k = Matrix3::zeros();
                for c in 0..3 {
                    k.set_row(c, &m[c].eps.unwrap_generic(Const::<3>, U1).transpose());
                }
                (m.map(|v| v.re), Some(k))
            } else {
                let r1 = self.end.config.rot[i];
                (inertial_moment(&j0, &start.rot[i], &r1, prev, i, dt), None)
            };
            for c in 0..3 {
                self.nodal[6 * i + 3 + c] += m[c];
                self.abs[6 * i + 3 + c] += m[c].abs();
            }
            if let Some(k) = k {
                self.slots.add_rotational(self.asm, &self.topo.dofs, i, &k);
            }
        }
        self.topo.dofs.reduce(&self.nodal, r);
        // Joints: the derivative of Nᵀg with the slave's full residual
        // (internal + inertial − external).
        if tangent {
            let blocks = self
                .topo
                .geometric_blocks(self.mech, &self.end, &self.nodal);
            for (b, block) in blocks.iter().enumerate() {
                self.asm.add_block(b, block);
            }
        }
        let dofs = &self.topo.dofs;
        let f_ext = dofs.reduced_norm(&self.fext, &mut self.scratch);
        f_ext.max(dofs.reduced_norm(&self.abs, &mut self.scratch))
    }
}

impl NewtonSystem for NewmarkStep<'_> {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        self.evaluate_with(r, true)
    }

    fn residual(&mut self, r: &mut [f64]) -> f64 {
        self.evaluate_with(r, false)
    }

    fn update_tangent(&mut self, scratch: &mut [f64]) {
        self.evaluate_with(scratch, true);
    }

    fn tangent_key(&self) -> f64 {
        self.dt
    }

    fn tangent_values(&self) -> &[f64] {
        &self.asm.values
    }

    fn apply(&mut self, dq: &[f64]) {
        self.topo.apply(self.mech, &mut self.end, dq);
    }

    fn floor(&self) -> f64 {
        self.floor
    }

    fn free_motion(&self, mode: &[f64], tangent: TangentRef) -> FreeMotion {
        let topo = &self.topo;
        FreeMotion::of(
            self.mech,
            &topo.dofs,
            &topo.released_eqs,
            &self.end.config.x,
            mode,
            tangent,
        )
    }
}

/// Initial accelerations from the reduced equations of motion at t = 0,
/// `(Tᵀ M T) q̈ = −Tᵀ r` (translational and rotational inertia through the
/// node maps, joints included); nodal accelerations `pᵢ = Tᵢ q̈`, body angular
/// `A = Rᵀ α`. Velocity-dependent terms (gyroscopic, `Ṫ q̇`) are left out, so
/// a system that starts spinning begins with a small acceleration error that
/// the trapezoidal rule carries as an O(Δt) velocity offset. If the reduced
/// mass is singular (massless DOFs) the accelerations start at zero.
#[allow(clippy::too_many_arguments)]
fn initial_accelerations(
    mech: &Mechanism,
    topo: &Topology,
    inertia: &Inertia,
    asm: &mut Assembler,
    lu: &mut SparseLu,
    state: &MechanismState,
    residual: &[f64],
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let nodes = mech.mesh.node_count();
    let zero = (vec![Vector3::zeros(); nodes], vec![Vector3::zeros(); nodes]);
    asm.values.iter_mut().for_each(|v| *v = 0.0);
    for &(i, j, m) in &inertia.mass {
        asm.add_node_block(&topo.dofs, (i, 0), (j, 0), &(Matrix3::identity() * m));
    }
    for (i, j0) in inertia.rotational.iter().enumerate() {
        let r = state.config.rot[i];
        asm.add_node_block(&topo.dofs, (i, 3), (i, 3), &(r * j0 * r.transpose()));
    }
    let mut q = vec![0.0; topo.dofs.n_eq];
    topo.dofs.reduce(residual, &mut q);
    q.iter_mut().for_each(|v| *v = -*v);
    if lu.factor(&asm.values).is_err() || lu.solve(&mut q).is_err() {
        return zero;
    }
    let mut a = Vec::with_capacity(nodes);
    let mut alpha = Vec::with_capacity(nodes);
    for i in 0..nodes {
        let p = topo.dofs.node_increment(i, &q);
        a.push(p.fixed_rows::<3>(0).into_owned());
        alpha.push(state.config.rot[i].transpose() * p.fixed_rows::<3>(3));
    }
    (a, alpha)
}

/// Integrates `mech` from `initial` with Newmark's trapezoidal rule. Joints
/// enter through `N` (as in statics); driven coordinates and prescribed DOFs
/// follow their schedules.
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    if !(settings.dt > 0.0 && settings.t_end > 0.0) {
        return Err(SolveError::InvalidMechanism(
            "dt and t_end must be positive".into(),
        ));
    }
    let nodes = mech.mesh.node_count();
    let mut state = initial_state(mech);
    let mut topo = Topology::new(mech, &state)?;
    topo.impose(mech, &mut state, 0.0);
    let mut guard = RotationGuard::new(mech, &state);
    let n_eq = topo.dofs.n_eq;
    let inertia = Inertia::new(&mech.mesh, settings.mass);
    let mut asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
    let mut lu = SparseLu::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let slots = MassSlots::new(&asm, &topo.dofs, &inertia);
    let (mut r, mut dq) = (vec![0.0; n_eq], vec![0.0; n_eq]);
    let mut fext = vec![0.0; 6 * nodes];
    mech.external_forces(0.0, &mut fext);
    asm.assemble(&mech.mesh, &topo.dofs, &state.config);
    let residual: Vec<f64> = asm.nodal.iter().zip(&fext).map(|(a, b)| a - b).collect();
    let (v0, w0) = slave_velocities(mech, &topo, &state, initial);
    let (a0, alpha0) =
        initial_accelerations(mech, &topo, &inertia, &mut asm, &mut lu, &state, &residual);
    let mut kin = Kinematics {
        v: v0,
        w: w0,
        a: a0,
        alpha: alpha0,
    };
    let record = |state: &MechanismState,
                  kin: &Kinematics,
                  fext: &[f64],
                  t: f64,
                  dt: f64,
                  rep: Option<&NewtonReport>| {
        let mut rec = dynamic_record(
            mech,
            &inertia,
            &state.config,
            &kin.v,
            &kin.w,
            fext,
            t,
            dt,
            rep,
        );
        rec.joints = joint_records(mech, state);
        rec
    };
    on_step(&record(&state, &kin, &fext, 0.0, 0.0, None));
    let (mut t, mut control) = (
        0.0f64,
        StepControl::with(settings.dt, settings.max_halvings, GROW_AFTER),
    );
    // The drivers' work, by the trapezoidal rule on their reactions at both
    // ends of each step (the first step uses its end value twice).
    let mut driver_work = 0.0;
    let mut r_prev: Option<(Vec<Vec<f64>>, Vec<f64>)> = None;
    while t < settings.t_end * (1.0 - 1e-12) {
        let dt = control.next(t, settings.t_end);
        let start = state.config.clone();
        let mut end = state.clone();
        for i in 0..nodes {
            if !mech.fixed[i].iter().any(|&h| h) && topo.slave_of[i].is_none() {
                let spin = start.rot[i] * kin.w[i] * dt;
                end.config.increment(i, &(kin.v[i] * dt), &spin);
            }
        }
        topo.impose(mech, &mut end, t + dt);
        let mut f1 = vec![0.0; 6 * nodes];
        mech.external_forces(t + dt, &mut f1);
        let mut sys = NewmarkStep {
            mech,
            topo: &mut topo,
            inertia: &inertia,
            asm: &mut asm,
            start: &start,
            prev: &kin,
            end,
            dt,
            fext: f1,
            nodal: vec![0.0; 6 * nodes],
            abs: vec![0.0; 6 * nodes],
            scratch: vec![0.0; n_eq],
            slots: &slots,
            floor: mech.round_off_floor_at(&state.config.x),
        };
        match newton::solve(&mut sys, &mut lu, &settings.newton, &mut r, &mut dq) {
            Ok(report) => {
                if let Err(objection) = guard.accept(mech, &sys.end, t + dt) {
                    control.failed(t + dt, as_step_failure(objection)?)?;
                    continue;
                }
                let r_end = sys.topo.driver_reactions(mech, &sys.end, &sys.nodal);
                let r_start = r_prev.take().unwrap_or_else(|| r_end.clone());
                driver_work += driver_increment_work(mech, &state, &sys.end, &r_start, &r_end);
                r_prev = Some(r_end);
                let end = sys.end;
                let mut next = Kinematics {
                    v: Vec::new(),
                    a: Vec::new(),
                    w: Vec::new(),
                    alpha: Vec::new(),
                };
                for i in 0..nodes {
                    let u = end.config.x[i] - start.x[i];
                    let a1 = (u - kin.v[i] * dt - kin.a[i] * (dt * dt * (0.5 - BETA)))
                        / (BETA * dt * dt);
                    next.v
                        .push(kin.v[i] + (kin.a[i] * (1.0 - GAMMA) + a1 * GAMMA) * dt);
                    next.a.push(a1);
                    let al: Vector3<f64> = angular_acceleration(
                        &start.rot[i],
                        &end.config.rot[i],
                        &kin.w[i],
                        &kin.alpha[i],
                        dt,
                    );
                    next.w
                        .push(kin.w[i] + (kin.alpha[i] * (1.0 - GAMMA) + al * GAMMA) * dt);
                    next.alpha.push(al);
                }
                state = end;
                kin = next;
                t = control.advance(t, dt);
                mech.external_forces(t, &mut fext);
                let mut rec = record(&state, &kin, &fext, t, dt, Some(&report));
                rec.energy.driver_work = driver_work;
                on_step(&rec);
                control.succeeded();
            }
            Err(reason) => control.failed(t + dt, reason)?,
        }
    }
    Ok(state.config)
}

/// The drivers' work over a step by the trapezoidal rule: the mean of the
/// reactions at both ends ([`Topology::driver_reactions`]) times the driven
/// coordinates' and prescribed DOFs' increments.
fn driver_increment_work(
    mech: &Mechanism,
    start: &MechanismState,
    end: &MechanismState,
    r0: &(Vec<Vec<f64>>, Vec<f64>),
    r1: &(Vec<Vec<f64>>, Vec<f64>),
) -> f64 {
    let mut w = 0.0;
    for (j, joint) in mech.joints.iter().enumerate() {
        for (c, d) in joint.driven.iter().enumerate() {
            if d.is_some() {
                let dq = end.released[j].q[c] - start.released[j].q[c];
                w += 0.5 * (r0.0[j][c] + r1.0[j][c]) * dq;
            }
        }
    }
    for k in 0..mech.prescribed.len() {
        let dv = end.prescribed[k] - start.prescribed[k];
        w += 0.5 * (r0.1[k] + r1.1[k]) * dv;
    }
    w
}
