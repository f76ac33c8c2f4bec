//! Linear buckling: the load factors `λ` at which `K_material + λ K_geometric`
//! becomes singular about the undeformed state, with the prestress of the
//! model's loads — the classical buckling estimate.
//!
//! 1. `K₀`, the tangent of the undeformed, unloaded state;
//! 2. the linear solution `u₁ = K₀⁻¹ f` of the loads at λ = 1 and its strain
//!    rates at every Gauss point (dual numbers through the strains);
//! 3. the tangent `K₁` of the undeformed state of the mechanism whose
//!    elements carry those strains as stress, with the loads at λ = 1 (the
//!    joints' blocks see the slaves' reactions): `K_geometric = K₁ − K₀`
//!    exactly, the stress's part only ([`flexmech_core::prestress`]);
//! 4. the largest `μ = 1/λ > 0` of `−K_geometric φ = μ K₀ φ` ([`super::eigen`]).

use super::eigen::{self, EigenSolver, PencilError};
use super::linearise::Linearisation;
use super::pencil::SYMMETRIC;
use super::{check_count, oriented, ModeKind, ModeSet};
use crate::constraints::initial_state;
use crate::error::SolveError;
use crate::linsolve::SparseLu;
use crate::mechanism::Mechanism;

/// The `modes` lowest positive buckling load factors of `mech` under its
/// loads (at load factor 1) and their modes, each scaled to a largest nodal
/// displacement of 1 (largest rotation where no node moves); `solver`
/// `None` chooses by the unknowns.
pub fn buckling_modes(
    mech: &Mechanism,
    modes: usize,
    solver: Option<EigenSolver>,
) -> Result<ModeSet, SolveError> {
    if mech.has_drivers() {
        return Err(SolveError::InvalidMechanism(
            "buckling analysis multiplies the model's loads; prescribed motions and driven \
             joints are not loads: remove them (hold the DOFs with `fixed`)"
                .into(),
        ));
    }
    let state = initial_state(mech);
    let mut lin0 = Linearisation::at(mech, &state, None)?;
    let n = lin0.unknowns();
    check_count(modes, n)?;
    let mut k0 = lin0.tangent();
    let asymmetry = lin0.pattern.symmetrize(&mut k0);
    let u1 = linear_solution(&lin0, &k0)?;
    let (dx, dth, _) = lin0.expand(&u1);
    let mut prestressed = mech.clone();
    let (x0, rot0) = (&state.config.x, &state.config.rot);
    for e in &mut prestressed.mesh.elements {
        let rates = e.strain_rates((x0, rot0), (&dx, &dth));
        *e = e.prestrained(&rates);
    }
    let mut lin1 = Linearisation::at(&prestressed, &state, Some(1.0))?;
    let k1 = lin1.tangent();
    let mut b: Vec<f64> = k1.iter().zip(&k0).map(|(a, c)| c - a).collect();
    let asym_g = lin0.pattern.symmetrize(&mut b);
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return Err(SolveError::InvalidMechanism(
            "buckling analysis: the loads leave the mechanism without stress (no load, or \
             loads that only move it rigidly): nothing to buckle"
                .into(),
        ));
    }
    if asym_g > SYMMETRIC * 1e3 {
        return Err(SolveError::InvalidMechanism(format!(
            "buckling analysis: the geometric stiffness is not symmetric (relative asymmetry \
             {asym_g:.1e}; follower loads): use dead loads"
        )));
    }
    let solver = solver.unwrap_or(EigenSolver::for_unknowns(n));
    let (mu, vectors) = match eigen::largest(&lin0.pattern, (&k0, &b), modes, solver) {
        Ok(r) => r,
        Err(PencilError::NotDefinite) => return Err(unsupported()),
        Err(PencilError::Failed(why)) => {
            return Err(SolveError::InvalidMechanism(format!(
                "buckling analysis: {why}"
            )))
        }
    };
    let mut set = ModeSet::empty(ModeKind::Buckling, solver, n, asymmetry);
    for (mu, y) in mu.into_iter().zip(vectors).filter(|(mu, _)| *mu > 0.0) {
        let (u, theta, _) = lin0.expand(&y);
        let big = |v: &[nalgebra::Vector3<f64>]| v.iter().fold(0.0f64, |b, x| b.max(x.norm()));
        let norm = if big(&u) > 0.0 { big(&u) } else { big(&theta) };
        let phi = oriented(y.iter().map(|v| v / norm).collect());
        set.push(1.0 / mu, lin0.expand(&phi));
    }
    if set.eigenvalues.is_empty() {
        return Err(SolveError::InvalidMechanism(
            "buckling analysis: no positive load factor — the loads stiffen the mechanism \
             (reverse them to find where it buckles)"
                .into(),
        ));
    }
    Ok(set)
}

/// `u₁ = K₀⁻¹ f`, the linear response to the loads at load factor 1.
fn linear_solution(lin: &Linearisation<'_>, k0: &[f64]) -> Result<Vec<f64>, SolveError> {
    let mut lu = SparseLu::new(lin.pattern.symbolic.clone()).map_err(SolveError::Singular)?;
    let mut u = lin.reduced_load(1.0);
    lu.factor(k0).map_err(|_| unsupported())?;
    lu.solve(&mut u).map_err(|_| unsupported())?;
    Ok(u)
}

/// The error of a mechanism whose unloaded tangent is singular.
fn unsupported() -> SolveError {
    SolveError::Singular(
        "buckling analysis: the unloaded tangent is singular or not positive definite — a \
         rigid motion or a mechanism is not held (support every rigid-body motion)"
            .into(),
    )
}
