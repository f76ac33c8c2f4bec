//! One driver for every time integrator: a [`Simulation`] steps a mechanism
//! through time with the scheme's terms over the shared reduced system
//! ([`crate::system`]) — predictor, drivers imposed, Newton, the rotation
//! guard, step control (shared with statics), the drivers' work and the
//! records.
//!
//! ```no_run
//! # use flexmech_integrators::dynamics::{DynamicSettings, Motion};
//! # use flexmech_integrators::dynamics::simulation::{Integrator, Simulation};
//! # fn demo(mech: &flexmech_integrators::Mechanism, settings: &DynamicSettings)
//! #     -> Result<(), flexmech_integrators::SolveError> {
//! let rest = Motion::rest(mech.mesh.node_count());
//! let mut sim = Simulation::new(mech, Integrator::EnergyMomentum, settings, &rest)?;
//! while let Some(step) = sim.step()? {
//!     if step.energy.kinetic > 1e3 {
//!         break; // the user's own stopping rule
//!     }
//! }
//! let (v, w) = sim.velocities();
//! # let _ = (v, w);
//! # Ok(()) }
//! ```

use std::ops::ControlFlow;

use super::checkpoint::{Checkpoint, CheckpointMismatch, Tape};
use super::midpoint::MidpointTerms;
use super::newmark_terms::{Coefficients, NewmarkTerms};
use super::time_scheme::{SchemeSensitivities, TimeScheme};
use super::{inertia_round_off_floor, DynamicSettings, Motion, Scheme, GROW_AFTER};
use crate::assembly::Assembler;
use crate::constraints::{initial_state, MechanismState, Topology};
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::measure::{dynamic_record, follower_work};
use crate::mechanism::Mechanism;
use crate::newton::NewtonReport;
use crate::record::{Sensitivity, StepRecord};
use crate::rotation_guard::{as_step_failure, RotationGuard};
use crate::sensitivity::Parameter;
use crate::step_control::StepControl;
use crate::system::ReducedSystem;
use crate::tolerances::TOLERANCES;
use flexmech_core::{Configuration, Element};
use nalgebra::Vector3;

/// The time integrators.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Newmark's trapezoidal rule on SO(3) ([`super::newmark`]).
    Newmark,
    /// The generalized-α scheme on the Lie group
    /// ([`super::generalized_alpha`]).
    GeneralizedAlpha {
        /// Spectral radius at infinite frequency, in `[0, 1]`.
        rho_inf: f64,
    },
    /// The momentum-conserving midpoint scheme ([`super::momentum`]).
    Momentum,
    /// The energy–momentum scheme ([`super::energy_momentum`]).
    EnergyMomentum,
    /// The paper's energy–momentum scheme ([`super::energy_momentum_paper`]).
    EnergyMomentumPaper,
}

impl Integrator {
    /// The name used in model and result files (`"energy-momentum"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Newmark => "newmark",
            Integrator::GeneralizedAlpha { .. } => "generalized-alpha",
            Integrator::Momentum => "momentum",
            Integrator::EnergyMomentum => "energy-momentum",
            Integrator::EnergyMomentumPaper => "energy-momentum-paper",
        }
    }
}

/// A mechanism in time: its state, velocities and time, advanced one
/// converged step at a time.
pub struct Simulation<'m> {
    inner: Box<dyn Stepping + 'm>,
    integrator: Integrator,
}

impl<'m> Simulation<'m> {
    /// Sets up `mech` with `integrator` from `initial` at t = 0 (drivers
    /// imposed, slave velocities through `N`).
    pub fn new(
        mech: &'m Mechanism,
        integrator: Integrator,
        settings: &DynamicSettings,
        initial: &Motion,
    ) -> Result<Self, SolveError> {
        if !(settings.dt > 0.0 && settings.t_end > 0.0) {
            return Err(SolveError::InvalidMechanism(
                "dt and t_end must be positive".into(),
            ));
        }
        if mech.spin.is_some() {
            return Err(SolveError::InvalidMechanism(
                "a steady spin of the frame is for statics and modes; a dynamic run spins \
                 the structure itself (initial velocities, drivers)"
                    .into(),
            ));
        }
        if scheme_refuses_damping(integrator) && !mech.damped_elements().is_empty() {
            return Err(SolveError::InvalidMechanism(format!(
                "structural damping runs with integrator \"newmark\" or \"generalized-alpha\", \
                 not \"{}\"",
                integrator.name()
            )));
        }
        let scheme = match integrator {
            Integrator::Newmark => None,
            Integrator::GeneralizedAlpha { rho_inf } => {
                if !(0.0..=1.0).contains(&rho_inf) {
                    return Err(SolveError::InvalidMechanism(format!(
                        "generalized-alpha: rho_inf must lie in [0, 1], found {rho_inf}"
                    )));
                }
                None
            }
            Integrator::Momentum => Some(Scheme::Momentum),
            Integrator::EnergyMomentum => Some(Scheme::EnergyMomentum),
            Integrator::EnergyMomentumPaper => Some(Scheme::EnergyMomentumPaper),
        };
        if scheme == Some(Scheme::EnergyMomentumPaper)
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
        let mut state = initial_state(mech);
        let topo = Topology::new(mech, &state)?;
        topo.impose(mech, &mut state, 0.0);
        let inertia = mech.inertia(settings.mass);
        let mut asm = Assembler::new(&mech.mesh, &topo.dofs, &topo.local_eqs);
        let mut lu = SparseLu::new(asm.pattern().clone()).map_err(SolveError::Singular)?;
        let inner: Box<dyn Stepping + 'm> = match scheme {
            None => {
                let coefficients = match integrator {
                    Integrator::GeneralizedAlpha { rho_inf } => {
                        Coefficients::generalized_alpha(rho_inf)
                    }
                    _ => Coefficients::TRAPEZOIDAL,
                };
                let terms = NewmarkTerms::new(
                    mech,
                    &topo,
                    &mut asm,
                    &mut lu,
                    &state,
                    inertia,
                    initial,
                    coefficients,
                );
                let sys = ReducedSystem::new(mech, topo, asm, state, terms);
                Box::new(Stepper::new(sys, lu, settings))
            }
            Some(scheme) => {
                let terms = MidpointTerms::new(mech, &topo, &asm, &state, inertia, initial, scheme);
                let sys = ReducedSystem::new(mech, topo, asm, state, terms);
                Box::new(Stepper::new(sys, lu, settings))
            }
        };
        Ok(Self { inner, integrator })
    }

    /// Continues a run from a [`Checkpoint`] taken by
    /// [`Simulation::checkpoint`] (possibly in another process) of the same
    /// mechanism, integrator and settings (`t_end` may differ). With full
    /// Newton the continued run is the uninterrupted one bit for bit; with
    /// modified Newton its first step factorises a fresh tangent, so it agrees
    /// to the Newton tolerance.
    pub fn resume(
        mech: &'m Mechanism,
        integrator: Integrator,
        settings: &DynamicSettings,
        checkpoint: &Checkpoint,
    ) -> Result<Self, SolveError> {
        let refuse = |why: String| SolveError::InvalidMechanism(format!("restart: {why}"));
        if checkpoint.integrator != integrator.name() {
            return Err(refuse(format!(
                "the saved run used integrator \"{}\", this one \"{}\"",
                checkpoint.integrator,
                integrator.name()
            )));
        }
        let rest = Motion::rest(mech.mesh.node_count());
        let mut sim = Self::new(mech, integrator, settings, &rest)?;
        sim.inner
            .restore(checkpoint)
            .map_err(|e| refuse(e.to_string()))?;
        Ok(sim)
    }

    /// Everything the simulation carries to its next step, for
    /// [`Simulation::resume`].
    pub fn checkpoint(&self) -> Checkpoint {
        let mut c = self.inner.checkpoint();
        c.integrator = self.integrator.name().to_string();
        c
    }

    /// Computes the exact sensitivities of every step to `params` from now
    /// on, into each record's [`StepRecord::sensitivities`] (see
    /// [`crate::dynamics::newmark_sensitivity`]'s method: one more tangent
    /// evaluation and factorisation per step, one solve per parameter).
    /// Only at t = 0, before any step (the derivatives of a state are not
    /// stored in a checkpoint); with `"newmark"` and `"generalized-alpha"`
    /// so far, without structural damping.
    pub fn differentiate(&mut self, params: &[Parameter]) -> Result<(), SolveError> {
        if self.inner.time() != 0.0 {
            return Err(SolveError::InvalidMechanism(
                "sensitivities start at t = 0, before the first step (a continued run cannot \
                 carry them)"
                    .into(),
            ));
        }
        self.inner.differentiate(params)
    }

    /// Advances one converged step (halving and retrying as step control
    /// allows) and returns its record; `None` once `t_end` is reached.
    pub fn step(&mut self) -> Result<Option<StepRecord>, SolveError> {
        self.inner.step()
    }

    /// Steps to `t_end`, calling `on_step` after every converged step.
    pub fn run(&mut self, mut on_step: impl FnMut(&StepRecord)) -> Result<(), SolveError> {
        while let Some(record) = self.step()? {
            on_step(&record);
        }
        Ok(())
    }

    /// Steps until `observe` breaks (after the step it was shown) or `t_end`
    /// is reached; returns the break value, if any.
    pub fn run_until<B>(
        &mut self,
        mut observe: impl FnMut(&StepRecord, &Self) -> ControlFlow<B>,
    ) -> Result<Option<B>, SolveError> {
        while let Some(record) = self.step()? {
            if let ControlFlow::Break(b) = observe(&record, self) {
                return Ok(Some(b));
            }
        }
        Ok(None)
    }

    /// The record of the current state (the initial one before any step).
    pub fn record(&self) -> StepRecord {
        self.inner.record()
    }

    /// The current time.
    pub fn time(&self) -> f64 {
        self.inner.time()
    }

    /// The current state: positions, rotations, joint coordinates and
    /// prescribed values.
    pub fn state(&self) -> &MechanismState {
        self.inner.state()
    }

    /// The current nodal velocities: spatial translational `v` and body
    /// angular `W` (`Ṙ = R Ŵ`).
    pub fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        self.inner.velocities()
    }
}

/// Whether `integrator` cannot take structural damping (the midpoint
/// schemes: their conservation statements have no place for it yet).
fn scheme_refuses_damping(integrator: Integrator) -> bool {
    !matches!(
        integrator,
        Integrator::Newmark | Integrator::GeneralizedAlpha { .. }
    )
}

/// Runs `integrator` from `initial` to `t_end`, reporting the record at
/// t = 0 and after every converged step; returns the final configuration.
pub fn solve(
    mech: &Mechanism,
    integrator: Integrator,
    settings: &DynamicSettings,
    initial: &Motion,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<Configuration, SolveError> {
    let mut sim = Simulation::new(mech, integrator, settings, initial)?;
    on_step(&sim.record());
    sim.run(on_step)?;
    Ok(sim.state().config.clone())
}

/// A [`Stepper`] of any scheme, as [`Simulation`] holds it.
trait Stepping {
    fn step(&mut self) -> Result<Option<StepRecord>, SolveError>;
    fn record(&self) -> StepRecord;
    fn time(&self) -> f64;
    fn state(&self) -> &MechanismState;
    fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]);
    fn checkpoint(&self) -> Checkpoint;
    fn restore(&mut self, checkpoint: &Checkpoint) -> Result<(), CheckpointMismatch>;
    fn differentiate(&mut self, params: &[Parameter]) -> Result<(), SolveError>;
}

/// The driver of one scheme `S`. Between steps `sys.end` is the current
/// state; during a step `sys.start` holds the state it started from.
struct Stepper<'m, S> {
    sys: ReducedSystem<'m, S>,
    lu: SparseLu,
    settings: DynamicSettings,
    control: StepControl,
    guard: RotationGuard,
    t: f64,
    /// Size of the last converged step (0 before the first).
    last_dt: f64,
    /// The drivers' work since t = 0.
    driver_work: f64,
    /// The follower loads' work since t = 0.
    follower_work: f64,
    /// Newton's scratch.
    r: Vec<f64>,
    dq: Vec<f64>,
    /// External forces at the current time (for the records' potential).
    fext_now: Vec<f64>,
    /// The exact sensitivities, when asked for, and those of the current
    /// state.
    sensitivities: Option<(SchemeSensitivities, Vec<Sensitivity>)>,
}

impl<'m, S: TimeScheme> Stepper<'m, S> {
    fn new(sys: ReducedSystem<'m, S>, lu: SparseLu, settings: &DynamicSettings) -> Self {
        let n_eq = sys.topo.dofs.n_eq;
        let mut fext_now = vec![0.0; sys.fext.len()];
        sys.mech.external_forces(0.0, &mut fext_now);
        Self {
            guard: RotationGuard::new(sys.mech, &sys.end),
            sys,
            lu,
            settings: *settings,
            control: StepControl::with(settings.dt, settings.max_halvings, GROW_AFTER),
            t: 0.0,
            last_dt: 0.0,
            driver_work: 0.0,
            follower_work: 0.0,
            r: vec![0.0; n_eq],
            dq: vec![0.0; n_eq],
            fext_now,
            sensitivities: None,
        }
    }

    /// The predictor of the step `t → t + dt` into `sys.end`: constant
    /// velocities of the free nodes and constant rates of the joints'
    /// released coordinates, then the drivers at `t + dt`.
    fn predict(&mut self, dt: f64) {
        let sys = &mut self.sys;
        let mech = sys.mech;
        sys.start.clone_from(&sys.end);
        let (v, w) = sys.terms.predictor_velocities();
        let (topo, start_rot) = (&sys.topo, &sys.start.config.rot);
        let end = &mut sys.end.config;
        crate::threads::increment_poses(&mut end.x, &mut end.rot, |i| {
            (!mech.fixed[i].iter().any(|&h| h) && topo.slave_of[i].is_none())
                .then(|| (v[i] * dt, start_rot[i] * w[i] * dt))
        });
        for (j, rates) in sys.terms.joint_rates().iter().enumerate() {
            let delta: Vec<f64> = rates.iter().map(|r| r * dt).collect();
            if delta.iter().any(|&d| d != 0.0) {
                mech.joints[j].map.advance(&mut sys.end.released[j], &delta);
            }
        }
        sys.topo.impose(mech, &mut sys.end, self.t + dt);
    }

    fn record_with(&self, report: Option<&NewtonReport>) -> StepRecord {
        let sys = &self.sys;
        let mut rec = dynamic_record(
            sys.mech,
            sys.terms.mass(),
            &sys.end,
            sys.terms.velocities(),
            &self.fext_now,
            (self.t, self.last_dt),
            Some(self.guard.accepted()),
            report,
        );
        rec.energy.driver_work = self.driver_work;
        // Follower loads and damping have no potential: minus the follower
        // work and plus the dissipated energy stand for it.
        let dissipated = sys.terms.dissipated();
        rec.energy.dissipated = dissipated;
        rec.energy.potential += dissipated - self.follower_work;
        rec.energy.total += dissipated - self.follower_work;
        if report.is_some() {
            // The converged iterate's residual, the last one Newton evaluated
            // (before a closing correction, which moves the state by less
            // than the tolerance or the floor allow).
            sys.record_reactions(&mut rec);
        }
        if let Some((_, now)) = &self.sensitivities {
            rec.sensitivities = now.clone();
        }
        rec
    }
}

impl<S: TimeScheme> Stepping for Stepper<'_, S> {
    fn step(&mut self) -> Result<Option<StepRecord>, SolveError> {
        let t_end = self.settings.t_end;
        while self.t < t_end * (1.0 - TOLERANCES.end_of_run) {
            let (t, dt) = (self.t, self.control.next(self.t, t_end));
            self.sys.terms.set_step(dt);
            self.predict(dt);
            let sys = &mut self.sys;
            let mech = sys.mech;
            sys.load_time = sys.terms.load_time(t, dt);
            mech.external_forces(sys.load_time, &mut sys.fext);
            let x = &sys.start.config.x;
            sys.floor = mech.round_off_floor_at(x)
                + inertia_round_off_floor(mech, sys.terms.mass(), x, dt)
                + mech.damping_round_off_floor_at(x, dt);
            let outcome = S::solve(
                sys,
                &mut self.lu,
                &self.settings.newton,
                &mut self.r,
                &mut self.dq,
            );
            let (report, beta) = match outcome {
                Ok(done) => done,
                Err(reason) => {
                    sys.end.clone_from(&sys.start);
                    self.control.failed(t + dt, reason)?;
                    continue;
                }
            };
            if let Err(objection) = self.guard.accept(mech, &sys.end, t + dt) {
                sys.end.clone_from(&sys.start);
                self.control.failed(t + dt, as_step_failure(objection)?)?;
                continue;
            }
            if let Some((sens, now)) = &mut self.sensitivities {
                // The loads at the step's end (a midpoint scheme's `sys.fext`
                // are at tₙ₊½).
                let mut fext_end = vec![0.0; sys.fext.len()];
                mech.external_forces(t + dt, &mut fext_end);
                *now = S::sensitivity_step(sys, sens, &fext_end)?;
            }
            self.driver_work += S::finish(sys, dt);
            self.follower_work +=
                follower_work(mech, (t, &sys.start.config), (t + dt, &sys.end.config));
            self.t = self.control.advance(t, dt);
            self.last_dt = dt;
            mech.external_forces(self.t, &mut self.fext_now);
            let mut rec = self.record_with(Some(&report));
            rec.beta = beta;
            self.control.succeeded();
            return Ok(Some(rec));
        }
        Ok(None)
    }

    fn record(&self) -> StepRecord {
        self.record_with(None)
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn state(&self) -> &MechanismState {
        &self.sys.end
    }

    fn velocities(&self) -> (&[Vector3<f64>], &[Vector3<f64>]) {
        self.sys.terms.velocities()
    }

    fn checkpoint(&self) -> Checkpoint {
        let (step, level, easy) = self.control.saved();
        let mut tape = Tape::default();
        self.sys.terms.save(&mut tape);
        let end = &self.sys.end;
        Checkpoint {
            integrator: String::new(),
            time: self.t,
            last_dt: self.last_dt,
            driver_work: self.driver_work,
            follower_work: self.follower_work,
            step,
            level,
            easy,
            positions: end.config.x.clone(),
            rotations: end.config.rot.clone(),
            released: end.released.clone(),
            prescribed: end.prescribed.clone(),
            scheme: tape.into_data(),
        }
    }

    fn restore(&mut self, c: &Checkpoint) -> Result<(), CheckpointMismatch> {
        let mech = self.sys.mech;
        let n = mech.mesh.node_count();
        let counts = [
            ("nodal positions", c.positions.len(), n),
            ("nodal rotations", c.rotations.len(), n),
            ("joints", c.released.len(), mech.joints.len()),
            ("prescribed DOFs", c.prescribed.len(), mech.prescribed.len()),
        ];
        for (what, saved, here) in counts {
            if saved != here {
                return Err(CheckpointMismatch(format!(
                    "{saved} {what} saved, the mechanism has {here}"
                )));
            }
        }
        if !(c.time.is_finite() && c.time >= 0.0) {
            return Err(CheckpointMismatch(format!("saved time {}", c.time)));
        }
        self.control
            .restore(c.step, c.level, c.easy)
            .map_err(CheckpointMismatch)?;
        self.sys
            .terms
            .restore(mech, &mut Tape::reading(&c.scheme))?;
        self.sys.end = c.state();
        self.sys.start.clone_from(&self.sys.end);
        self.t = c.time;
        self.last_dt = c.last_dt;
        self.driver_work = c.driver_work;
        self.follower_work = c.follower_work;
        self.guard = RotationGuard::new(mech, &self.sys.end);
        mech.external_forces(self.t, &mut self.fext_now);
        Ok(())
    }

    fn differentiate(&mut self, params: &[Parameter]) -> Result<(), SolveError> {
        let sens = S::sensitivities(&mut self.sys, params, self.settings.mass)?;
        let initial = sens.initial();
        self.sensitivities = Some((sens, initial));
        Ok(())
    }
}
