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

use super::midpoint::dynamic_record;
use super::{DynamicSettings, Motion};
use crate::assembly::Assembler;
use crate::dofs::DofMap;
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonSystem};
use crate::record::StepRecord;
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

struct NewmarkStep<'a> {
    mech: &'a Mechanism,
    dofs: &'a DofMap,
    inertia: &'a Inertia,
    asm: &'a mut Assembler,
    start: &'a Configuration,
    prev: &'a Kinematics,
    end: Configuration,
    dt: f64,
    fext: Vec<f64>,
    nodal: Vec<f64>,
    abs: Vec<f64>,
    scratch: Vec<f64>,
    floor: f64,
}

impl NewtonSystem for NewmarkStep<'_> {
    fn evaluate(&mut self, r: &mut [f64]) -> f64 {
        let end = &self.end;
        self.asm.assemble(&self.mech.mesh, self.dofs, end);
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
        for &(i, j, m) in &self.inertia.mass {
            let u = end.x[j] - start.x[j];
            let a1 = (u - prev.v[j] * dt - prev.a[j] * (dt * dt * (0.5 - BETA))) / (BETA * dt * dt);
            for c in 0..3 {
                self.nodal[6 * i + c] += m * a1[c];
                self.abs[6 * i + c] += (m * a1[c]).abs();
            }
            let k = m / (BETA * dt * dt);
            let (mi, mj) = (&self.dofs.nodes[i], &self.dofs.nodes[j]);
            for (ei, ci) in mi.eqs.iter().zip(&mi.cols) {
                for (ej, cj) in mj.eqs.iter().zip(&mj.cols) {
                    let v = k * ci.fixed_rows::<3>(0).dot(&cj.fixed_rows::<3>(0));
                    if v != 0.0 {
                        self.asm.add_entry(*ei, *ej, v);
                    }
                }
            }
        }
        // Rotational inertia Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁), by AD in a spin of Rₙ₊₁.
        type D = DualSVec64<3>;
        for (i, j0) in self.inertia.rotational.iter().enumerate() {
            if *j0 == Matrix3::zeros() {
                continue;
            }
            let eta = Vector3::new(
                D::from_re(0.0).derivative(0),
                D::from_re(0.0).derivative(1),
                D::from_re(0.0).derivative(2),
            );
            let r1 = exp(&eta) * end.rot[i].map(D::from_re);
            let a1 = angular_acceleration(&start.rot[i], &r1, &prev.w[i], &prev.alpha[i], dt);
            let w1 = (prev.w[i] + prev.alpha[i] * (dt * (1.0 - GAMMA))).map(D::from_re)
                + a1 * D::from_re(dt * GAMMA);
            let jd = j0.map(D::from_re);
            let m = r1 * (jd * a1 + w1.cross(&(jd * w1)));
            let mut k = Matrix3::zeros();
            for c in 0..3 {
                self.nodal[6 * i + 3 + c] += m[c].re;
                self.abs[6 * i + 3 + c] += m[c].re.abs();
                k.set_row(c, &m[c].eps.unwrap_generic(Const::<3>, U1).transpose());
            }
            let map = &self.dofs.nodes[i];
            for (ei, ci) in map.eqs.iter().zip(&map.cols) {
                for (ej, cj) in map.eqs.iter().zip(&map.cols) {
                    let v = ci.fixed_rows::<3>(3).dot(&(k * cj.fixed_rows::<3>(3)));
                    if v != 0.0 {
                        self.asm.add_entry(*ei, *ej, v);
                    }
                }
            }
        }
        self.dofs.reduce(&self.nodal, r);
        self.dofs.reduce(&self.fext, &mut self.scratch);
        let f_ext = norm(&self.scratch);
        self.dofs.reduce(&self.abs, &mut self.scratch);
        f_ext.max(norm(&self.scratch))
    }

    fn tangent_values(&self) -> &[f64] {
        &self.asm.values
    }

    fn apply(&mut self, dq: &[f64]) {
        for n in 0..self.end.x.len() {
            let p = self.dofs.node_increment(n, dq);
            if p != nalgebra::Vector6::zeros() {
                self.end.increment(
                    n,
                    &p.fixed_rows::<3>(0).into_owned(),
                    &p.fixed_rows::<3>(3).into_owned(),
                );
            }
        }
    }

    fn floor(&self) -> f64 {
        self.floor
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Integrates `mech` from `initial` with Newmark's trapezoidal rule. Initial
/// accelerations come from the equations of motion at t = 0 with the lumped
/// (row-sum) masses: `a₀ = (f_ext − f_int)/mᵢ`, `A₀ = J₀⁻¹(R₀ᵀm_ext − W₀ × J₀W₀)`
/// (zero where a node carries no mass or rotational inertia).
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    if !mech.joints.is_empty() || !mech.prescribed.is_empty() {
        return Err(SolveError::InvalidMechanism(
            "joints and prescribed motion are not available in dynamic analyses yet".into(),
        ));
    }
    if !(settings.dt > 0.0 && settings.t_end > 0.0) {
        return Err(SolveError::InvalidMechanism(
            "dt and t_end must be positive".into(),
        ));
    }
    let nodes = mech.mesh.node_count();
    let dofs = DofMap::independent(&mech.fixed);
    let inertia = Inertia::new(&mech.mesh, settings.mass);
    let mut asm = Assembler::new(&mech.mesh, &dofs, &[]);
    let mut lu = SparseLu::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
    let (mut r, mut dq) = (vec![0.0; dofs.n_eq], vec![0.0; dofs.n_eq]);
    let mut config = Configuration::initial(&mech.mesh.positions);
    let mut fext = vec![0.0; 6 * nodes];
    mech.external_forces(0.0, &mut fext);
    asm.assemble(&mech.mesh, &dofs, &config);
    let mut kin = Kinematics {
        v: initial.v.clone(),
        w: initial.w.clone(),
        a: (0..nodes)
            .map(|i| {
                let f = Vector3::new(
                    fext[6 * i] - asm.nodal[6 * i],
                    fext[6 * i + 1] - asm.nodal[6 * i + 1],
                    fext[6 * i + 2] - asm.nodal[6 * i + 2],
                );
                if inertia.row_mass[i] > 0.0 && !mech.fixed[i][..3].iter().any(|&h| h) {
                    f / inertia.row_mass[i]
                } else {
                    Vector3::zeros()
                }
            })
            .collect(),
        alpha: (0..nodes)
            .map(|i| {
                let m = Vector3::new(
                    fext[6 * i + 3] - asm.nodal[6 * i + 3],
                    fext[6 * i + 4] - asm.nodal[6 * i + 4],
                    fext[6 * i + 5] - asm.nodal[6 * i + 5],
                );
                let j0 = inertia.rotational[i];
                let w = initial.w[i];
                match j0.try_inverse() {
                    Some(ji) if !mech.fixed[i][3..].iter().any(|&h| h) => {
                        ji * (m - w.cross(&(j0 * w)))
                    }
                    _ => Vector3::zeros(),
                }
            })
            .collect(),
    };
    on_step(&dynamic_record(
        mech, &inertia, &config, &kin.v, &kin.w, &fext, 0.0, 0.0, None,
    ));
    let (mut t, mut step, mut halvings, mut easy) = (0.0f64, settings.dt, 0usize, 0usize);
    while t < settings.t_end * (1.0 - 1e-12) {
        let dt = step.min(settings.t_end - t);
        let mut end = config.clone();
        for i in 0..nodes {
            if !mech.fixed[i].iter().any(|&h| h) {
                let spin = config.rot[i] * kin.w[i] * dt;
                end.increment(i, &(kin.v[i] * dt), &spin);
            }
        }
        let mut f1 = vec![0.0; 6 * nodes];
        mech.external_forces(t + dt, &mut f1);
        let mut sys = NewmarkStep {
            mech,
            dofs: &dofs,
            inertia: &inertia,
            asm: &mut asm,
            start: &config,
            prev: &kin,
            end,
            dt,
            fext: f1,
            nodal: vec![0.0; 6 * nodes],
            abs: vec![0.0; 6 * nodes],
            scratch: vec![0.0; dofs.n_eq],
            floor: mech.round_off_floor(),
        };
        match newton::solve(&mut sys, &mut lu, &settings.newton, &mut r, &mut dq) {
            Ok(report) => {
                let end = sys.end;
                let mut next = Kinematics {
                    v: Vec::new(),
                    a: Vec::new(),
                    w: Vec::new(),
                    alpha: Vec::new(),
                };
                for i in 0..nodes {
                    let u = end.x[i] - config.x[i];
                    let a1 = (u - kin.v[i] * dt - kin.a[i] * (dt * dt * (0.5 - BETA)))
                        / (BETA * dt * dt);
                    next.v
                        .push(kin.v[i] + (kin.a[i] * (1.0 - GAMMA) + a1 * GAMMA) * dt);
                    next.a.push(a1);
                    let al: Vector3<f64> = angular_acceleration(
                        &config.rot[i],
                        &end.rot[i],
                        &kin.w[i],
                        &kin.alpha[i],
                        dt,
                    );
                    next.w
                        .push(kin.w[i] + (kin.alpha[i] * (1.0 - GAMMA) + al * GAMMA) * dt);
                    next.alpha.push(al);
                }
                config = end;
                kin = next;
                t += dt;
                mech.external_forces(t, &mut fext);
                on_step(&dynamic_record(
                    mech,
                    &inertia,
                    &config,
                    &kin.v,
                    &kin.w,
                    &fext,
                    t,
                    dt,
                    Some(&report),
                ));
                halvings = 0;
                easy += 1;
                if easy >= 4 && step < settings.dt {
                    step = (2.0 * step).min(settings.dt);
                    easy = 0;
                }
            }
            Err(reason) => {
                if halvings >= settings.max_halvings {
                    return Err(SolveError::NoConvergence {
                        time: t + dt,
                        halvings,
                        reason,
                    });
                }
                halvings += 1;
                easy = 0;
                step *= 0.5;
            }
        }
    }
    Ok(config)
}
