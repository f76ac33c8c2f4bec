//! What a solver hands out after every converged step: a plain value that the
//! HDF5 writer, charts and tests consume. Nothing here knows about files.

/// Energies of the whole mechanism at the end of a step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// Kinetic energy `T = ½∫(A_ρ ṙ·ṙ + W·J_ρ W) ds` (zero in statics).
    pub kinetic: f64,
    /// Strain energy `Π = ½∫(Γ·C_N Γ + K·C_M K) ds`.
    pub strain: f64,
    /// Potential of gravity and of dead external loads (`−Σ f·u`); minus
    /// the follower loads' work and plus the damping's dissipation since
    /// t = 0 stand for the potential those forces do not have.
    pub potential: f64,
    /// `kinetic + strain + potential`.
    pub total: f64,
    /// Work done on the mechanism since t = 0 by its drivers: driven joint
    /// coordinates and prescribed nodal DOFs (`Σ pᵢ·gᵢ` of each step, the
    /// reactions' work). With drivers `total − driver_work` is the conserved
    /// quantity of a conservative system. Zero in statics.
    pub driver_work: f64,
    /// Energy dissipated by structural damping since t = 0 (included in
    /// `potential` and `total`).
    pub dissipated: f64,
}

/// State of one joint at the end of a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointRecord {
    /// Released angle ψ about the joint axis (NaN for a kind without one,
    /// e.g. prismatic or rigid; see `JointKinematics::reported_angle`).
    pub angle: f64,
    /// Released translation `r_R` in the master frame.
    pub released_translation: [f64; 3],
    /// `‖r_s − r_m − Λ_m f(ψ)‖ + ‖Λ_mᵀΛ_s − exp(ψ t̂)‖` (Frobenius).
    pub constraint_error: f64,
    /// What the joint exerts on its slave node in the step's equations:
    /// force, then moment (global components). NaN in records taken before
    /// any step (no residual has been evaluated yet).
    pub reaction: [f64; 6],
}

/// One converged (time or load) step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    /// Time at the end of the step (statics: the load factor).
    pub time: f64,
    /// Step size actually used, after halvings.
    pub dt: f64,
    /// Newton iterations of the step.
    pub iterations: usize,
    /// Tangent factorisations of the step (equal to `iterations` with full
    /// Newton; fewer with modified Newton, which reuses one).
    pub factorizations: usize,
    /// Final scaled residual norm.
    pub residual: f64,
    /// Scaled residual after each Newton iteration (index 0: before the first solve).
    pub residual_history: Vec<f64>,
    /// Energy–momentum β of the step; NaN for the other integrators and statics.
    pub beta: f64,
    /// Energies at the end of the step.
    pub energy: Energies,
    /// Total linear momentum.
    pub momentum_linear: [f64; 3],
    /// Total angular momentum about the origin.
    pub momentum_angular: [f64; 3],
    /// Position of every node.
    pub positions: Vec<[f64; 3]>,
    /// Rotation of every node's triad from its initial configuration, as a unit
    /// quaternion `(w, x, y, z)`.
    pub quaternions: Vec<[f64; 4]>,
    /// One record per joint, in model order.
    pub joints: Vec<JointRecord>,
    /// What holds each node of `Mechanism::supported_nodes`: force, then
    /// moment, at its fixed and prescribed DOFs (zero at free ones). NaN in
    /// records taken before any step.
    pub support_reactions: Vec<[f64; 6]>,
    /// Dynamics: every node's translational velocity `v` (spatial); empty
    /// in statics.
    pub velocities: Vec<[f64; 3]>,
    /// Dynamics: every node's angular velocity in spatial components,
    /// `ω = R W` (`Ṙ = ω̂ R`); empty in statics.
    pub angular_velocities: Vec<[f64; 3]>,
    /// Statics: the number of negative eigenvalues of the converged reduced
    /// tangent (see [`crate::stability`]); non-zero means the equilibrium
    /// is unstable (past a bifurcation or limit point). `None` in dynamics.
    pub negative_pivots: Option<usize>,
    /// Statics with sensitivities (`statics::solve_static_with`): one per
    /// parameter, in the order given; empty otherwise.
    pub sensitivities: Vec<Sensitivity>,
    /// Statics: the critical point (limit or bifurcation) located between
    /// the previous step and this one, where the stability count changed
    /// (see [`crate::critical`]); `None` otherwise.
    pub critical: Option<crate::critical::CriticalPoint>,
}

/// The exact derivatives of one step's results with respect to one
/// parameter `p` (see [`crate::sensitivity`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sensitivity {
    /// `dx/dp` of every node's position.
    pub displacement: Vec<[f64; 3]>,
    /// `d(total energy)/dp` ([`Energies::total`]); NaN where the total is
    /// path-dependent (follower loads).
    pub energy: f64,
}
