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

use super::bordered::{self, Bordered};
use super::checkpoint::{CheckpointMismatch, Tape};
use super::inertia_pairs::{midpoint_moment_pair, moments_in_pairs_into};
use super::mass_slots::MassSlots;
use super::midpoint_kernels::{
    correction_size, element_force, element_kernel, start_of, started_force, started_force_pair,
    started_kernel, started_kernel_pair, started_tangent, started_tangent_pair, step_starts_into,
    CorrectionTally,
};
use super::midpoint_sensitivity::MidpointSensitivities;
use super::time_scheme::{SchemeSensitivities, TimeScheme};
pub use super::Scheme;
use super::{increment_work, slave_velocities, Motion};
use crate::assembly::{Assembler, PairKernel};
use crate::constraints::{MechanismState, Topology};
use crate::dofs::DofMap;
use crate::dynamics::midpoint_predictor::MidpointPredictor;
use crate::error::NewtonFailure;
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;
use crate::newton::{self, NewtonReport, NewtonSettings};
use crate::record::Sensitivity;
use crate::sensitivity::Parameter;
use crate::system::{Ends, ReducedSystem, Reduction, StepTerms};
use flexmech_core::rotation::{cayley_inverse, cayley_tangent_inverse, log};
use flexmech_core::step_start::StepStart;
use flexmech_core::{BeamElement, Configuration, Element, Inertia};
use nalgebra::{Matrix3, Vector3};

/// A cheap-tangent kernel of two neighbouring 2-node elements from their
/// step starts, with their forces or alone ([`started_kernel_pair`],
/// [`started_tangent_pair`]).
type StartedPair =
    fn([(&BeamElement<2>, &StepStart); 2], &Configuration, [&mut [f64]; 2], [&mut [f64]; 2]);

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

/// Inertial moment `(πₙ₊₁ − πₙ)/Δt` of one node and, if `tangent`, its
/// derivative with respect to a spatial spin of the end rotation
/// (`R₁ ← exp(η̂)R₁`; zero otherwise), in closed form: with
/// `θ = cay⁻¹(R₁Rₙᵀ)`, `δθ = (I − ½θ̂ + ¼θθᵀ)η` (Cayley's tangent), so
/// `δWₙ₊₁ = 2RₙᵀδΘ/Δt` and, with `πₙ₊₁ = R₁J₀Wₙ₊₁`,
///
/// ```text
/// ∂m/∂η = (−π̂ₙ₊₁ + R₁J₀Rₙᵀ(I − ½θ̂ + ¼θθᵀ) 2/Δt)/Δt
/// ```
///
/// equal to forward AD of [`inertial_moment_at`] to round-off (tested).
fn inertial_moment(
    j0: &Matrix3<f64>,
    r_n: &Matrix3<f64>,
    r_end: &Matrix3<f64>,
    w_n: &Vector3<f64>,
    dt: f64,
    tangent: bool,
) -> (Vector3<f64>, Matrix3<f64>) {
    let m = inertial_moment_at(j0, r_n, r_end, w_n, dt);
    if !tangent {
        return (m, Matrix3::zeros());
    }
    let theta = cayley_inverse(&(r_end * r_n.transpose()));
    let w1 = r_n.transpose() * theta * (2.0 / dt) - w_n;
    let pi1 = r_end * (j0 * w1);
    let k = (r_end * j0 * r_n.transpose() * cayley_tangent_inverse(&theta) * (2.0 / dt)
        - pi1.cross_matrix())
        / dt;
    (m, k)
}

/// `(πₙ₊₁ − πₙ)/Δt` for the end rotation `r1` (generic, for AD), with
/// `Wₙ₊₁ = 2 Rₙᵀ cay⁻¹(Rₙ₊₁Rₙᵀ)/Δt − Wₙ`.
pub(super) fn inertial_moment_at<T: flexmech_core::Scalar>(
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

/// The midpoint schemes' terms of the reduced system: the scheme's element
/// force between the step's ends, the inertial forces `M(vₙ₊₁ − vₙ)/Δt` and
/// `(πₙ₊₁ − πₙ)/Δt` with their tangents, joints through `Ñ`; loads at `tₙ₊½`.
pub(crate) struct MidpointTerms {
    pub(super) inertia: Inertia,
    slots: MassSlots,
    pub(super) scheme: Scheme,
    /// The paper's energy–momentum β (0 for the other schemes).
    pub(super) beta: f64,
    /// Whether the last step solved its energy equation for β (the paper's
    /// scheme, where β had a lever on the energy).
    pub(super) bordered: bool,
    pub(super) dt: f64,
    /// Velocities at the start of the step.
    pub(super) v_n: Vec<Vector3<f64>>,
    pub(super) w_n: Vec<Vector3<f64>>,
    /// Rates of each joint's released coordinates over the last step.
    pub(super) rates: Vec<Vec<f64>>,
    /// Which velocities predict the coming step.
    predictor: MidpointPredictor,
    /// Whether the energy–momentum scheme's exact tangent is asked for
    /// (see [`NewtonSystem::set_exact_tangent`](crate::newton::NewtonSystem::set_exact_tangent)).
    pub(super) exact_tangent: bool,
    /// The energy–momentum scheme's correction sizes at the last residual
    /// evaluation.
    tally: CorrectionTally,
    /// The energy–momentum scheme's 2-node elements' [`StepStart`]s of the
    /// step being solved (empty for the other schemes; an entry is used only
    /// for the start it was computed at).
    starts: Vec<StepStart>,
    /// The node pairs' moments of the last residual-only evaluation, kept
    /// for their allocation ([`moments_in_pairs_into`]).
    moments: std::sync::Mutex<Vec<[Vector3<f64>; 2]>>,
}

impl MidpointTerms {
    /// The terms at t = 0: slave velocities through `N`, each joint's first
    /// released rate from `initial`.
    pub(crate) fn new(
        mech: &Mechanism,
        topo: &Topology,
        asm: &Assembler,
        state: &MechanismState,
        inertia: Inertia,
        initial: &Motion,
        scheme: Scheme,
    ) -> Self {
        let slots = MassSlots::new(asm, &topo.dofs, &inertia);
        let (v_n, w_n) = slave_velocities(mech, topo, state, initial);
        let rates = initial_released_rates(mech, initial);
        Self {
            inertia,
            slots,
            scheme,
            beta: 0.0,
            bordered: false,
            dt: f64::NAN,
            v_n,
            w_n,
            rates,
            predictor: MidpointPredictor::default(),
            exact_tangent: true,
            tally: CorrectionTally::default(),
            moments: Default::default(),
            starts: Vec::new(),
        }
    }

    /// The elements' forces and tangents between `start` and `end` into
    /// `asm`: a 2-node element with its step start by `started` (while the
    /// cheap tangent is asked for: [`started_kernel`], or
    /// [`started_tangent`] for the tangent alone), two neighbouring ones by
    /// `started_pair` ([`started_kernel_pair`], [`started_tangent_pair`]),
    /// any other by [`element_kernel`].
    fn tangents<K>(
        &self,
        mech: &Mechanism,
        dofs: &DofMap,
        asm: &mut Assembler,
        (start, end): Ends,
        (started, started_pair): (K, StartedPair),
    ) where
        K: Fn((&BeamElement<2>, &StepStart), &Configuration, &mut [f64], &mut [f64]) + Sync,
    {
        let (scheme, beta, exact) = (self.scheme, self.beta, self.exact_tangent);
        let starts = &self.starts;
        let elements = &mech.mesh.elements;
        let from = |i: usize| start_of(starts, &elements[i], i, start).filter(|_| !exact);
        let one = |el: &Element, i: usize, re: &mut [f64], ke: &mut [f64]| match from(i) {
            Some(from) => started(from, end, re, ke),
            None => element_kernel(el, start, end, scheme, beta, exact, re, ke),
        };
        let two = |i: usize,
                   _: [&BeamElement<2>; 2],
                   [ra, rb]: [&mut [f64]; 2],
                   [ka, kb]: [&mut [f64]; 2]| {
            match (from(i), from(i + 1)) {
                (Some(a), Some(b)) => started_pair([a, b], end, [ra, rb], [ka, kb]),
                _ => {
                    one(&elements[i], i, ra, ka);
                    one(&elements[i + 1], i + 1, rb, kb);
                }
            }
        };
        asm.assemble_paired(&mech.mesh, dofs, one, Some(&two as &PairKernel));
    }
}

impl StepTerms for MidpointTerms {
    fn reduction(&self) -> Reduction {
        Reduction::Incremental
    }

    fn elements(
        &self,
        mech: &Mechanism,
        dofs: &DofMap,
        asm: &mut Assembler,
        start: &Configuration,
        end: &Configuration,
        tangent: bool,
    ) {
        let (scheme, beta, tally) = (self.scheme, self.beta, &self.tally);
        tally.start(!tangent);
        let starts = &self.starts;
        if tangent {
            self.tangents(
                mech,
                dofs,
                asm,
                (start, end),
                (started_kernel, started_kernel_pair),
            );
        } else {
            asm.assemble_residual_paired(
                &mech.mesh,
                |i, [a, b], forces| match (
                    start_of(starts, a, i, start),
                    start_of(starts, b, i + 1, start),
                ) {
                    (Some(from_a), Some(from_b)) => {
                        started_force_pair([from_a, from_b], end, tally, forces);
                        true
                    }
                    _ => false,
                },
                |el, i, re| match start_of(starts, el, i, start) {
                    Some(from) => started_force(from, end, tally, re),
                    None => element_force(el, start, end, scheme, beta, tally, re),
                },
            );
        }
    }

    /// The energy–momentum scheme's cheap tangent is worth computing alone:
    /// its force, the discrete gradient, is most of its kernel's work.
    fn tangents_alone(&self) -> bool {
        self.scheme == Scheme::EnergyMomentum && !self.exact_tangent
    }

    fn element_tangents(&self, mech: &Mechanism, dofs: &DofMap, asm: &mut Assembler, ends: Ends) {
        self.tally.start(false);
        self.tangents(
            mech,
            dofs,
            asm,
            ends,
            (started_tangent, started_tangent_pair),
        );
    }

    fn inertia(
        &self,
        start: &Configuration,
        end: &Configuration,
        g: &mut [f64],
        abs: &mut [f64],
        tangent: Option<(&mut Assembler, &DofMap)>,
    ) {
        let dt = self.dt;
        // Translational inertia: Σⱼ m_ij (vⱼ,ₙ₊₁ − vⱼ,ₙ)/Δt, vₙ₊₁ = 2(xₙ₊₁ − xₙ)/Δt − vₙ;
        // rotational (πₙ₊₁ − πₙ)/Δt, node by node — without the tangent two
        // nodes at a time ([`moments_in_pairs_into`], the same bits).
        let (j0, w_n) = (&self.inertia.rotational, &self.w_n);
        let mut moments = crate::threads::lock(&self.moments);
        let paired = tangent.is_none();
        if paired {
            let pi_n = |i: usize| start.rot[i] * (j0[i] * w_n[i]);
            moments_in_pairs_into(
                j0,
                |i| inertial_moment_at(&j0[i], &start.rot[i], &end.rot[i], &w_n[i], dt),
                |i| midpoint_moment_pair((j0, &start.rot, &end.rot), (w_n, pi_n), i, dt),
                &mut moments,
            );
        }
        let moments = &*moments;
        self.slots.add_inertia(
            &self.inertia,
            g,
            abs,
            tangent,
            |j| (end.x[j] - start.x[j]) * (2.0 / dt) - self.v_n[j] * 2.0,
            |m, dv| dv.map(|d| m * d / dt),
            2.0 / (dt * dt),
            |i, j0, tangent| match (tangent, paired) {
                (false, true) => (moments[i / 2][i % 2], Matrix3::zeros()),
                _ => inertial_moment(j0, &start.rot[i], &end.rot[i], &w_n[i], dt, tangent),
            },
        );
    }

    fn tangent_key(&self) -> f64 {
        self.dt
    }

    /// Only the energy–momentum scheme's 2-node elements have a cheaper
    /// tangent than the exact one ([`element_kernel`]).
    fn tangent_is_exact(&self) -> bool {
        self.exact_tangent || self.scheme != Scheme::EnergyMomentum
    }

    fn set_exact_tangent(&mut self, exact: bool) {
        self.exact_tangent = exact;
    }

    /// The momentum and energy–momentum schemes conserve what they conserve
    /// to what their steps converge to: their converged iterates are closed.
    fn closes_converged(&self) -> bool {
        self.scheme != Scheme::EnergyMomentumPaper
    }

    fn conserves_energy(&self) -> bool {
        self.scheme == Scheme::EnergyMomentum
    }
}

impl Bordered for MidpointTerms {
    fn set_beta(&mut self, beta: f64) {
        self.beta = beta;
    }
}

impl TimeScheme for MidpointTerms {
    fn set_step(&mut self, dt: f64) {
        self.dt = dt;
    }

    fn load_time(&self, t: f64, dt: f64) -> f64 {
        t + 0.5 * dt
    }

    fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        (&self.v_n, &self.w_n)
    }

    fn joint_rates(&self) -> &[Vec<f64>] {
        &self.rates
    }

    /// The blend of `midpoint_predictor` for the momentum and
    /// energy–momentum schemes; the paper's scheme keeps the end velocities:
    /// its bordered Newton on `(q, β)` ends at the round-off floor by the
    /// stall test alone, and with the blend the central differences of its
    /// spin-up's energy missed the exact sensitivity by 1.4e-4 (the test's
    /// bound is 1e-4).
    fn predictor_velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        match self.scheme {
            Scheme::EnergyMomentumPaper => (&self.v_n, &self.w_n),
            _ => self.predictor.velocities((&self.v_n, &self.w_n)),
        }
    }

    /// β, the step size, `v`, `W`, every joint's released rates and the
    /// predictor's memory.
    fn save(&self, tape: &mut Tape) {
        tape.put(self.beta);
        tape.put(self.dt);
        tape.put_vectors(&self.v_n);
        tape.put_vectors(&self.w_n);
        tape.put(self.rates.len() as f64);
        for r in &self.rates {
            tape.put_list(r);
        }
        self.predictor.save(tape);
    }

    fn restore(&mut self, mech: &Mechanism, tape: &mut Tape) -> Result<(), CheckpointMismatch> {
        let n = mech.mesh.node_count();
        self.beta = tape.take()?;
        self.dt = tape.take()?;
        self.v_n = tape.take_vectors("velocities", n)?;
        self.w_n = tape.take_vectors("angular velocities", n)?;
        let joints = tape.take_count("joints", Some(mech.joints.len()))?;
        self.rates = (0..joints)
            .map(|j| tape.take_list("a joint's rates", Some(mech.joints[j].map.released_count())))
            .collect::<Result<Vec<_>, _>>()?;
        self.predictor = MidpointPredictor::restore(tape, n)?;
        tape.done()
    }

    fn mass(&self) -> &Inertia {
        &self.inertia
    }

    fn sensitivities(
        sys: &mut ReducedSystem<'_, Self>,
        params: &[Parameter],
        mass: flexmech_core::MassKind,
    ) -> Result<SchemeSensitivities, SolveError> {
        MidpointSensitivities::new(sys, params, mass).map(SchemeSensitivities::Midpoint)
    }

    fn sensitivity_step(
        sys: &mut ReducedSystem<'_, Self>,
        sens: &mut SchemeSensitivities,
        fext_end: &[f64],
    ) -> Result<Vec<Sensitivity>, SolveError> {
        match sens {
            SchemeSensitivities::Midpoint(s) => s.step(sys, fext_end),
            _ => Err(SolveError::InvalidMechanism(
                "sensitivities set up for another scheme".into(),
            )),
        }
    }

    /// Plain Newton (the energy–momentum scheme's record carries the size
    /// of its discrete gradient's corrections as `beta`), or the bordered
    /// Newton on `(q, β)` of the paper's scheme.
    fn solve(
        sys: &mut ReducedSystem<'_, Self>,
        lu: &mut SparseLu,
        settings: &NewtonSettings,
        r: &mut [f64],
        dq: &mut [f64],
    ) -> Result<(NewtonReport, f64), NewtonFailure> {
        sys.terms.beta = 0.0;
        match sys.terms.scheme {
            Scheme::Momentum => newton::solve(sys, lu, settings, r, dq).map(|rep| (rep, f64::NAN)),
            Scheme::EnergyMomentum => {
                step_starts_into(sys.mech, &sys.start.config, &mut sys.terms.starts);
                newton::solve(sys, lu, settings, r, dq).map(|rep| {
                    // Newton's last evaluation was at the accepted iterate, or
                    // at the one a closing correction moved on (by less than the
                    // tolerance or the floor allow).
                    let size = sys
                        .terms
                        .tally
                        .correction_size(sys.mech)
                        .unwrap_or_else(|| {
                            correction_size(sys.mech, &sys.start.config, &sys.end.config)
                        });
                    (rep, size)
                })
            }
            Scheme::EnergyMomentumPaper => {
                let solved = bordered::solve_step(sys, lu, settings);
                // β took part in the step's equations (else it was left out).
                sys.terms.bordered = matches!(&solved, Ok((_, beta)) if beta.is_finite());
                solved
            }
        }
    }

    /// The end velocities and released rates; the drivers' work is exact
    /// for these schemes (`Σ pᵢ·gᵢ = ΔH − W_loads`).
    fn finish(sys: &mut ReducedSystem<'_, Self>, dt: f64) -> f64 {
        let (start, end) = (&sys.start, &sys.end);
        // Without drivers the sum would be the free equations' residual
        // (at the Newton tolerance), not work: exactly zero then.
        let work = if sys.mech.has_drivers() {
            increment_work(&start.config, &end.config, &sys.nodal, true)
        } else {
            0.0
        };
        let terms = &mut sys.terms;
        let (v1, w1) = end_motion(&start.config, &end.config, &terms.v_n, &terms.w_n, dt);
        // The paper's scheme predicts with the end velocities alone
        // (`predictor_velocities`): no memory to keep.
        if terms.scheme != Scheme::EnergyMomentumPaper {
            let mid = |a: &[Vector3<f64>], b: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
                a.iter().zip(b).map(|(a, b)| (a + b) * 0.5).collect()
            };
            let mid = (mid(&terms.v_n, &v1), mid(&terms.w_n, &w1));
            let ends = ((&terms.v_n[..], &terms.w_n[..]), (&v1[..], &w1[..]));
            terms.predictor.finish(&terms.inertia, dt, ends, mid);
        }
        for (j, rate) in terms.rates.iter_mut().enumerate() {
            *rate = released_rate(&start.released[j], &end.released[j], rate.len(), dt);
        }
        terms.v_n = v1;
        terms.w_n = w1;
        work
    }
}

/// Every joint's released rates at t = 0: the model's initial rate of the
/// first coordinate (the angle), zero for the others.
pub(super) fn initial_released_rates(mech: &Mechanism, initial: &Motion) -> Vec<Vec<f64>> {
    mech.joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let mut rate = vec![0.0; joint.map.released_count()];
            if let Some(r0) = rate.first_mut() {
                *r0 = initial.joint_rates.get(j).copied().unwrap_or(0.0);
            }
            rate
        })
        .collect()
}

/// The rate of a joint's released coordinates over a step: additive
/// coordinates by their difference, a multiplicative released rotation by
/// the spin between its two values.
pub(super) fn released_rate(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::initial_state;
    use crate::dynamics::mass_slots::inertia_oracle::{assert_equals_ad, inertia, rotations};
    use crate::newton::NewtonSystem;
    use crate::JointInstance;
    use flexmech_core::{MassKind, Mesh, Section};
    use flexmech_joints::{ReleasedState, Screw, MAX_RELEASED};
    use std::sync::Arc;

    /// A clamped post and an arm on a screw joint at its top, under
    /// gravity: 2-node elements with their step starts, and a joint.
    fn screw_arm() -> Mechanism {
        let sec = Section::new([1e6, 4e5, 4e5], [1e3; 3], 2.0, [0.02, 0.01, 0.01]);
        let mut mesh = Mesh::default();
        let (z, top) = (Vector3::z(), Vector3::new(0.0, 0.0, 2.0));
        let post = mesh.add_straight_beam(Vector3::zeros(), top, Vector3::x(), 3, 2, sec);
        let end = Vector3::new(1.0, 0.0, 2.0);
        let arm = mesh.add_straight_beam(top, end, Vector3::y(), 4, 2, sec);
        let (post, arm) = (post.unwrap(), arm.unwrap());
        let mut mech = Mechanism::new(mesh);
        mech.fixed[post[0]] = [true; 6];
        mech.gravity = z * -9.81;
        mech.joints.push(JointInstance {
            name: "screw".into(),
            master: *post.last().unwrap(),
            slave: arm[0],
            map: Arc::new(Screw {
                axis: z,
                pitch: 0.1,
            }),
            initial: ReleasedState::new([0.0; MAX_RELEASED]),
            driven: vec![None],
        });
        mech
    }

    /// The tangent Newton brings up to date at an iterate whose residual it
    /// has just evaluated is computed alone (the energy–momentum scheme's
    /// cheap tangent without its discrete gradient): the values of a whole
    /// evaluation with the tangent to the bit, and the residual's nodal
    /// forces kept — which the whole evaluation gives again.
    /// The energy–momentum screw arm's system with its cheap tangent, moved
    /// off its step start.
    fn moved_energy_momentum_system(mech: &Mechanism) -> ReducedSystem<'_, MidpointTerms> {
        let mut state = initial_state(mech);
        let topo = Topology::new(mech, &state).unwrap();
        topo.impose(mech, &mut state, 0.0);
        let asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
        let (inertia, rest) = (
            mech.inertia(MassKind::Consistent),
            Motion::rest(mech.mesh.node_count()),
        );
        let scheme = Scheme::EnergyMomentum;
        let terms = MidpointTerms::new(mech, &topo, &asm, &state, inertia, &rest, scheme);
        let mut sys = ReducedSystem::new(mech, topo, asm, state, terms);
        sys.terms.set_step(1e-2);
        step_starts_into(mech, &sys.start.config, &mut sys.terms.starts);
        sys.set_exact_tangent(false);
        let n = sys.topo.dofs.n_eq;
        let dq: Vec<f64> = (0..n).map(|i| 1e-3 * (0.7 * i as f64).sin()).collect();
        sys.apply(&dq);
        sys
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The tangent Newton brings up to date at an iterate whose residual it
    /// has just evaluated is computed alone (the energy–momentum scheme's
    /// cheap tangent without its discrete gradient): the values of a whole
    /// evaluation with the tangent to the bit, and the residual's nodal
    /// forces kept — which the whole evaluation gives again.
    #[test]
    fn a_tangent_computed_alone_is_a_whole_evaluations_to_the_bit() {
        let mech = screw_arm();
        let mut sys = moved_energy_momentum_system(&mech);
        assert!(sys.terms.tangents_alone());
        let n = sys.topo.dofs.n_eq;
        let mut r = vec![0.0; n];
        sys.residual(&mut r);
        let nodal = sys.nodal.clone();
        sys.update_tangent_at_residual(&mut vec![0.0; n]);
        let alone = sys.asm.values.clone();
        assert_eq!(sys.nodal, nodal, "the residual's nodal forces kept");
        sys.evaluate(&mut r);
        assert_eq!(bits(&alone), bits(&sys.asm.values));
        assert_eq!(sys.nodal, nodal);
        assert!(alone.iter().any(|v| *v != 0.0));
    }

    /// The elements' forces and cheap tangents, whole and alone, taken two
    /// neighbouring elements at a time: the bits of one at a time.
    #[test]
    fn element_pairs_give_the_bits_of_one_element_at_a_time() {
        let mech = screw_arm();
        let mut sys = moved_energy_momentum_system(&mech);
        let (start, end) = (&sys.start.config, &sys.end.config);
        let (terms, asm, dofs) = (&sys.terms, &mut sys.asm, &sys.topo.dofs);
        // Every 2-node element finds its own step start (`step_starts_into`
        // writes pairs in place).
        let els = &mech.mesh.elements;
        assert!(
            els.len() % 2 == 1,
            "an odd count: the last element on its own"
        );
        for (i, el) in els.iter().enumerate() {
            let found = start_of(&terms.starts, el, i, start).is_some();
            assert_eq!(found, matches!(el, Element::Linear(_)), "element {i}");
        }
        type Started = fn((&BeamElement<2>, &StepStart), &Configuration, &mut [f64], &mut [f64]);
        let kernels: [Started; 2] = [started_kernel, started_tangent];
        for (alone, started) in [false, true].into_iter().zip(kernels) {
            match alone {
                true => terms.element_tangents(&mech, dofs, asm, (start, end)),
                false => terms.elements(&mech, dofs, asm, start, end, true),
            }
            let two = (asm.values.clone(), asm.nodal.clone());
            asm.assemble_with(&mech.mesh, dofs, |el, i, re, ke| {
                match start_of(&terms.starts, el, i, start) {
                    Some(from) => started(from, end, re, ke),
                    None => element_kernel(el, start, end, terms.scheme, 0.0, false, re, ke),
                }
            });
            assert_eq!(bits(&two.0), bits(&asm.values), "tangent alone: {alone}");
            assert_eq!(bits(&two.1), bits(&asm.nodal), "tangent alone: {alone}");
            assert!(two.0.iter().any(|v| *v != 0.0));
        }
    }

    #[test]
    fn closed_form_inertial_tangent_equals_forward_ad() {
        let (j0, (r_n, ends)) = (inertia(), rotations());
        let w_n = Vector3::new(0.3, -1.2, 2.0);
        for dt in [1e-3, 0.05] {
            // Both branches of the inverse Cayley map (the last end is
            // beyond 120°).
            for (e, r1) in ends.iter().enumerate() {
                let closed = inertial_moment(&j0, &r_n, r1, &w_n, dt, true);
                let what = format!("dt {dt}, end {e}");
                assert_equals_ad(
                    r1,
                    closed,
                    |r| inertial_moment_at(&j0, &r_n, r, &w_n, dt),
                    &what,
                );
                assert_eq!(inertial_moment(&j0, &r_n, r1, &w_n, dt, false).0, closed.0);
            }
        }
    }
}
