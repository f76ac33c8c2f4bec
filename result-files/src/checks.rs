//! The checks every completed run passes before it is called "completed"
//! without a word: the energy balance of a dynamic run and the stability of
//! a static load path. Each watches the converged steps as they come and
//! gives a warning (stderr, the summary line and the result file's root
//! attribute `warnings`) when the result is doubtful.

use flexmech_integrators::critical::{CriticalKind, CriticalPoint};
use flexmech_integrators::dynamics::Integrator;
use flexmech_integrators::modal::buckling_modes;
use flexmech_integrators::{Mechanism, StepRecord};
use flexmech_model::{Analysis, Model, PrescribedSpec};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// The energy balance a dynamic run is checked against: the largest change
/// of `T + Π − W_loads − W_drivers` (kinetic and strain energy less the work
/// of the applied loads — gravity, dead and follower forces and moments,
/// with their time functions — and of the drivers since t = 0) relative to the energy scale
/// (the largest of these terms met in the run). The conserving schemes keep
/// it at the Newton tolerance plus the O(Δt²) error of the trapezoidal load
/// work, Newmark within ~1e-3 on well-resolved runs; beyond 5 % the result is
/// not to be trusted without a look. A dissipative integrator
/// (generalized-α) removes energy by design: only a growth of the balance
/// warns for it.
pub const ENERGY_BALANCE_WARNING: f64 = 5e-2;

/// Tracks a dynamic run's energy balance.
#[derive(Debug, Default)]
pub(crate) struct Balance {
    /// The integrator dissipates energy by design: only growth counts.
    dissipative: bool,
    first: Option<f64>,
    worst: f64,
    scale: f64,
    /// Work of the applied loads since t = 0: the trapezoidal rule over
    /// each step, `½(fₙ + fₙ₊₁)·Δx + ½(mₙ + mₙ₊₁)·Δθ` per node, with `Δθ`
    /// the step's spatial rotation vector (exact for constant forces).
    load_work: f64,
    /// The previous step's node positions, orientations and loads.
    previous: Option<Snapshot>,
    /// The loads' storage of the step before the previous, reused.
    spare: Vec<f64>,
}

/// Node positions, orientations (quaternions) and nodal loads of a step.
type Snapshot = (Vec<[f64; 3]>, Vec<[f64; 4]>, Vec<f64>);

impl Balance {
    /// A balance for an integrator that conserves energy (up to its error)
    /// or, when `dissipative`, may only lose it.
    pub(crate) fn new(dissipative: bool) -> Self {
        Self {
            dissipative,
            ..Self::default()
        }
    }

    /// Takes in a converged step of `mech`.
    pub(crate) fn push(&mut self, mech: &Mechanism, s: &StepRecord) {
        let mut loads = std::mem::take(&mut self.spare);
        loads.clear();
        loads.resize(6 * s.positions.len(), 0.0);
        mech.external_forces(s.time, &mut loads);
        if !mech.follower_loads.is_empty() {
            let rot: Vec<_> = s
                .quaternions
                .iter()
                .map(|q| quaternion(*q).to_rotation_matrix().into_inner())
                .collect();
            mech.add_follower_forces(s.time, &rot, 1.0, &mut loads);
        }
        if let Some((x0, q0, f0)) = &self.previous {
            for n in 0..s.positions.len() {
                let loaded = |f: &[f64]| f[6 * n..6 * n + 6].iter().any(|&v| v != 0.0);
                if !loaded(f0) && !loaded(&loads) {
                    // No work: skip the node's rotation increment.
                    continue;
                }
                let dx = Vector3::from(s.positions[n]) - Vector3::from(x0[n]);
                let turn = quaternion(s.quaternions[n]) * quaternion(q0[n]).inverse();
                let dtheta = turn.scaled_axis();
                for c in 0..3 {
                    let (force, moment) = (6 * n + c, 6 * n + 3 + c);
                    self.load_work += 0.5 * (f0[force] + loads[force]) * dx[c];
                    self.load_work += 0.5 * (f0[moment] + loads[moment]) * dtheta[c];
                }
            }
        }
        let e = &s.energy;
        let b = e.kinetic + e.strain - self.load_work - e.driver_work + e.dissipated;
        let b0 = *self.first.get_or_insert(b);
        let off = if self.dissipative {
            (b - b0).max(0.0)
        } else {
            (b - b0).abs()
        };
        self.worst = self.worst.max(off);
        for v in [e.kinetic, e.strain, self.load_work, e.driver_work, b0] {
            if v.is_finite() {
                self.scale = self.scale.max(v.abs());
            }
        }
        // Into the storage the previous step's took (no allocation per step).
        match &mut self.previous {
            Some((x0, q0, f0)) => {
                x0.clone_from(&s.positions);
                q0.clone_from(&s.quaternions);
                self.spare = std::mem::replace(f0, loads);
            }
            None => self.previous = Some((s.positions.clone(), s.quaternions.clone(), loads)),
        }
    }

    /// The warning, when the balance is off by more than the threshold.
    pub(crate) fn warning(&self) -> Option<String> {
        let drift = self.worst / self.scale.max(f64::MIN_POSITIVE);
        // A NaN drift (a blown-up energy) warns too.
        (self.first.is_some() && (drift > ENERGY_BALANCE_WARNING || drift.is_nan())).then(|| {
            format!(
                "energy balance: kinetic + strain energy − work of loads and drives changed by \
                 {drift:.2e} of the energy scale (threshold {ENERGY_BALANCE_WARNING:.0e}); the \
                 step may be too large for this integrator, or the solution blew up: check with \
                 a smaller dt or integrator = \"energy-momentum\""
            )
        })
    }
}

fn quaternion(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Tracks a static run's stability: the negative eigenvalues of the
/// converged tangent at each load factor.
///
/// The count is the stability of the equilibrium when the problem is
/// conservative in the unknowns the solver uses — dead forces, gravity,
/// supports, joints and their drives (the Euler column loses stability at
/// `π²EI/4L²` to the load step). Two inputs make the tangent's symmetric part
/// something else than a Hessian: an applied nodal moment (a dead moment is
/// not conservative for finite 3D rotations) and a prescribed nodal rotation
/// (held on the rotation increments, not on a conserved constraint). The
/// count is still written for such models, but it warns only for the others.
#[derive(Debug)]
pub(crate) struct Stability {
    /// Whether the count is a stability statement (see above).
    conservative: bool,
    /// The first load factor with a negative eigenvalue, and the most met.
    unstable: Option<(f64, usize)>,
    /// A step whose count is undefined (an exactly zero pivot).
    undefined: Option<f64>,
    /// The load factor where the path became stable again after its last
    /// unstable step (on a branch it switched to, past a limit point).
    stable_again: Option<f64>,
}

impl Stability {
    /// A watch for a model that is `conservative` in the above sense.
    pub(crate) fn new(conservative: bool) -> Self {
        Self {
            conservative,
            unstable: None,
            undefined: None,
            stable_again: None,
        }
    }

    /// Takes in a converged step.
    pub(crate) fn push(&mut self, s: &StepRecord) {
        match s.negative_pivots {
            Some(0) => {
                if self.unstable.is_some() {
                    self.stable_again.get_or_insert(s.time);
                }
            }
            Some(n) => {
                let (_, most) = self.unstable.get_or_insert((s.time, n));
                *most = (*most).max(n);
                self.stable_again = None;
            }
            None => {
                self.undefined.get_or_insert(s.time);
            }
        }
    }

    /// The warning, when some equilibrium on the path was unstable.
    pub(crate) fn warning(&self) -> Option<String> {
        if !self.conservative {
            return None;
        }
        if let (Some((lambda, most)), Some(again)) = (self.unstable, self.stable_again) {
            return Some(format!(
                "stability: the path passed unstable equilibria from load factor {lambda:.4} \
                 (up to {most} negative eigenvalue(s) of the tangent, \
                 /solver/negative_pivots) and is stable again from load factor {again:.4} on: \
                 it crossed a limit point or left a bifurcation onto another branch"
            ));
        }
        if let Some((lambda, most)) = self.unstable {
            return Some(format!(
                "stability: the equilibrium is unstable from load factor {lambda:.4} on (up to \
                 {most} negative eigenvalue(s) of the tangent, /solver/negative_pivots): the \
                 path followed is past a bifurcation or limit point, where the real structure \
                 would buckle or snap; to follow the buckled branch use control = \
                 \"arc-length\" with branch_switch = true, or add a small imperfection (a load \
                 or geometry perturbation)"
            ));
        }
        self.undefined.map(|lambda| {
            format!(
                "stability: the tangent at load factor {lambda:.4} has an exactly zero pivot, so \
                 its stability is undefined (a bifurcation point)"
            )
        })
    }
}

/// The checks of a run of `model`, watching its converged steps: the
/// energy balance of a dynamic run, the stability of a static load path.
/// A run driven step by step outside [`crate::run()`] (the Python package's
/// `Simulation`) keeps one to give its file the same `warnings`.
#[derive(Debug)]
pub struct RunChecks {
    balance: Option<Balance>,
    stability: Option<Stability>,
}

impl RunChecks {
    /// The checks a run of `model` passes.
    pub fn new(model: &Model) -> Self {
        let dynamic = matches!(model.solver.analysis, Analysis::Dynamic { .. });
        let dissipative = matches!(
            model.solver.analysis,
            Analysis::Dynamic {
                integrator: Integrator::GeneralizedAlpha { .. },
                ..
            }
        );
        Self {
            balance: dynamic.then(|| Balance::new(dissipative)),
            // Modal and buckling analyses report stability by their modes
            // (a negative ω², the load factors).
            stability: matches!(
                model.solver.analysis,
                Analysis::Static { .. } | Analysis::ArcLength { .. }
            )
            .then(|| Stability::new(conservative(model))),
        }
    }

    /// Takes a converged step of `mech`.
    pub fn push(&mut self, mech: &Mechanism, step: &StepRecord) {
        if let Some(b) = &mut self.balance {
            b.push(mech, step);
        }
        if let Some(s) = &mut self.stability {
            s.push(step);
        }
    }

    /// The warnings so far (for a completed run).
    pub fn warnings(&self) -> Vec<String> {
        self.balance
            .as_ref()
            .and_then(Balance::warning)
            .into_iter()
            .chain(self.stability.as_ref().and_then(Stability::warning))
            .collect()
    }

    /// [`RunChecks::warnings`] of a static path of `mech` that located
    /// `critical` points: the stability warning names them and the
    /// nearest linear buckling load factor.
    pub fn warnings_with(&self, mech: &Mechanism, critical: &[CriticalPoint]) -> Vec<String> {
        let mut warnings = self.warnings();
        let unstable = self.stability.as_ref().and_then(|s| s.unstable);
        if let (Some(w), Some((lambda, _))) = (warnings.last_mut(), unstable) {
            if w.starts_with("stability:") {
                w.push_str(&nearest_critical(mech, critical, lambda));
            }
        }
        warnings
    }
}

/// The stability warning's last words: the critical points located on the
/// path and — unless every one is a limit point — the linear buckling load
/// factor (`analysis = "buckling"`, about the undeformed state) nearest the
/// first of them (or the first unstable load factor `lambda`).
fn nearest_critical(mech: &Mechanism, critical: &[CriticalPoint], lambda: f64) -> String {
    let mut text = String::new();
    if !critical.is_empty() {
        let list: Vec<String> = critical
            .iter()
            .map(|p| format!("{} at {:.6}", p.kind.name(), p.load_factor))
            .collect();
        text.push_str(&format!(
            "; critical points located (/stability): {}",
            list.join(", ")
        ));
    }
    // Limit points only: a linear buckling load (a bifurcation of the
    // linear prestress) says nothing about them.
    if !critical.is_empty() && critical.iter().all(|p| p.kind == CriticalKind::Limit) {
        return text;
    }
    let at = critical.first().map_or(lambda, |p| p.load_factor);
    match buckling_modes(mech, NEAREST_BUCKLING_MODES, None) {
        Ok(set) => {
            let nearest = set
                .values()
                .into_iter()
                .min_by(|a, b| (a - at).abs().total_cmp(&(b - at).abs()));
            if let Some(b) = nearest {
                text.push_str(&format!(
                    "; the nearest linear buckling load factor (analysis = \"buckling\", about \
                     the undeformed state) is {b:.6}"
                ));
            }
        }
        Err(e) => text.push_str(&format!("; no linear buckling estimate: {e}")),
    }
    text
}

/// Buckling load factors computed to name the nearest one.
const NEAREST_BUCKLING_MODES: usize = 3;

/// Whether the stability count of a static `model` is a stability
/// statement (see [`Stability`]): no applied nodal moment, no prescribed
/// nodal rotation.
fn conservative(model: &Model) -> bool {
    model
        .loads
        .iter()
        .all(|l| l.moment == [0.0; 3] && !l.follower)
        && model
            .distributed_loads
            .iter()
            .all(|l| l.moment == [0.0; 3] && !l.follower)
        && model.prescribed.iter().all(|p| match p {
            PrescribedSpec::NodeDof { dof, .. } => *dof < 3,
            PrescribedSpec::JointAngle { .. } => true,
        })
}
