//! The Newmark family on SO(3) as terms of the shared reduced system:
//! the trapezoidal rule (β = ¼, γ = ½, see [`super::newmark`]) and its
//! generalized-α extension (see [`super::generalized_alpha`]), which adds
//! the pseudo-acceleration average of Arnold & Brüls (2007) and reduces to
//! the trapezoidal rule bit for bit when `α_m = α_f = 0`.

use super::checkpoint::{CheckpointMismatch, Tape};
use super::inertia_pairs::{
    angular_acceleration_pair, in_node_pairs_into, moments_in_pairs_into, newmark_moment_pair,
    newmark_tangent_pair,
};
use super::mass_slots::MassSlots;
use super::newmark_sensitivity::NewmarkSensitivities;
use super::slave_velocities;
use super::time_scheme::{SchemeSensitivities, TimeScheme};
use super::Motion;
use crate::assembly::Assembler;
use crate::constraints::{MechanismState, Topology};
use crate::dofs::DofMap;
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::record::Sensitivity;
use crate::sensitivity::Parameter;
use crate::system::{ReducedSystem, Reduction, StepTerms};
use flexmech_core::rotation::{log, tangent_inverse};
use flexmech_core::{Configuration, Element, Inertia};
use nalgebra::{Matrix3, Vector3};
use std::sync::Mutex;

/// The coefficients of a Newmark-family scheme: Newmark's `β`, `γ` and the
/// generalized-α weights `α_m`, `α_f` of the pseudo-acceleration `a`,
/// `(1 − α_m) aₙ₊₁ + α_m aₙ = (1 − α_f) q̈ₙ₊₁ + α_f q̈ₙ` (Arnold & Brüls 2007,
/// eq. 8; FORMULATION §4.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Newmark's `β`.
    pub beta: f64,
    /// Newmark's `γ`.
    pub gamma: f64,
    /// Weight of the previous pseudo-acceleration.
    pub alpha_m: f64,
    /// Weight of the previous acceleration.
    pub alpha_f: f64,
    /// The spectral radius at infinite frequency they were made from
    /// (`None`: the trapezoidal rule).
    pub rho_inf: Option<f64>,
}

impl Coefficients {
    /// The trapezoidal rule: `β = ¼`, `γ = ½`, `α_m = α_f = 0`.
    pub const TRAPEZOIDAL: Self = Self {
        beta: 0.25,
        gamma: 0.5,
        alpha_m: 0.0,
        alpha_f: 0.0,
        rho_inf: None,
    };

    /// Chung & Hulbert's optimal choice for the spectral radius `ρ∞` at
    /// infinite frequency (`0 ≤ ρ∞ ≤ 1`): `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`,
    /// `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ + α_f − α_m`, `β = ¼(γ + ½)²` —
    /// second-order accurate, unconditionally stable for linear problems,
    /// high frequencies damped to `ρ∞` per step.
    pub fn generalized_alpha(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Self {
            beta: 0.25 * (gamma + 0.5).powi(2),
            gamma,
            alpha_m,
            alpha_f,
            rho_inf: Some(rho_inf),
        }
    }

    /// The acceleration `q̈ₙ₊₁` from the pseudo-accelerations `aₙ₊₁`, `aₙ`
    /// and the previous acceleration `q̈ₙ` (generic, for AD).
    fn acceleration<T: flexmech_core::Scalar>(
        &self,
        a1: Vector3<T>,
        a_n: &Vector3<f64>,
        acc_n: &Vector3<f64>,
    ) -> Vector3<T> {
        let c = |x: f64| T::from_subset(&x);
        let history = a_n * self.alpha_m - acc_n * self.alpha_f;
        (a1 * c(1.0 - self.alpha_m) + history.map(c)) / c(1.0 - self.alpha_f)
    }

    /// `∂q̈ₙ₊₁/∂uₙ₊₁ = (1 − α_m)/((1 − α_f) β Δt²)`: the tangent of the
    /// inertial force per unit mass.
    fn stiffness(&self, dt: f64) -> f64 {
        (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * dt * dt)
    }
}

/// Velocities, pseudo-accelerations (`a`, `alpha`) and accelerations (`acc`,
/// `ang_acc`) at the end of a step; the trapezoidal rule keeps `a = acc`.
#[derive(Debug, Clone)]
pub(super) struct Kinematics {
    pub(super) v: Vec<Vector3<f64>>,
    pub(super) a: Vec<Vector3<f64>>,
    pub(super) w: Vec<Vector3<f64>>,
    pub(super) alpha: Vec<Vector3<f64>>,
    pub(super) acc: Vec<Vector3<f64>>,
    pub(super) ang_acc: Vec<Vector3<f64>>,
}

/// Translational pseudo-acceleration at `n+1` for the displacement `u` of
/// the step: `aₙ₊₁ = (u − Δt vₙ − Δt²(½ − β) aₙ)/(β Δt²)`.
fn pseudo_acceleration(
    k: &Coefficients,
    u: Vector3<f64>,
    v_n: &Vector3<f64>,
    a_n: &Vector3<f64>,
    dt: f64,
) -> Vector3<f64> {
    (u - v_n * dt - a_n * (dt * dt * (0.5 - k.beta))) / (k.beta * dt * dt)
}

/// Body angular pseudo-acceleration at `n+1` for the end rotation `r1`,
/// with the body increment `Ω = Rₙᵀ log(Rₙ₊₁Rₙᵀ)` (generic, for AD).
pub(super) fn angular_acceleration<T: flexmech_core::Scalar>(
    k: &Coefficients,
    r_n: &Matrix3<f64>,
    r1: &Matrix3<T>,
    w_n: &Vector3<f64>,
    a_n: &Vector3<f64>,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let omega = log(&(r1 * r_n.map(c).transpose()));
    acceleration_of_increment(k, r_n, omega, w_n, a_n, dt)
}

/// [`angular_acceleration`] from the spatial increment `ω = log(Rₙ₊₁Rₙᵀ)`.
fn acceleration_of_increment<T: flexmech_core::Scalar>(
    k: &Coefficients,
    r_n: &Matrix3<f64>,
    omega: Vector3<T>,
    w_n: &Vector3<f64>,
    a_n: &Vector3<f64>,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let big_omega = r_n.map(c).transpose() * omega;
    (big_omega - w_n.map(c) * c(dt) - a_n.map(c) * c(dt * dt * (0.5 - k.beta)))
        / c(k.beta * dt * dt)
}

/// Inertial moment `Rₙ₊₁(J₀Ȧₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)` of node `i` for the end
/// rotation `r1`, `Ȧ` the body angular acceleration (generic, for AD).
pub(super) fn inertial_moment<T: flexmech_core::Scalar>(
    k: &Coefficients,
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r1: &Matrix3<T>,
    prev: &Kinematics,
    i: usize,
    dt: f64,
) -> Vector3<T> {
    let c = |x: f64| T::from_subset(&x);
    let a1 = angular_acceleration(k, r_n, r1, &prev.w[i], &prev.alpha[i], dt);
    let w1 = (prev.w[i] + prev.alpha[i] * (dt * (1.0 - k.gamma))).map(c) + a1 * c(dt * k.gamma);
    let acc1 = k.acceleration(a1, &prev.alpha[i], &prev.ang_acc[i]);
    let jd = j0.map(c);
    *r1 * (jd * acc1 + w1.cross(&(jd * w1)))
}

/// [`inertial_moment`] and its derivative under a spatial spin of the end
/// rotation (`R₁ ← exp(η̂)R₁`), in closed form: with `ω = log(R₁Rₙᵀ)`,
/// `δω = H⁻¹(ω)η`, so `δaₙ₊₁ = RₙᵀH⁻¹(ω)η/(βΔt²)`, `δWₙ₊₁ = γΔt δaₙ₊₁`,
/// `δȦₙ₊₁ = (1 − α_m)/(1 − α_f) δaₙ₊₁`, and with `v = J₀Ȧ + W × J₀W`,
///
/// ```text
/// ∂m/∂η = −m̂ + R₁ [ (1 − α_m)/(1 − α_f) J₀ + γΔt (ŴJ₀ − (J₀W)^) ] RₙᵀH⁻¹(ω)/(βΔt²)
/// ```
///
/// equal to forward AD of [`inertial_moment`] to round-off (tested).
pub(super) fn inertial_moment_tangent(
    k: &Coefficients,
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r1: &Matrix3<f64>,
    prev: &Kinematics,
    i: usize,
    dt: f64,
) -> (Vector3<f64>, Matrix3<f64>) {
    let omega = log(&(r1 * r_n.transpose()));
    let a1 = acceleration_of_increment(k, r_n, omega, &prev.w[i], &prev.alpha[i], dt);
    let w1 = prev.w[i] + prev.alpha[i] * (dt * (1.0 - k.gamma)) + a1 * (dt * k.gamma);
    let acc1 = k.acceleration(a1, &prev.alpha[i], &prev.ang_acc[i]);
    let jw = j0 * w1;
    let m = r1 * (j0 * acc1 + w1.cross(&jw));
    let dv_da = j0 * ((1.0 - k.alpha_m) / (1.0 - k.alpha_f))
        + (w1.cross_matrix() * j0 - jw.cross_matrix()) * (k.gamma * dt);
    let da_deta = r_n.transpose() * tangent_inverse(&omega) / (k.beta * dt * dt);
    (m, -m.cross_matrix() + r1 * dv_da * da_deta)
}

/// The Newmark family's terms of the reduced system: the beams' internal
/// forces at `tₙ₊₁`, the inertial forces `M q̈ₙ₊₁` and
/// `Rₙ₊₁(J₀Ȧₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁)` with their tangents, joints through `N`.
pub(crate) struct NewmarkTerms {
    pub(super) coefficients: Coefficients,
    /// The damped elements and their damping times `η`.
    pub(super) damped: Vec<(Element, f64)>,
    /// Energy dissipated by damping since t = 0.
    dissipated: f64,
    /// Each damped element's damping force (`6N`) at the last accepted
    /// state, for the next step's work (empty at t = 0: the initial
    /// accelerations leave the damping out).
    damping_forces: Vec<Vec<f64>>,
    pub(super) inertia: Inertia,
    slots: MassSlots,
    /// Velocities and accelerations at the start of the step.
    pub(super) prev: Kinematics,
    /// The joints' initial rates (of their first released coordinate).
    pub(super) initial_rates: Vec<f64>,
    /// Every joint's released rates over the last step (its coordinates'
    /// increments over the step size): the predictor carries them on, as
    /// it carries the nodes' velocities.
    rates: Vec<Vec<f64>>,
    pub(super) dt: f64,
    /// The drivers' reactions at the end of the last accepted step.
    reactions: Option<(Vec<Vec<f64>>, Vec<f64>)>,
    /// The rotational inertia's node pairs of the last evaluation, kept for
    /// their allocations: moments, or moments with their tangents.
    pairs: Mutex<NodePairs>,
}

/// Node pairs' values ([`in_node_pairs_into`]): node `i`'s is `[i / 2][i % 2]`.
#[derive(Default)]
struct NodePairs {
    moments: Vec<[Vector3<f64>; 2]>,
    tangents: Vec<[(Vector3<f64>, Matrix3<f64>); 2]>,
}

impl NewmarkTerms {
    /// The terms at t = 0: slave velocities through `N`, accelerations from
    /// the equations of motion ([`initial_accelerations`]; `asm` and `lu`
    /// serve as scratch).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        mech: &Mechanism,
        topo: &Topology,
        asm: &mut Assembler,
        lu: &mut SparseLu,
        state: &MechanismState,
        inertia: Inertia,
        initial: &Motion,
        coefficients: Coefficients,
    ) -> Self {
        let nodes = mech.mesh.node_count();
        let slots = MassSlots::new(asm, &topo.dofs, &inertia);
        let mut fext = vec![0.0; 6 * nodes];
        mech.external_forces(0.0, &mut fext);
        // The forces only: the tangent's values are the mass's next.
        asm.assemble_residual(&mech.mesh, &state.config);
        let residual: Vec<f64> = asm.nodal.iter().zip(&fext).map(|(a, b)| a - b).collect();
        let (v, w) = slave_velocities(mech, topo, state, initial);
        let (a, alpha, _) =
            initial_accelerations(mech, topo, &inertia, asm, lu, state, &residual, None);
        let damped = mech
            .damped_elements()
            .into_iter()
            .map(|(e, eta)| (mech.mesh.elements[e].clone(), eta))
            .collect();
        Self {
            coefficients,
            damped,
            dissipated: 0.0,
            damping_forces: Vec::new(),
            inertia,
            slots,
            prev: Kinematics {
                v,
                acc: a.clone(),
                a,
                w,
                ang_acc: alpha.clone(),
                alpha,
            },
            dt: f64::NAN,
            reactions: None,
            pairs: Mutex::default(),
            initial_rates: initial.joint_rates.clone(),
            rates: super::midpoint::initial_released_rates(mech, initial),
        }
    }
}

impl NewmarkTerms {
    /// The Kelvin–Voigt damping forces of the step `start → end` in the
    /// nodal residual `g` (magnitudes in `abs`) and, with `tangent`, their
    /// element tangents through the node maps.
    fn add_damping(
        &self,
        start: &Configuration,
        end: &Configuration,
        g: &mut [f64],
        abs: &mut [f64],
        mut tangent: Option<(&mut Assembler, &DofMap)>,
    ) {
        for (e, eta) in &self.damped {
            let nodes = e.nodes();
            let n = 6 * nodes.len();
            let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
            e.damping_residual_tangent(
                (&start.x, &start.rot),
                (&end.x, &end.rot),
                eta / self.dt,
                &mut r,
                &mut k,
            );
            for (a, &na) in nodes.iter().enumerate() {
                for c in 0..6 {
                    g[6 * na + c] += r[6 * a + c];
                    abs[6 * na + c] += r[6 * a + c].abs();
                }
            }
            if let Some((asm, dofs)) = tangent.as_mut() {
                for (a, &na) in nodes.iter().enumerate() {
                    for (b, &nb) in nodes.iter().enumerate() {
                        for (ra, cb) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
                            // Column-major n × n: entry (row, col) at col·n + row.
                            let block =
                                Matrix3::from_fn(|i, j| k[(6 * b + cb + j) * n + 6 * a + ra + i]);
                            asm.add_node_block(dofs, (na, ra), (nb, cb), &block);
                        }
                    }
                }
            }
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
        let (dt, prev, k) = (self.dt, &self.prev, &self.coefficients);
        let mut tangent = tangent;
        if !self.damped.is_empty() {
            let blocks = tangent.as_mut().map(|(asm, dofs)| (&mut **asm, *dofs));
            self.add_damping(start, end, g, abs, blocks);
        }
        // Translational inertia M q̈ₙ₊₁ from the pseudo-acceleration
        // aₙ₊₁ = (u − Δt vₙ − Δt²(½−β)aₙ)/(βΔt²); rotational
        // Rₙ₊₁(J₀Ȧₙ₊₁ + Wₙ₊₁ × J₀Wₙ₊₁), its tangent in closed form in a spin of
        // Rₙ₊₁ ([`inertial_moment_tangent`]). Both two nodes at a time
        // (`inertia_pairs`, the same bits).
        let j0 = &self.inertia.rotational;
        let mut pairs = crate::threads::lock(&self.pairs);
        let NodePairs { moments, tangents } = &mut *pairs;
        if tangent.is_none() {
            moments_in_pairs_into(
                j0,
                |i| inertial_moment(k, &j0[i], &start.rot[i], &end.rot[i], prev, i, dt),
                |i| {
                    Some(newmark_moment_pair(
                        k,
                        (j0, &start.rot, &end.rot),
                        prev,
                        i,
                        dt,
                    ))
                },
                moments,
            );
        } else {
            in_node_pairs_into(
                j0,
                |i| inertial_moment_tangent(k, &j0[i], &start.rot[i], &end.rot[i], prev, i, dt),
                |i| {
                    let rotary = (&j0[..], &start.rot[..], &end.rot[..]);
                    Some(newmark_tangent_pair(k, rotary, prev, i, dt))
                },
                tangents,
            );
        }
        let (moments, tangents) = (&*moments, &*tangents);
        let with_tangent = tangent.is_some();
        self.slots.add_inertia(
            &self.inertia,
            g,
            abs,
            tangent,
            |j| {
                let a1 = pseudo_acceleration(k, end.x[j] - start.x[j], &prev.v[j], &prev.a[j], dt);
                k.acceleration(a1, &prev.a[j], &prev.acc[j])
            },
            |m, a| a.map(|a| m * a),
            k.stiffness(dt),
            |i, j0, tangent| match (tangent, with_tangent) {
                (true, _) => tangents[i / 2][i % 2],
                (false, false) => (moments[i / 2][i % 2], Matrix3::zeros()),
                (false, true) => {
                    let m = inertial_moment(k, j0, &start.rot[i], &end.rot[i], prev, i, dt);
                    (m, Matrix3::zeros())
                }
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

    fn joint_rates(&self) -> &[Vec<f64>] {
        &self.rates
    }

    fn mass(&self) -> &Inertia {
        &self.inertia
    }

    fn dissipated(&self) -> f64 {
        self.dissipated
    }

    /// `v, a, W, A`, the step size, and the drivers' reactions at the last
    /// accepted state (flag 1 and per joint then prescribed, or flag 0); the
    /// generalized-α scheme then adds `ρ∞` and the accelerations `q̈`, `Ȧ`
    /// (the trapezoidal rule's have `a = q̈`).
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
        if let Some(rho_inf) = self.coefficients.rho_inf {
            tape.put(rho_inf);
            tape.put_vectors(&self.prev.acc);
            tape.put_vectors(&self.prev.ang_acc);
        }
        if !self.damped.is_empty() {
            tape.put(self.dissipated);
        }
        tape.put(self.rates.len() as f64);
        for r in &self.rates {
            tape.put_list(r);
        }
        if !self.damped.is_empty() {
            tape.put(self.damping_forces.len() as f64);
            for f in &self.damping_forces {
                tape.put_list(f);
            }
        }
    }

    fn restore(&mut self, mech: &Mechanism, tape: &mut Tape) -> Result<(), CheckpointMismatch> {
        let n = mech.mesh.node_count();
        let v = tape.take_vectors("velocities", n)?;
        let a = tape.take_vectors("accelerations", n)?;
        let w = tape.take_vectors("angular velocities", n)?;
        let alpha = tape.take_vectors("angular accelerations", n)?;
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
        let (acc, ang_acc) = match self.coefficients.rho_inf {
            None => (a.clone(), alpha.clone()),
            Some(rho_inf) => {
                let saved = tape.take()?;
                if saved != rho_inf {
                    return Err(CheckpointMismatch(format!(
                        "the saved run used rho_inf = {saved}, this one {rho_inf}"
                    )));
                }
                (
                    tape.take_vectors("accelerations q̈", n)?,
                    tape.take_vectors("angular accelerations Ȧ", n)?,
                )
            }
        };
        self.prev = Kinematics {
            v,
            a,
            w,
            alpha,
            acc,
            ang_acc,
        };
        if !self.damped.is_empty() {
            self.dissipated = tape.take()?;
        }
        // Checkpoints written before the released rates were carried end
        // here: the predictor then starts the joints from rest.
        if !tape.is_done() {
            let joints = tape.take_count("joints", Some(mech.joints.len()))?;
            self.rates = (0..joints)
                .map(|j| {
                    tape.take_list("a joint's rates", Some(mech.joints[j].map.released_count()))
                })
                .collect::<Result<Vec<_>, _>>()?;
        } else {
            self.rates.iter_mut().flatten().for_each(|r| *r = 0.0);
        }
        // Checkpoints written before the damping forces were carried end
        // here: the next step's work then takes them as zero at its start.
        self.damping_forces = if !self.damped.is_empty() && !tape.is_done() {
            // None before the first step, else one per damped element.
            let count = tape.take_count("damped elements' forces", None)?;
            if count != 0 && count != self.damped.len() {
                return Err(CheckpointMismatch(format!(
                    "the saved run has {count} damped elements' forces, this one {} damped elements",
                    self.damped.len()
                )));
            }
            (0..count)
                .map(|_| tape.take_list("a damped element's force", None))
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        tape.done()
    }

    fn sensitivities(
        sys: &mut ReducedSystem<'_, Self>,
        params: &[Parameter],
        mass: flexmech_core::MassKind,
    ) -> Result<SchemeSensitivities, SolveError> {
        NewmarkSensitivities::new(sys, params, mass).map(SchemeSensitivities::Newmark)
    }

    fn sensitivity_step(
        sys: &mut ReducedSystem<'_, Self>,
        sens: &mut SchemeSensitivities,
        fext_end: &[f64],
    ) -> Result<Vec<Sensitivity>, SolveError> {
        match sens {
            SchemeSensitivities::Newmark(s) => s.step(sys, fext_end),
            _ => Err(SolveError::InvalidMechanism(
                "sensitivities set up for another scheme".into(),
            )),
        }
    }

    /// Newmark's updates of velocities and (pseudo-)accelerations; the drivers' work
    /// by the trapezoidal rule on their reactions at both ends of the step
    /// (the first step uses its end value twice).
    fn finish(sys: &mut ReducedSystem<'_, Self>, dt: f64) -> f64 {
        let r_end = sys.topo.driver_reactions(sys.mech, &sys.end, &sys.nodal);
        let r_start = sys.terms.reactions.take().unwrap_or_else(|| r_end.clone());
        let work = driver_increment_work(sys.mech, &sys.start, &sys.end, &r_start, &r_end);
        sys.terms.reactions = Some(r_end);
        let (start, end) = (&sys.start.config, &sys.end.config);
        let terms = &mut sys.terms;
        terms.dissipated += damping_work(&terms.damped, &mut terms.damping_forces, start, end, dt);
        for (j, rate) in sys.terms.rates.iter_mut().enumerate() {
            let count = rate.len();
            *rate = super::midpoint::released_rate(
                &sys.start.released[j],
                &sys.end.released[j],
                count,
                dt,
            );
        }
        let (kin, k) = (&mut sys.terms.prev, &sys.terms.coefficients);
        // The angular accelerations (a logarithm each) two nodes at a time
        // (the same bits), on two threads for a large mesh.
        let nodes = start.x.len();
        let angular = {
            let kin = &*kin;
            let one = |i| {
                angular_acceleration(k, &start.rot[i], &end.rot[i], &kin.w[i], &kin.alpha[i], dt)
            };
            crate::threads::map_nodes(nodes.div_ceil(2), |p| match [2 * p, 2 * p + 1] {
                i if i[1] < nodes => {
                    let rotations = (&start.rot[..], &end.rot[..]);
                    angular_acceleration_pair(k, rotations, (&kin.w, &kin.alpha), i, dt)
                }
                i => [one(i[0]), Vector3::zeros()],
            })
        };
        for (i, al) in angular.into_iter().flatten().take(nodes).enumerate() {
            let a1 = pseudo_acceleration(k, end.x[i] - start.x[i], &kin.v[i], &kin.a[i], dt);
            kin.v[i] += (kin.a[i] * (1.0 - k.gamma) + a1 * k.gamma) * dt;
            kin.acc[i] = k.acceleration(a1, &kin.a[i], &kin.acc[i]);
            kin.a[i] = a1;
            let al: Vector3<f64> = al;
            kin.w[i] += (kin.alpha[i] * (1.0 - k.gamma) + al * k.gamma) * dt;
            kin.ang_acc[i] = k.acceleration(al, &kin.alpha[i], &kin.ang_acc[i]);
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
/// `extra`: an equation and a value added to `Tᵀ r` (a joint parameter's
/// share of a free angle's equation); the reduced `q̈` is returned too.
#[allow(clippy::too_many_arguments)]
pub(super) fn initial_accelerations(
    mech: &Mechanism,
    topo: &Topology,
    inertia: &Inertia,
    asm: &mut Assembler,
    lu: &mut SparseLu,
    state: &MechanismState,
    residual: &[f64],
    extra: Option<(usize, f64)>,
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>, Vec<f64>) {
    let nodes = mech.mesh.node_count();
    let zero = (
        vec![Vector3::zeros(); nodes],
        vec![Vector3::zeros(); nodes],
        vec![0.0; topo.dofs.n_eq],
    );
    asm.values.iter_mut().for_each(|v| *v = 0.0);
    asm.add_mass(&topo.dofs, inertia, &state.config.rot);
    let mut q = vec![0.0; topo.dofs.n_eq];
    topo.dofs.reduce(residual, &mut q);
    if let Some((eq, value)) = extra {
        q[eq] += value;
    }
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
    (a, alpha, q)
}

/// The drivers' work over a step by the trapezoidal rule: the mean of the
/// reactions at both ends ([`Topology::driver_reactions`]) times the driven
/// coordinates' and prescribed DOFs' increments.
/// The work of the damping forces over the step `start → end` by the
/// trapezoidal rule on their values at both ends — the scheme's own
/// energy identity (`ΔT = ½(fₙ + fₙ₊₁)·Δq` for the trapezoidal rule) —,
/// the end's forces kept in `forces` for the next step (at t = 0 they are
/// zero: the initial accelerations leave the damping out). `2ψ` of the
/// pseudo-potential would count a mode ringing at the step's frequency,
/// whose damping forces alternate and do no work in the scheme, as
/// dissipating at every step: a beam started by a tip velocity recorded
/// eighty times its energy as dissipated.
fn damping_work(
    damped: &[(Element, f64)],
    forces: &mut Vec<Vec<f64>>,
    start: &Configuration,
    end: &Configuration,
    dt: f64,
) -> f64 {
    forces.resize_with(damped.len(), Vec::new);
    let mut work = 0.0;
    for ((e, eta), f0) in damped.iter().zip(forces.iter_mut()) {
        let mut f1 = vec![0.0; e.dofs()];
        e.damping_force(
            (&start.x, &start.rot),
            (&end.x, &end.rot),
            eta / dt,
            &mut f1,
        );
        f0.resize(f1.len(), 0.0);
        for (a, &n) in e.nodes().iter().enumerate() {
            let dx = end.x[n] - start.x[n];
            let dpsi = log(&(end.rot[n] * start.rot[n].transpose()));
            for c in 0..3 {
                let (i, j) = (6 * a + c, 6 * a + 3 + c);
                work += 0.5 * ((f0[i] + f1[i]) * dx[c] + (f0[j] + f1[j]) * dpsi[c]);
            }
        }
        *f0 = f1;
    }
    work
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::mass_slots::inertia_oracle::{assert_equals_ad, inertia, rotations};

    #[test]
    fn closed_form_inertial_tangent_equals_forward_ad() {
        let v = |a: f64, b: f64, c: f64| Vector3::new(a, b, c);
        let prev = Kinematics {
            v: vec![],
            a: vec![],
            w: vec![v(0.3, -1.2, 2.0)],
            alpha: vec![v(-4.0, 1.5, 0.7)],
            acc: vec![],
            ang_acc: vec![v(2.0, -0.5, 3.0)],
        };
        let (j0, (r_n, ends)) = (inertia(), rotations());
        for (coefficients, dt) in [
            (Coefficients::TRAPEZOIDAL, 1e-3),
            (Coefficients::generalized_alpha(0.6), 0.05),
        ] {
            for (e, r1) in ends.iter().enumerate() {
                let closed = inertial_moment_tangent(&coefficients, &j0, &r_n, r1, &prev, 0, dt);
                assert_equals_ad(
                    r1,
                    closed,
                    |r| inertial_moment(&coefficients, &j0, &r_n, r, &prev, 0, dt),
                    &format!("dt {dt}, end {e}"),
                );
            }
        }
    }
}
