//! Every fixed tolerance of the solvers, named once with its meaning. The
//! user's own settings — the Newton tolerance on the scaled residual, the
//! iteration and halving limits — are in [`crate::NewtonSettings`] and the
//! analyses' settings; what is here follows from round-off and is the same
//! for every model.

/// The solvers' fixed tolerances (see [`TOLERANCES`] for the values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Newton has diverged when the scaled residual has grown by this factor
    /// over the first iterate's (or the tolerance, if larger): `10⁸`.
    pub divergence_growth: f64,
    /// A residual at the round-off floor has stopped falling when it is not
    /// below this fraction of the previous one: `½`.
    pub stall_ratio: f64,
    /// Modified Newton refactors when a residual is not below this fraction
    /// of the previous one: `½`.
    pub modified_contraction: f64,
    /// Newton switches from an approximate tangent to the exact one when a
    /// residual is not below this fraction of the previous one: `1/20`
    /// (the exact tangent's quadratic convergence then wins within the
    /// iterations a step usually takes).
    pub inexact_contraction: f64,
    /// The band LU keeps a column's diagonal pivot while it is at least this
    /// fraction of the column's largest entry on the equilibrated matrix:
    /// `1/10` (threshold partial pivoting; the growth of the entries per
    /// interchange is then at most `1 + 1/τ`).
    pub pivot_threshold: f64,
    /// Condition number of the equilibrated tangent above which a solution
    /// is not unique (a mechanism): `1/(100 ε)`. A null direction gives
    /// `κ ≳ 1/ε`; a slender cantilever of a thousand elements with
    /// `EA/EI = 10⁵` has `κ ≈ 10¹⁰`.
    pub singular_condition: f64,
    /// A factorisation whose smallest equilibrated pivot is above this
    /// fraction of its largest has its converged solve's singularity check
    /// (a condition estimate, two more solves) left out: `10⁻⁹`. A null
    /// direction leaves a pivot of round-off size (`≈ ε` of the largest) in
    /// an elimination with pivoting, and `κ ≳ 1/ε`; the check refuses from
    /// `κ > 1/(100 ε)` — five orders below this alarm.
    pub pivot_alarm: f64,
    /// A run has reached its end (`t_end`, or the load factor 1) when it is
    /// within this fraction of it: `10⁻¹²` (round-off of summed steps).
    pub end_of_run: f64,
    /// A time (or load level) within this fraction of a step of a multiple
    /// of the nominal step is that multiple: `10⁻⁹`.
    pub level_snap: f64,
    /// The paper's energy–momentum border pivot `d − cᵀK⁻¹b` has vanished
    /// (β has no lever on the energy) below this fraction of its terms'
    /// size: `10⁻¹⁰`.
    pub border_pivot: f64,
    /// The energy residual of the paper's scheme is round-off below this
    /// multiple of ε times the energy terms' size: `64 ε`.
    pub energy_round_off: f64,
}

/// The values in force.
pub const TOLERANCES: Tolerances = Tolerances {
    divergence_growth: 1e8,
    stall_ratio: 0.5,
    modified_contraction: 0.5,
    inexact_contraction: 0.05,
    pivot_threshold: 0.1,
    singular_condition: 1.0 / (100.0 * f64::EPSILON),
    pivot_alarm: 1e-9,
    end_of_run: 1e-12,
    level_snap: 1e-9,
    border_pivot: 1e-10,
    energy_round_off: 64.0 * f64::EPSILON,
};
