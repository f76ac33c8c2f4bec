//! The midpoint machinery shared by the momentum-conserving and
//! energy–momentum schemes (paper eqs 16–17, FORMULATION §4):
//!
//! * translations `(xₙ₊₁ − xₙ)/Δt = ½(vₙ + vₙ₊₁)`, inertial force `M(vₙ₊₁ − vₙ)/Δt`;
//! * rotations `Rₙ₊₁ = cay(θ)Rₙ`, `θ = (Δt/2) Rₙ(Wₙ + Wₙ₊₁)`, inertial moment
//!   `(πₙ₊₁ − πₙ)/Δt` with `π = R J₀ W` — so that `θ·(πₙ₊₁ − πₙ)/Δt` and
//!   `u·M(vₙ₊₁ − vₙ)/Δt` are exactly the kinetic energy changes;
//! * internal force of the scheme ([`Scheme`]): `q_k(Nₙ₊½, Mₙ₊½)` with the
//!   geodesic mid rotation (momentum), the energy-consistent discrete
//!   gradient (energy–momentum, FORMULATION §4.3), or `q_k` with the
//!   algebraic mid rotation plus `β q_k(N_d, 0)` (the paper's energy–momentum);
//! * external loads at `tₙ₊½`;
//! * joints through the exact incremental map `Ñ` (paper eqs 21–23,
//!   [`flexmech_joints::incremental`]): slaves are placed exactly by relation
//!   (1) after every Newton update, and the reduced equations are `Ñᵀ g = 0`,
//!   so the conservation properties of the beams hold for the joined system.
//!
//! Newton's tangent for a joined system is the exact derivative of `Ñᵀ g`:
//! the assembled blocks with the slaves' rows through `Ñ` and columns through
//! `N` (the slave's end pose moves with the unknowns through `N`), plus
//! `(∂Ñ/∂q)ᵀ g` with the slaves' residuals held
//! ([`Topology::incremental_blocks`], AD through `Ñ`). Newton converges
//! quadratically with joints too.

use super::mass_slots::MassSlots;
pub use super::Scheme;
use super::{increment_work, slave_velocities};
use super::{DynamicSettings, Motion, StepControl, GROW_AFTER};
use crate::assembly::Assembler;
use crate::constraints::{initial_state, joint_records, MechanismState, Topology};
use crate::error::SolveError;
use crate::free_motion::FreeMotion;
use crate::linsolve::{SparseLu, TangentRef};
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonReport, NewtonSystem};
use crate::record::{Energies, StepRecord};
use crate::rotation_guard::{as_step_failure, RotationGuard};
use crate::statics::strain_energy;
use flexmech_core::conserving::{MidRotation, Pose, Pose3};
use flexmech_core::rotation::{cayley_inverse, exp, log};
use flexmech_core::{cst, BeamElement, Configuration, Element, Inertia, Scalar};
use nalgebra::{Const, Matrix3, SVector, Vector3, U1};
use num_dual::DualSVec64;

/// Velocities at the end of a step from the configurations at both ends.
pub fn end_motion(
    start: &Configuration,
    end: &Configuration,
    v_n: &[Vector3<f64>],
    w_n: &[Vector3<f64>],
    dt: f64,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let v = (0..end.x.len())
        .map(|i| (end.x[i] - start.x[i]) * (2.0 / dt) - v_n[i])
        .collect();
    let w = (0..end.x.len())
        .map(|i| {
            let theta = cayley_inverse(&(end.rot[i] * start.rot[i].transpose()));
            start.rot[i].transpose() * theta * (2.0 / dt) - w_n[i]
        })
        .collect();
    (v, w)
}

/// Dual numbers for derivatives with respect to an element's 12 increments.
pub(super) type Dual12 = DualSVec64<12>;

/// An element's pose at the step's start, and its start and end poses as
/// [`Dual12`] numbers with the end seeded by spatial increments
/// (`x ← x + η`, `R ← exp(η̂)R`), so that any function of them carries its
/// derivative with respect to the end pose.
pub(super) fn seeded_poses(
    e: &BeamElement<2>,
    start: &Configuration,
    end: &Configuration,
) -> (Pose<f64>, Pose<Dual12>, Pose<Dual12>) {
    type D = Dual12;
    let n = e.nodes;
    let s = pose_of(e, start);
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    let v = |j: usize| Vector3::new(seed(j), seed(j + 1), seed(j + 2));
    let sd: Pose<D> = (
        s.0.map(|x| x.map(D::from_re)),
        s.1.map(|q| q.map(D::from_re)),
    );
    let ed: Pose<D> = (
        [
            end.x[n[0]].map(D::from_re) + v(0),
            end.x[n[1]].map(D::from_re) + v(6),
        ],
        [
            exp(&v(3)) * end.rot[n[0]].map(D::from_re),
            exp(&v(9)) * end.rot[n[1]].map(D::from_re),
        ],
    );
    (s, sd, ed)
}

/// `q_k(Nₙ₊½, Mₙ₊½)` and, when `correction` is asked for, the energy–momentum
/// correction's `q_k(N_d, 0)`, `N_d = Nₙ₊₁ − Nₙ`, of one element between its
/// start pose `s` and the seeded poses `sd`, `ed` (see [`seeded_poses`]), as
/// dual numbers.
pub(super) fn midpoint_forces(
    e: &BeamElement<2>,
    s: &Pose<f64>,
    sd: &Pose<Dual12>,
    ed: &Pose<Dual12>,
    mid: MidRotation,
    correction: bool,
) -> (SVector<Dual12, 12>, Option<SVector<Dual12, 12>>) {
    type D = Dual12;
    let (nbar, mbar) = averaged_resultants(e, s, ed);
    let qk = e.midpoint_force(sd, ed, &nbar, &mbar, mid);
    // N_d = Nₙ₊₁ − Nₙ = 2(Nₙ₊½ − Nₙ).
    let n0 = e.resultants(&s.0, &s.1).0.map(D::from_re);
    let qd = correction.then(|| {
        e.midpoint_force(
            sd,
            ed,
            &((nbar - n0) * D::from_re(2.0)),
            &Vector3::zeros(),
            mid,
        )
    });
    (qk, qd)
}

/// Element kernel of the midpoint schemes: the scheme's internal force
/// (`q_k(Nₙ₊½, Mₙ₊½)` with the geodesic mid rotation for the momentum
/// scheme; the energy-consistent discrete gradient for the energy–momentum
/// scheme; `q_k(Nₙ₊½, Mₙ₊½) + β q_k(N_d, 0)` with the algebraic mid rotation
/// for the paper's energy–momentum scheme) and its derivative with respect
/// to spatial increments of the end pose (`x ← x + η`, `R ← exp(η̂)R`):
/// closed form for the momentum scheme, AD over the end spins with
/// closed-form chord columns for the energy–momentum scheme
/// ([`flexmech_core::conserving_tangent`]), forward-mode AD over all twelve
/// increments for the paper's scheme.
fn element_kernel(
    el: &Element,
    start: &Configuration,
    end: &Configuration,
    scheme: Scheme,
    beta: f64,
    r: &mut [f64],
    k: &mut [f64],
) {
    let e = match el {
        Element::Linear(e) => e,
        Element::Quadratic(e) => return quadratic_kernel(e, start, end, r, k),
    };
    let pose = |c: &Configuration| pose_of(e, c);
    let (q, jac) = match scheme {
        Scheme::Momentum => e.momentum_force_tangent(&pose(start), &pose(end)),
        Scheme::EnergyMomentum => e.energy_momentum_force_tangent(&pose(start), &pose(end)),
        Scheme::EnergyMomentumPaper => {
            type D = Dual12;
            let (s, sd, ed) = seeded_poses(e, start, end);
            let (mut q, qd) = midpoint_forces(e, &s, &sd, &ed, scheme.mid_rotation(), beta != 0.0);
            if let Some(qd) = qd {
                q += qd * D::from_re(beta);
            }
            for i in 0..12 {
                r[i] = q[i].re;
                let row = q[i].eps.unwrap_generic(Const::<12>, U1);
                for j in 0..12 {
                    k[j * 12 + i] = row[j];
                }
            }
            return;
        }
    };
    r.copy_from_slice(q.as_slice());
    k.copy_from_slice(jac.as_slice());
}

/// The element force of [`element_kernel`] alone (no derivative): for
/// residual checks that no factorisation follows.
fn element_force(
    el: &Element,
    start: &Configuration,
    end: &Configuration,
    scheme: Scheme,
    beta: f64,
    r: &mut [f64],
) {
    let q = match (el, scheme) {
        (Element::Linear(e), Scheme::Momentum | Scheme::EnergyMomentum) => {
            let (s, t) = (pose_of(e, start), pose_of(e, end));
            let (nbar, mbar) = averaged_resultants(e, &s, &t);
            if scheme == Scheme::Momentum {
                e.midpoint_force(&s, &t, &nbar, &mbar, MidRotation::Geodesic)
            } else {
                e.discrete_gradient_force(&s, &t, &nbar, &mbar)
            }
        }
        (Element::Quadratic(e), _) => {
            let n = e.nodes;
            let s: Pose3<f64> = (n.map(|i| start.x[i]), n.map(|i| start.rot[i]));
            let t: Pose3<f64> = (n.map(|i| end.x[i]), n.map(|i| end.rot[i]));
            r.copy_from_slice(e.discrete_gradient_force(&s, &t).as_slice());
            return;
        }
        (Element::Linear(_), Scheme::EnergyMomentumPaper) => {
            let mut k = [0.0; 144];
            return element_kernel(el, start, end, scheme, beta, r, &mut k);
        }
    };
    r.copy_from_slice(q.as_slice());
}

/// Element kernel for 3-node elements, in both conserving schemes: the
/// energy-consistent discrete gradient (FORMULATION §4.3; there is no
/// paper form for them, so the momentum scheme uses it too and conserves
/// energy as well) and its AD derivative under spatial increments of the
/// end pose.
fn quadratic_kernel(
    e: &BeamElement<3>,
    start: &Configuration,
    end: &Configuration,
    r: &mut [f64],
    k: &mut [f64],
) {
    type D = DualSVec64<18>;
    let n = e.nodes;
    let seed = |j: usize| D::from_re(0.0).derivative(j);
    let v = |j: usize| Vector3::new(seed(j), seed(j + 1), seed(j + 2));
    let sd: Pose3<D> = (
        std::array::from_fn(|i| start.x[n[i]].map(D::from_re)),
        std::array::from_fn(|i| start.rot[n[i]].map(D::from_re)),
    );
    let ed: Pose3<D> = (
        std::array::from_fn(|i| end.x[n[i]].map(D::from_re) + v(6 * i)),
        std::array::from_fn(|i| exp(&v(6 * i + 3)) * end.rot[n[i]].map(D::from_re)),
    );
    let q = e.discrete_gradient_force(&sd, &ed);
    for i in 0..18 {
        r[i] = q[i].re;
        let row = q[i].eps.unwrap_generic(Const::<18>, U1);
        for j in 0..18 {
            k[j * 18 + i] = row[j];
        }
    }
}

/// The step averages `(Nₙ₊½, Mₙ₊½)` of an element's material resultants
/// between the start pose `s` and the end pose `ed` (plain, or seeded for
/// AD: see [`seeded_poses`]).
fn averaged_resultants<T: Scalar>(
    e: &BeamElement<2>,
    s: &Pose<f64>,
    ed: &Pose<T>,
) -> (Vector3<T>, Vector3<T>) {
    let (n0, m0) = e.resultants(&s.0, &s.1);
    let (n1, m1) = e.resultants(&ed.0, &ed.1);
    let half = cst::<T>(0.5);
    (
        (n0.map(cst::<T>) + n1) * half,
        (m0.map(cst::<T>) + m1) * half,
    )
}

/// A 2-node element's nodal positions and rotations in a configuration.
fn pose_of(e: &BeamElement<2>, c: &Configuration) -> Pose<f64> {
    let n = e.nodes;
    ([c.x[n[0]], c.x[n[1]]], [c.rot[n[0]], c.rot[n[1]]])
}

/// The energy–momentum scheme's consistency measure of a converged step:
/// the largest size, over the 2-node elements, of the rank-one corrections
/// of the discrete gradient relative to the largest element force, `O(Δt²)`
/// (NaN for a mesh without 2-node elements).
pub fn correction_size(mech: &Mechanism, start: &Configuration, end: &Configuration) -> f64 {
    let (mut corr, mut size) = (0.0f64, 0.0f64);
    for el in &mech.mesh.elements {
        let Element::Linear(e) = el else { continue };
        let (s, t) = (pose_of(e, start), pose_of(e, end));
        let (nbar, mbar) = averaged_resultants(e, &s, &t);
        let (q, c) = e.discrete_gradient_parts(&s, &t, &nbar, &mbar);
        corr = corr.max(c.norm());
        size = size.max(q.norm());
    }
    let linear = mech
        .mesh
        .elements
        .iter()
        .any(|e| matches!(e, Element::Linear(_)));
    if !linear {
        f64::NAN
    } else if size > 0.0 {
        corr / size
    } else {
        0.0
    }
}

/// Inertial moment `(πₙ₊₁ − πₙ)/Δt` of one node and, if `tangent`, its
/// derivative with respect to a spatial spin of the end rotation (by AD;
/// zero otherwise).
fn inertial_moment(
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r_end: &Matrix3<f64>,
    w_n: &Vector3<f64>,
    dt: f64,
    tangent: bool,
) -> (Vector3<f64>, Matrix3<f64>) {
    if !tangent {
        return (
            inertial_moment_at(j0, r_n, r_end, w_n, dt),
            Matrix3::zeros(),
        );
    }
    type D = DualSVec64<3>;
    let eta = Vector3::new(
        D::from_re(0.0).derivative(0),
        D::from_re(0.0).derivative(1),
        D::from_re(0.0).derivative(2),
    );
    let r1 = exp(&eta) * r_end.map(D::from_re);
    let m = inertial_moment_at(j0, r_n, &r1, w_n, dt);
    let mut k = Matrix3::zeros();
    let mut val = Vector3::zeros();
    for i in 0..3 {
        val[i] = m[i].re;
        k.set_row(i, &m[i].eps.unwrap_generic(Const::<3>, U1).transpose());
    }
    (val, k)
}

/// `(πₙ₊₁ − πₙ)/Δt` for the end rotation `r1` (generic, for AD), with
/// `Wₙ₊₁ = 2 Rₙᵀ cay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ`.
fn inertial_moment_at<T: flexmech_core::Scalar>(
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r1: &Matrix3<T>,
    w_n: &Vector3<f64>,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let rn = r_n.map(c);
    let theta = cayley_inverse(&(*r1 * rn.transpose()));
    let w1 = rn.transpose() * theta * c(2.0 / dt) - w_n.map(c);
    let pi_n = r_n * (j0 * w_n);
    (*r1 * (j0.map(c) * w1) - pi_n.map(c)) / c(dt)
}

/// One step of a midpoint scheme, as the [`NewtonSystem`] Newton solves.
pub struct MidpointStep<'a> {
    pub mech: &'a Mechanism,
    /// Unknowns and node maps (refreshed at the iterate).
    pub topo: &'a mut Topology,
    pub inertia: &'a Inertia,
    pub asm: &'a mut Assembler,
    /// The state at `tₙ`.
    pub start: &'a MechanismState,
    pub v_n: &'a [Vector3<f64>],
    pub w_n: &'a [Vector3<f64>],
    /// The current iterate of the state at `tₙ₊₁` (slaves placed exactly).
    pub end: MechanismState,
    pub dt: f64,
    pub scheme: Scheme,
    /// The paper's energy–momentum β (0 for the other schemes).
    pub beta: f64,
    /// External nodal forces at `tₙ₊½`.
    pub fext: Vec<f64>,
    pub nodal: Vec<f64>,
    /// Magnitudes of the internal and inertial contributions (residual scale).
    pub inertia_abs: Vec<f64>,
    pub scratch: Vec<f64>,
    /// Tangent positions of the mass blocks.
    pub(crate) slots: &'a MassSlots,
    pub floor: f64,
}

impl MidpointStep<'_> {
    /// The reduced residual `Ñᵀ g` of nodal residuals `g` (plain `Tᵀ g`
    /// without joints).
    pub fn reduce_residual(&self, g: &[f64], out: &mut [f64]) {
        self.topo
            .reduce_incremental(self.mech, self.start, &self.end, g, out);
    }
}

impl MidpointStep<'_> {
    /// The residual into `r` (returns the force scale) and, if `tangent`,
    /// the tangent values.
    fn evaluate_with(&mut self, r: &mut [f64], tangent: bool) -> f64 {
        self.topo.refresh(self.mech, &self.end);
        if !self.mech.joints.is_empty() {
            self.topo.refresh_rows(self.mech, self.start, &self.end);
        }
        let (start, end) = (&self.start.config, &self.end.config);
        let (scheme, beta) = (self.scheme, self.beta);
        if tangent {
            self.asm
                .assemble_with(&self.mech.mesh, &self.topo.dofs, |el, _, re, ke| {
                    element_kernel(el, start, end, scheme, beta, re, ke)
                });
        } else {
            self.asm.assemble_residual_with(&self.mech.mesh, |el, re| {
                element_force(el, start, end, scheme, beta, re)
            });
        }
        let dt = self.dt;
        for (g, (fi, fe)) in self
            .nodal
            .iter_mut()
            .zip(self.asm.nodal.iter().zip(&self.fext))
        {
            *g = fi - fe;
        }
        // Translational inertia: Σⱼ m_ij (vⱼ,ₙ₊₁ − vⱼ,ₙ)/Δt, vₙ₊₁ = 2(xₙ₊₁ − xₙ)/Δt − vₙ.
        self.inertia_abs.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..self.inertia.mass.len() {
            let (i, j, m) = self.inertia.mass[k];
            let dv =
                (self.end.config.x[j] - self.start.config.x[j]) * (2.0 / dt) - self.v_n[j] * 2.0;
            for c in 0..3 {
                self.nodal[6 * i + c] += m * dv[c] / dt;
                self.inertia_abs[6 * i + c] += (m * dv[c] / dt).abs();
            }
            if tangent {
                let block = Matrix3::identity() * (2.0 * m / (dt * dt));
                self.slots
                    .add_translational(self.asm, &self.topo.dofs, k, (i, j), &block);
            }
        }
        // Rotational inertia, node by node.
        for i in 0..self.inertia.rotational.len() {
            let j0 = self.inertia.rotational[i];
            if j0 == Matrix3::zeros() {
                continue;
            }
            let (m, k) = inertial_moment(
                &j0,
                &self.start.config.rot[i],
                &self.end.config.rot[i],
                &self.w_n[i],
                dt,
                tangent,
            );
            for c in 0..3 {
                self.nodal[6 * i + 3 + c] += m[c];
                self.inertia_abs[6 * i + 3 + c] += m[c].abs();
            }
            if tangent {
                self.slots.add_rotational(self.asm, &self.topo.dofs, i, &k);
            }
        }
        self.reduce_residual(&self.nodal, r);
        if tangent && !self.mech.joints.is_empty() {
            // ∂(Ñᵀ)/∂q g with the slaves' full residuals (see the module docs).
            let blocks =
                self.topo
                    .incremental_blocks(self.mech, self.start, &self.end, &self.nodal);
            for (b, block) in blocks.iter().enumerate() {
                self.asm.add_block(b, block);
            }
        }
        for (a, b) in self.inertia_abs.iter_mut().zip(&self.asm.nodal_abs) {
            *a += b;
        }
        let dofs = &self.topo.dofs;
        let f_ext = dofs.reduced_norm(&self.fext, &mut self.scratch);
        f_ext.max(dofs.reduced_norm(&self.inertia_abs, &mut self.scratch))
    }
}

impl NewtonSystem for MidpointStep<'_> {
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

/// Runs a midpoint scheme from `initial` over `[0, t_end]`, reporting a record
/// at t = 0 and after every converged step. Beams of 2-node elements; joints
/// through `Ñ`, driven joint coordinates and prescribed DOFs follow their
/// schedules (their work enters the energy balance as external work).
pub fn solve(
    mech: &Mechanism,
    settings: &DynamicSettings,
    initial: &Motion,
    scheme: Scheme,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    if scheme == Scheme::EnergyMomentumPaper
        && mech
            .mesh
            .elements
            .iter()
            .any(|e| !matches!(e, Element::Linear(_)))
    {
        return Err(SolveError::InvalidMechanism(
            "the paper's energy-momentum scheme needs 2-node elements".into(),
        ));
    }
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
    let (mut v, mut w) = slave_velocities(mech, &topo, &state, initial);
    // Rates of the released coordinates, for the predictor.
    let mut rates: Vec<Vec<f64>> = mech
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let mut rate = vec![0.0; joint.map.released_count()];
            if let Some(r0) = rate.first_mut() {
                *r0 = initial.joint_rates.get(j).copied().unwrap_or(0.0);
            }
            rate
        })
        .collect();
    let mut fext = vec![0.0; 6 * nodes];
    mech.external_forces(0.0, &mut fext);
    let record = |state: &MechanismState,
                  v: &[Vector3<f64>],
                  w: &[Vector3<f64>],
                  fext: &[f64],
                  t: f64,
                  dt: f64,
                  rep: Option<&NewtonReport>| {
        let mut rec = dynamic_record(mech, &inertia, &state.config, v, w, fext, t, dt, rep);
        rec.joints = joint_records(mech, state);
        rec
    };
    on_step(&record(&state, &v, &w, &fext, 0.0, 0.0, None));
    let (mut t, mut control) = (
        0.0f64,
        StepControl::with(settings.dt, settings.max_halvings, GROW_AFTER),
    );
    let mut driver_work = 0.0;
    while t < settings.t_end * (1.0 - 1e-12) {
        let dt = control.next(t, settings.t_end);
        // Predictor: constant velocities over the step.
        let mut end = state.clone();
        for i in 0..nodes {
            if !mech.fixed[i].iter().any(|&h| h) && topo.slave_of[i].is_none() {
                let spin = state.config.rot[i] * w[i] * dt;
                end.config.increment(i, &(v[i] * dt), &spin);
            }
        }
        for (j, joint) in mech.joints.iter().enumerate() {
            let delta: Vec<f64> = rates[j].iter().map(|r| r * dt).collect();
            if delta.iter().any(|&d| d != 0.0) {
                joint.map.advance(&mut end.released[j], &delta);
            }
        }
        topo.impose(mech, &mut end, t + dt);
        let mut fmid = vec![0.0; 6 * nodes];
        mech.external_forces(t + 0.5 * dt, &mut fmid);
        let mut sys = MidpointStep {
            mech,
            topo: &mut topo,
            inertia: &inertia,
            asm: &mut asm,
            start: &state,
            v_n: &v,
            w_n: &w,
            end,
            dt,
            scheme,
            beta: 0.0,
            fext: fmid,
            nodal: vec![0.0; 6 * nodes],
            inertia_abs: vec![0.0; 6 * nodes],
            scratch: vec![0.0; n_eq],
            slots: &slots,
            floor: mech.round_off_floor_at(&state.config.x),
        };
        let outcome = match scheme {
            Scheme::Momentum => newton::solve(&mut sys, &mut lu, &settings.newton, &mut r, &mut dq)
                .map(|rep| (rep, f64::NAN)),
            Scheme::EnergyMomentum => {
                newton::solve(&mut sys, &mut lu, &settings.newton, &mut r, &mut dq).map(|rep| {
                    let size = correction_size(mech, &sys.start.config, &sys.end.config);
                    (rep, size)
                })
            }
            Scheme::EnergyMomentumPaper => {
                super::energy_momentum_paper::solve_step(&mut sys, &mut lu, &settings.newton)
            }
        };
        match outcome {
            Ok((report, beta)) => {
                if let Err(objection) = guard.accept(mech, &sys.end, t + dt) {
                    control.failed(t + dt, as_step_failure(objection)?)?;
                    continue;
                }
                // The drivers' work: exact for these schemes (Σ pᵢ·gᵢ = ΔH − W_loads).
                driver_work += increment_work(&state.config, &sys.end.config, &sys.nodal, true);
                let end = sys.end;
                let (v1, w1) = end_motion(&state.config, &end.config, &v, &w, dt);
                for (j, rate) in rates.iter_mut().enumerate() {
                    *rate = released_rate(&state.released[j], &end.released[j], rate.len(), dt);
                }
                state = end;
                v = v1;
                w = w1;
                t = control.advance(t, dt);
                mech.external_forces(t, &mut fext);
                let mut rec = record(&state, &v, &w, &fext, t, dt, Some(&report));
                rec.beta = beta;
                rec.energy.driver_work = driver_work;
                on_step(&rec);
                control.succeeded();
            }
            Err(reason) => control.failed(t + dt, reason)?,
        }
    }
    Ok(state.config)
}

/// The rate of a joint's released coordinates over a step: additive
/// coordinates by their difference, a multiplicative released rotation by
/// the spin between its two values.
fn released_rate(
    a: &flexmech_joints::ReleasedState,
    b: &flexmech_joints::ReleasedState,
    count: usize,
    dt: f64,
) -> Vec<f64> {
    if a.rot != b.rot {
        let spin = log(&(b.rot * a.rot.transpose())) / dt;
        return vec![spin.x, spin.y, spin.z];
    }
    (0..count).map(|c| (b.q[c] - a.q[c]) / dt).collect()
}

/// A record with energies (kinetic, strain, potential of the external forces
/// `−Σ f·u` — gravity included — and their sum) and momenta.
#[allow(clippy::too_many_arguments)]
pub fn dynamic_record(
    mech: &Mechanism,
    inertia: &Inertia,
    config: &Configuration,
    v: &[Vector3<f64>],
    w: &[Vector3<f64>],
    fext: &[f64],
    time: f64,
    dt: f64,
    report: Option<&NewtonReport>,
) -> StepRecord {
    let kinetic = inertia.kinetic_energy(v, w);
    let strain = strain_energy(mech, config);
    let potential: f64 = -(0..config.x.len())
        .map(|n| {
            (config.x[n] - mech.mesh.positions[n]).dot(&Vector3::new(
                fext[6 * n],
                fext[6 * n + 1],
                fext[6 * n + 2],
            ))
        })
        .sum::<f64>();
    let lin = inertia.linear_momentum(v);
    let ang = inertia.angular_momentum(&config.x, &config.rot, v, w);
    StepRecord {
        time,
        dt,
        iterations: report.map_or(0, |r| r.iterations),
        factorizations: report.map_or(0, |r| r.factorizations),
        residual: report.map_or(0.0, |r| r.residual),
        residual_history: report.map_or_else(Vec::new, |r| r.history.clone()),
        beta: f64::NAN,
        energy: Energies {
            kinetic,
            strain,
            potential,
            total: kinetic + strain + potential,
            driver_work: 0.0,
        },
        negative_pivots: None,
        momentum_linear: [lin.x, lin.y, lin.z],
        momentum_angular: [ang.x, ang.y, ang.z],
        positions: config.x.iter().map(|x| [x.x, x.y, x.z]).collect(),
        quaternions: (0..config.x.len())
            .map(|i| {
                let q = config.quaternion(i);
                [q.x, q.y, q.z, q.w]
            })
            .collect(),
        joints: Vec::new(),
    }
}
