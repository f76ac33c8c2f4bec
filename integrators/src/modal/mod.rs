//! Linearised analysis: vibration modes about a static state and linear
//! buckling (FORMULATION §6).
//!
//! The master–slave method leaves the joined system in minimum coordinates,
//! so the linearisation about a state is the ordinary pencil of the reduced
//! tangent `K = ∂(Nᵀg)/∂q` and the reduced mass `NᵀMN` — no constraint
//! rows, and every mode satisfies relation (1) exactly (slaves follow
//! through `N`). At an equilibrium under conservative loads `K` is
//! symmetric; the modes are those of `K φ = ω² M φ`, solved by shift-invert
//! (`(K + sM)⁻¹M`, [`eigen`]) so that the low modes keep their relative
//! accuracy whatever the highest frequency of the mesh. Buckling: see
//! [`buckling`].

pub mod buckling;
mod damping;
pub mod eigen;
mod gyroscopic;
mod linearise;
mod pencil;

pub use buckling::buckling_modes;
pub use eigen::{EigenSolver, DENSE_UNKNOWNS};

use crate::constraints::{initial_state, MechanismState};
use crate::error::SolveError;
use crate::measure::static_record;
use crate::mechanism::Mechanism;
use crate::record::StepRecord;
use crate::statics::{solve_static, StaticSettings};
pub use damping::ModalDamping;
use eigen::PencilError;
use flexmech_core::MassKind;
use linearise::{Expanded, Linearisation};
use nalgebra::Vector3;
use pencil::{Pattern, SYMMETRIC};

/// The shift `s` of `(K + sM)⁻¹M` as a part of the mesh's stiffness-to-mass
/// ratio `ω_ref² = Σ|Kᵢᵢ| / Σ|Mᵢᵢ|` (of the order of its highest `ω²`):
/// above every rigid mode, below or near the low elastic ones.
pub(crate) const SHIFT: f64 = 1e-6;

/// Factor by which the shift grows when `K + sM` is not positive definite
/// (a state past a stability limit: some `ω² < −s`).
const SHIFT_GROWTH: f64 = 100.0;

/// The largest shift tried, as a part of `ω_ref²`.
const MAX_SHIFT: f64 = 1e6;

/// `|ω²|` below this part of `ω_ref²` is a rigid (zero-frequency) mode: the
/// round-off of a rigid motion's `ω²` is `~ε ω_ref²` times a modest factor.
pub const RIGID_MODE: f64 = 1e-13;

/// What a set of modes is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeKind {
    /// Free vibration: `K φ = ω² M φ`.
    Vibration,
    /// Linear buckling: `(K_material + λ K_geometric) φ = 0`.
    Buckling,
}

/// Modes of a linearisation, lowest first.
#[derive(Debug, Clone)]
pub struct ModeSet {
    /// Vibration or buckling.
    pub kind: ModeKind,
    /// Vibration: `ω²` (per unit of model time squared; rigid modes exactly
    /// 0; negative past a stability limit). Buckling: the load factors `λ`.
    pub eigenvalues: Vec<f64>,
    /// Per mode, every node's displacement (vibration: unit mass norm
    /// `φᵀMφ = 1`; buckling: the largest nodal displacement 1, or the
    /// largest rotation where no node moves).
    pub displacement: Vec<Vec<Vector3<f64>>>,
    /// Per mode, every node's rotation as a spatial rotation vector.
    pub rotation: Vec<Vec<Vector3<f64>>>,
    /// Per mode, every joint's released coordinates (model order; zero for
    /// driven ones).
    pub released: Vec<Vec<Vec<f64>>>,
    /// How many of the modes are rigid (zero frequency).
    pub rigid: usize,
    /// The solver that found them.
    pub solver: EigenSolver,
    /// Unknowns of the reduced system.
    pub unknowns: usize,
    /// Relative asymmetry of the tangent, whose symmetric part was used.
    pub asymmetry: f64,
    /// Complex modes (a spinning mechanism): their imaginary parts, damping
    /// ratios and whirl.
    pub complex: Option<ComplexParts>,
    /// Structural damping projected on the (real) modes, where elements
    /// are damped.
    pub damping: Option<ModalDamping>,
}

/// What complex modes add to real ones.
#[derive(Debug, Clone, Default)]
pub struct ComplexParts {
    /// Per mode, every node's displacement, imaginary part.
    pub displacement: Vec<Vec<Vector3<f64>>>,
    /// Per mode, every node's rotation vector, imaginary part.
    pub rotation: Vec<Vec<Vector3<f64>>>,
    /// Per mode, `ζ = −Re λ/|λ|`.
    pub damping_ratio: Vec<f64>,
    /// Per mode, +1 forward (orbits turn with the spin), −1 backward, 0 none.
    pub whirl: Vec<f64>,
}

impl ModeSet {
    /// Vibration: the frequencies `ω/2π` (cycles per unit of model time),
    /// `−√|ω²|/2π` for a divergent mode (`ω² < 0`). Buckling: the load
    /// factors.
    pub fn values(&self) -> Vec<f64> {
        match self.kind {
            ModeKind::Buckling => self.eigenvalues.clone(),
            ModeKind::Vibration => self
                .eigenvalues
                .iter()
                .map(|w2| w2.signum() * w2.abs().sqrt() / std::f64::consts::TAU)
                .collect(),
        }
    }

    fn push(&mut self, value: f64, (u, theta, released): Expanded) {
        self.eigenvalues.push(value);
        self.displacement.push(u);
        self.rotation.push(theta);
        self.released.push(released);
    }

    fn empty(kind: ModeKind, solver: EigenSolver, unknowns: usize, asymmetry: f64) -> Self {
        Self {
            kind,
            eigenvalues: Vec::new(),
            displacement: Vec::new(),
            rotation: Vec::new(),
            released: Vec::new(),
            rigid: 0,
            solver,
            unknowns,
            asymmetry,
            complex: None,
            damping: None,
        }
    }
}

/// What a linearisation is asked for: how many modes, with which mass,
/// by which solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeRequest {
    /// How many of the lowest modes.
    pub modes: usize,
    /// Translational mass distribution.
    pub mass: MassKind,
    /// The eigensolver (`None`: by the unknowns, [`EigenSolver::for_unknowns`]).
    pub solver: Option<EigenSolver>,
}

/// Settings of a modal analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalSettings {
    /// The modes asked for.
    pub request: ModeRequest,
    /// The static path to the state the modes are about, where the
    /// mechanism is loaded or driven.
    pub preload: StaticSettings,
}

/// Whether anything loads or drives the mechanism (then the modes are about
/// the static equilibrium at load factor 1).
pub fn is_loaded(mech: &Mechanism) -> bool {
    !mech.loads.is_empty()
        || !mech.follower_loads.is_empty()
        || !mech.load_fields.is_empty()
        || mech.gravity != Vector3::zeros()
        || mech.has_drivers()
        || mech.spin.as_ref().is_some_and(|s| s.rate != 0.0)
}

/// The modal analysis of `mech`: the static path to load factor 1 where it
/// is loaded or driven (each converged step to `on_step`; otherwise the
/// initial state as one record at 0), then the `modes` lowest vibration
/// modes about the state reached.
pub fn solve_modal(
    mech: &Mechanism,
    settings: &ModalSettings,
    mut on_step: impl FnMut(&StepRecord),
) -> Result<ModeSet, SolveError> {
    let (state, load) = if is_loaded(mech) {
        (
            solve_static(mech, &settings.preload, &mut on_step)?.state,
            1.0,
        )
    } else {
        let state = initial_state(mech);
        let fext = vec![0.0; 6 * mech.mesh.node_count()];
        on_step(&static_record(mech, &state, &fext, 0.0, 0.0, None));
        (state, 0.0)
    };
    vibration_modes(mech, &state, load, &settings.request, false)
}

/// The `modes` lowest vibration modes of `mech` linearised at `state` with
/// the loads at `load_time` (the mechanism held still in that pose: no
/// inertial forces of a motion). With `symmetric_part`, the symmetric part
/// of a non-symmetric tangent is used (a stored state off equilibrium,
/// [`ModeSet::asymmetry`] says how far); otherwise a tangent whose relative
/// asymmetry exceeds `1e-7` is refused (follower loads: a non-self-adjoint
/// problem).
pub fn vibration_modes(
    mech: &Mechanism,
    state: &MechanismState,
    load_time: f64,
    request: &ModeRequest,
    symmetric_part: bool,
) -> Result<ModeSet, SolveError> {
    let (modes, mass) = (request.modes, request.mass);
    let mut lin = Linearisation::at(mech, state, Some(load_time))?;
    let n = lin.unknowns();
    check_count(modes, n)?;
    let mut k = lin.tangent();
    let asymmetry = lin.pattern.symmetrize(&mut k);
    if asymmetry > SYMMETRIC && !symmetric_part {
        return Err(SolveError::InvalidMechanism(format!(
            "modal analysis: the tangent at the state is not symmetric (relative asymmetry \
             {asymmetry:.1e}; follower loads make the linearised problem non-self-adjoint); \
             its complex modes are not computed: use dead loads"
        )));
    }
    let m = lin.mass(mass);
    let reference =
        diagonal_sum(&lin.pattern, &k) / diagonal_sum(&lin.pattern, &m).max(f64::MIN_POSITIVE);
    if mech.spin.as_ref().is_some_and(|s| s.rate != 0.0) {
        if !mech.damped_elements().is_empty() {
            return Err(SolveError::InvalidMechanism(
                "modal analysis: a spinning structure with structural damping: its complex \
                 modes (gyroscopic and damping matrices together) are not computed; give the \
                 sections damping = 0 for the modes"
                    .into(),
            ));
        }
        return gyroscopic::spinning_modes(&mut lin, (&k, &m), modes, reference, asymmetry);
    }
    let mut set = ModeSet::empty(
        ModeKind::Vibration,
        request.solver.unwrap_or(EigenSolver::for_unknowns(n)),
        n,
        asymmetry,
    );
    let (s, (mu, vectors)) = shifted_modes(&lin.pattern, (&k, &m), modes, reference, set.solver)?;
    for (mu, y) in mu.into_iter().zip(vectors) {
        if mu.is_nan() || mu <= 0.0 {
            return Err(SolveError::InvalidMechanism(format!(
                "modal analysis: only {} of the {modes} modes asked have mass (a degree of \
                 freedom without mass or inertia: give the sections rhoA and rhoJ)",
                set.eigenvalues.len()
            )));
        }
        let mut w2 = 1.0 / mu - s;
        if w2.abs() <= RIGID_MODE * reference {
            w2 = 0.0;
            set.rigid += 1;
        }
        let phi = oriented(y.iter().map(|v| v / mu.sqrt()).collect());
        set.push(w2, lin.expand(&phi));
    }
    set.damping = damping::modal_damping(mech, state, &set);
    Ok(set)
}

/// The shift-invert solve: `(s, (μ, y))` of `M y = μ (K + sM) y` with `s`
/// grown until `K + sM` is positive definite; then, where the lowest
/// elastic `ω²` lies below that shift, solved once more with the shift at
/// half of it (the error of `ω² = 1/μ − s` is `~ε s`, so the low modes keep
/// their digits: checked by the sparse solver against the dense one).
fn shifted_modes(
    pattern: &Pattern,
    (k, m): (&[f64], &[f64]),
    modes: usize,
    reference: f64,
    solver: EigenSolver,
) -> Result<(f64, eigen::Eigenpairs), SolveError> {
    let mut s = SHIFT * reference;
    let (mu, y) = loop {
        match shift_solve(pattern, (k, m), s, modes, solver)? {
            Some(found) => break found,
            None if s < MAX_SHIFT * reference => s *= SHIFT_GROWTH,
            None => {
                return Err(SolveError::InvalidMechanism(
                    "modal analysis: the tangent has no lower bound the mass can shift \
                     (a degree of freedom without mass or inertia and without stiffness?)"
                        .into(),
                ))
            }
        }
    };
    let elastic = mu
        .iter()
        .map(|mu| 1.0 / mu - s)
        .filter(|w2| w2.abs() > RIGID_MODE * reference)
        .fold(f64::INFINITY, f64::min);
    if elastic > 0.0 && elastic < s && elastic.is_finite() {
        let refined = 0.5 * elastic;
        if let Some((mu, y)) = shift_solve(pattern, (k, m), refined, modes, solver)? {
            return Ok((refined, (mu, y)));
        }
    }
    Ok((s, (mu, y)))
}

/// One shift-invert solve with the shift `s`; `None` when `K + sM` is not
/// positive definite.
fn shift_solve(
    pattern: &Pattern,
    (k, m): (&[f64], &[f64]),
    s: f64,
    modes: usize,
    solver: EigenSolver,
) -> Result<Option<eigen::Eigenpairs>, SolveError> {
    let a = Pattern::combine(k, s, m);
    match eigen::largest(pattern, (&a, m), modes, solver) {
        Ok(found) => Ok(Some(found)),
        Err(PencilError::NotDefinite) => Ok(None),
        Err(PencilError::Failed(why)) => Err(SolveError::InvalidMechanism(format!(
            "modal analysis: {why}"
        ))),
    }
}

/// `Σ|Kᵢᵢ|` of compressed-column values.
fn diagonal_sum(pattern: &Pattern, k: &[f64]) -> f64 {
    pattern.diagonal(k).iter().map(|v| v.abs()).sum()
}

/// `modes` must be at least 1 and at most the unknowns.
fn check_count(modes: usize, unknowns: usize) -> Result<(), SolveError> {
    if modes == 0 || modes > unknowns {
        return Err(SolveError::InvalidMechanism(format!(
            "`solver.modes` = {modes}: the mechanism has {unknowns} unknowns; ask for 1 to \
             {unknowns} modes"
        )));
    }
    Ok(())
}

/// `v` with the sign that makes its largest-magnitude entry positive (the
/// same shapes on every run).
fn oriented(mut v: Vec<f64>) -> Vec<f64> {
    let big = v
        .iter()
        .fold(0.0f64, |b, x| if x.abs() > b.abs() { *x } else { b });
    if big < 0.0 {
        v.iter_mut().for_each(|x| *x = -*x);
    }
    v
}

#[cfg(test)]
mod tests;
