//! Newmark's trapezoidal rule (β = ¼, γ = ½) on SO(3) as terms of the
//! shared reduced system (see [`super::newmark`] for the scheme).

use super::checkpoint::{CheckpointMismatch, Tape};
use super::mass_slots::{spin_derivative, MassSlots};
use super::slave_velocities;
use super::time_scheme::TimeScheme;
use super::Motion;
use crate::assembly::Assembler;
use crate::constraints::{MechanismState, Topology};
use crate::dofs::DofMap;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::system::{ReducedSystem, Reduction, StepTerms};
use flexmech_core::rotation::log;
use flexmech_core::{Configuration, Inertia};
use nalgebra::{Matrix3, Vector3};

const BETA: f64 = 0.25;
const GAMMA: f64 = 0.5;

/// Velocities and accelerations at the end of a step.
#[derive(Debug, Clone)]
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

/// Newmark's terms of the reduced system: the beams' internal forces at
/// `tₙ₊₁`, the inertial forces `M aₙ₊₁` and `Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)`
/// with their tangents, joints through `N`.
pub(crate) struct NewmarkTerms {
    inertia: Inertia,
    slots: MassSlots,
    /// Velocities and accelerations at the start of the step.
    prev: Kinematics,
    dt: f64,
    /// The drivers' reactions at the end of the last accepted step.
    reactions: Option<(Vec<Vec<f64>>, Vec<f64>)>,
}

impl NewmarkTerms {
    /// The terms at t = 0: slave velocities through `N`, accelerations from
    /// the equations of motion ([`initial_accelerations`]; `asm` and `lu`
    /// serve as scratch).
    pub(crate) fn new(
        mech: &Mechanism,
        topo: &Topology,
        asm: &mut Assembler,
        lu: &mut SparseLu,
        state: &MechanismState,
        inertia: Inertia,
        initial: &Motion,
    ) -> Self {
        let nodes = mech.mesh.node_count();
        let slots = MassSlots::new(asm, &topo.dofs, &inertia);
        let mut fext = vec![0.0; 6 * nodes];
        mech.external_forces(0.0, &mut fext);
        asm.assemble(&mech.mesh, &topo.dofs, &state.config);
        let residual: Vec<f64> = asm.nodal.iter().zip(&fext).map(|(a, b)| a - b).collect();
        let (v, w) = slave_velocities(mech, topo, state, initial);
        let (a, alpha) = initial_accelerations(mech, topo, &inertia, asm, lu, state, &residual);
        Self {
            inertia,
            slots,
            prev: Kinematics { v, a, w, alpha },
            dt: f64::NAN,
            reactions: None,
        }
    }
}

impl StepTerms for NewmarkTerms {
    fn reduction(&self) -> Reduction {
        Reduction::Variation
    }

    fn inertia(
        &self,
        start: &Configuration,
        end: &Configuration,
        g: &mut [f64],
        abs: &mut [f64],
        tangent: Option<(&mut Assembler, &DofMap)>,
    ) {
        let (dt, prev) = (self.dt, &self.prev);
        // Translational inertia M aₙ₊₁, aₙ₊₁ = (u − Δt vₙ − Δt²(½−β)aₙ)/(βΔt²);
        // rotational Rₙ₊₁(J₀Aₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁), its tangent by AD in a
        // spin of Rₙ₊₁.
        self.slots.add_inertia(
            &self.inertia,
            g,
            abs,
            tangent,
            |j, m| {
                let u = end.x[j] - start.x[j];
                let a1 =
                    (u - prev.v[j] * dt - prev.a[j] * (dt * dt * (0.5 - BETA))) / (BETA * dt * dt);
                a1.map(|a| m * a)
            },
            |m| m / (BETA * dt * dt),
            |i, j0, tangent| {
                spin_derivative(
                    &end.rot[i],
                    tangent,
                    |r1| inertial_moment(j0, &start.rot[i], r1, prev, i, dt),
                    |r1| inertial_moment(j0, &start.rot[i], r1, prev, i, dt),
                )
            },
        );
    }

    fn tangent_key(&self) -> f64 {
        self.dt
    }
}

impl TimeScheme for NewmarkTerms {
    fn set_step(&mut self, dt: f64) {
        self.dt = dt;
    }

    fn load_time(&self, t: f64, dt: f64) -> f64 {
        t + dt
    }

    fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        (&self.prev.v, &self.prev.w)
    }

    fn mass(&self) -> &Inertia {
        &self.inertia
    }

    /// `v, a, W, A`, the step size, and the drivers' reactions at the last
    /// accepted state (flag 1 and per joint then prescribed, or flag 0).
    fn save(&self, tape: &mut Tape) {
        for vs in [&self.prev.v, &self.prev.a, &self.prev.w, &self.prev.alpha] {
            tape.put_vectors(vs);
        }
        tape.put(self.dt);
        match &self.reactions {
            None => tape.put(0.0),
            Some((joints, prescribed)) => {
                tape.put(1.0);
                tape.put(joints.len() as f64);
                for r in joints {
                    tape.put_list(r);
                }
                tape.put_list(prescribed);
            }
        }
    }

    fn restore(&mut self, mech: &Mechanism, tape: &mut Tape) -> Result<(), CheckpointMismatch> {
        let n = mech.mesh.node_count();
        self.prev = Kinematics {
            v: tape.take_vectors("velocities", n)?,
            a: tape.take_vectors("accelerations", n)?,
            w: tape.take_vectors("angular velocities", n)?,
            alpha: tape.take_vectors("angular accelerations", n)?,
        };
        self.dt = tape.take()?;
        self.reactions = if tape.take()? == 0.0 {
            None
        } else {
            let joints = tape.take_count("joints with reactions", Some(mech.joints.len()))?;
            let rs = (0..joints)
                .map(|_| tape.take_list("a joint's reactions", None))
                .collect::<Result<Vec<_>, _>>()?;
            Some((rs, tape.take_list("prescribed DOFs' reactions", None)?))
        };
        tape.done()
    }

    /// Newmark's updates of velocities and accelerations; the drivers' work
    /// by the trapezoidal rule on their reactions at both ends of the step
    /// (the first step uses its end value twice).
    fn finish(sys: &mut ReducedSystem<'_, Self>, dt: f64) -> f64 {
        let r_end = sys.topo.driver_reactions(sys.mech, &sys.end, &sys.nodal);
        let r_start = sys.terms.reactions.take().unwrap_or_else(|| r_end.clone());
        let work = driver_increment_work(sys.mech, &sys.start, &sys.end, &r_start, &r_end);
        sys.terms.reactions = Some(r_end);
        let (start, end) = (&sys.start.config, &sys.end.config);
        let kin = &mut sys.terms.prev;
        for i in 0..start.x.len() {
            let u = end.x[i] - start.x[i];
            let a1 = (u - kin.v[i] * dt - kin.a[i] * (dt * dt * (0.5 - BETA))) / (BETA * dt * dt);
            kin.v[i] += (kin.a[i] * (1.0 - GAMMA) + a1 * GAMMA) * dt;
            kin.a[i] = a1;
            let al: Vector3<f64> =
                angular_acceleration(&start.rot[i], &end.rot[i], &kin.w[i], &kin.alpha[i], dt);
            kin.w[i] += (kin.alpha[i] * (1.0 - GAMMA) + al * GAMMA) * dt;
            kin.alpha[i] = al;
        }
        work
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
