//! Modes of a spinning structure: `(λ²M + λG + K) φ = 0` with the
//! skew-symmetric gyroscopic matrix `G` (FORMULATION §6).
//!
//! With `K` and `M` positive definite the first-order form `z = [q; q̇]`,
//! `P ż = Q z`, `P = [K 0; 0 M]`, `Q = [0 K; −K −G]`, has `P` symmetric
//! positive definite and `Q` skew-symmetric: the eigenvalues are `λ = iω`,
//! and with `P = LLᵀ` (`L = [L_K 0; 0 L_M]`) the matrix `H = i L⁻¹QL⁻ᵀ` is
//! Hermitian, `H w = −ω w` — faer's Hermitian eigen-decomposition (robust
//! and to round-off), never a general non-symmetric one. The blocks are
//! `L⁻¹QL⁻ᵀ = [0  L_Kᵀ L_M⁻ᵀ; −L_M⁻¹L_K  −L_M⁻¹ G L_M⁻ᵀ]`, and
//! `q = L_K⁻ᵀ w_top`. The three matrices are scaled by `D = diag(K)^-½`
//! first. A spinning state whose `K` is not positive definite (past a
//! stability limit, or free to move rigidly) is refused.

use super::eigen::{EigenSolver, PencilError};
use super::linearise::Linearisation;
use super::pencil::Pattern;
use super::{ComplexParts, ModeKind, ModeSet, RIGID_MODE};
use crate::error::SolveError;
use faer::{c64, Mat, Side};

/// Eigenvalues `λ` and vectors `φ` of the quadratic problem.
pub(crate) type ComplexPairs = (Vec<c64>, Vec<Vec<c64>>);

/// Every eigenpair `λ = iω`, `ω > 0`, of `(λ²M + λG + K)φ = 0`, by
/// increasing `ω`.
pub(crate) fn quadratic(
    pattern: &Pattern,
    (k, g, m): (&[f64], &[f64], &[f64]),
) -> Result<ComplexPairs, PencilError> {
    let n = pattern.n();
    let d: Vec<f64> = pattern
        .diagonal(k)
        .iter()
        .map(|v| if *v > 0.0 { 1.0 / v.sqrt() } else { 1.0 })
        .collect();
    let (k, g, m) = (
        pattern.dense(&pattern.scaled(k, &d)),
        pattern.dense(&pattern.scaled(g, &d)),
        pattern.dense(&pattern.scaled(m, &d)),
    );
    let lk = k.llt(Side::Lower).map_err(|_| PencilError::NotDefinite)?;
    let lm = m.llt(Side::Lower).map_err(|_| PencilError::NotDefinite)?;
    let (lk, lm) = (lk.L(), lm.L());
    // S12 = L_Kᵀ L_M⁻ᵀ = (L_M⁻¹ L_K)ᵀ; S22 = −L_M⁻¹ G L_M⁻ᵀ.
    let mut s21 = lk.to_owned();
    lm.solve_lower_triangular_in_place(&mut s21);
    let mut x = g.clone();
    lm.solve_lower_triangular_in_place(&mut x);
    let mut s22 = x.transpose().to_owned();
    lm.solve_lower_triangular_in_place(&mut s22);
    // s22 now holds L_M⁻¹ (L_M⁻¹ G)ᵀ = −L_M⁻¹ G L_M⁻ᵀ (G skew).
    let h = Mat::<c64>::from_fn(2 * n, 2 * n, |i, j| {
        let v = match (i < n, j < n) {
            (true, true) => 0.0,
            (true, false) => s21[(j - n, i)],
            (false, true) => -s21[(i - n, j)],
            (false, false) => s22[(i - n, j - n)],
        };
        c64::new(0.0, v)
    });
    let evd = h
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| PencilError::Failed(format!("Hermitian eigen-decomposition failed: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let lkc = Mat::<c64>::from_fn(n, n, |i, j| c64::new(lk[(i, j)], 0.0));
    let mut pairs: Vec<(c64, Vec<c64>)> = (0..2 * n)
        .filter(|&p| s[p].re < 0.0)
        .map(|p| {
            let omega = -s[p].re;
            let mut top = Mat::<c64>::from_fn(n, 1, |i, _| u[(i, p)]);
            lkc.transpose().solve_upper_triangular_in_place(&mut top);
            let phi = (0..n).map(|i| top[(i, 0)] * d[i]).collect();
            (c64::new(0.0, omega), phi)
        })
        .collect();
    pairs.sort_by(|a, b| a.0.im.total_cmp(&b.0.im));
    Ok(pairs.into_iter().unzip())
}

/// The `modes` lowest modes of the spinning mechanism linearised in `lin`
/// (tangent `k`, mass `m`, `ω_ref² = reference`): frequencies `Im λ / 2π`,
/// damping ratios `−Re λ/|λ|`, shapes `φ` scaled to `φᴴMφ = 1` with their
/// largest entry real and positive, the whirl of each mode about the spin
/// axis.
pub(crate) fn spinning_modes(
    lin: &mut Linearisation<'_>,
    (k, m): (&[f64], &[f64]),
    modes: usize,
    reference: f64,
    asymmetry: f64,
) -> Result<ModeSet, SolveError> {
    let n = lin.unknowns();
    let g = lin.gyroscopic();
    let (lambdas, vectors) = quadratic(&lin.pattern, (k, &g, m)).map_err(|e| {
        SolveError::InvalidMechanism(match e {
            PencilError::NotDefinite => "modal analysis of the spinning mechanism: its \
                 stiffness (with the centrifugal softening) or its mass is not positive \
                 definite — a state past a stability limit or a free rigid motion; its modes \
                 are not computed"
                .into(),
            PencilError::Failed(why) => format!("modal analysis: {why}"),
        })
    })?;
    if lambdas.len() < modes {
        return Err(SolveError::InvalidMechanism(format!(
            "modal analysis: only {} modes of the spinning mechanism found, {modes} asked",
            lambdas.len()
        )));
    }
    let axis = lin.spin_axis().unwrap_or_else(nalgebra::Vector3::z);
    let mut set = ModeSet::empty(ModeKind::Vibration, EigenSolver::Dense, n, asymmetry);
    let mut parts = ComplexParts::default();
    for (lambda, phi) in lambdas.into_iter().zip(vectors).take(modes) {
        let rigid = lambda.norm() <= (RIGID_MODE * reference).sqrt();
        let omega = if rigid { 0.0 } else { lambda.im };
        set.rigid += usize::from(rigid);
        let (re, im) = normalised(&lin.pattern, m, &phi);
        let (u_re, th_re, released) = lin.expand(&re);
        let (u_im, th_im, _) = lin.expand(&im);
        parts.damping_ratio.push(if rigid {
            0.0
        } else {
            -lambda.re / lambda.norm()
        });
        parts.whirl.push(whirl(&u_re, &u_im, &axis));
        parts.displacement.push(u_im);
        parts.rotation.push(th_im);
        set.push(omega * omega, (u_re, th_re, released));
    }
    set.complex = Some(parts);
    Ok(set)
}

/// The real and imaginary parts of `φ` scaled to `φᴴMφ = 1`, the largest
/// entry turned real and positive.
fn normalised(pattern: &Pattern, m: &[f64], phi: &[c64]) -> (Vec<f64>, Vec<f64>) {
    let big = phi.iter().copied().fold(
        c64::new(0.0, 0.0),
        |b, x| if x.norm() > b.norm() { x } else { b },
    );
    let phase = if big.norm() > 0.0 {
        big.conj() / big.norm()
    } else {
        c64::new(1.0, 0.0)
    };
    let turned: Vec<c64> = phi.iter().map(|x| x * phase).collect();
    let re: Vec<f64> = turned.iter().map(|x| x.re).collect();
    let im: Vec<f64> = turned.iter().map(|x| x.im).collect();
    let norm = (pattern.form(m, &re, &re) + pattern.form(m, &im, &im)).sqrt();
    let s = if norm > 0.0 { 1.0 / norm } else { 1.0 };
    (
        re.iter().map(|v| v * s).collect(),
        im.iter().map(|v| v * s).collect(),
    )
}

/// The whirl of a mode about `axis`: the nodes' orbits `a cos ωt − b sin ωt`
/// turn with the spin (+1) or against it (−1), summed over the nodes
/// (`−Σ (aᵢ × bᵢ)·axis`); 0 where the orbits enclose no area (below
/// `WHIRL_ZERO` of `Σ|aᵢ||bᵢ|`: a planar motion).
fn whirl(
    a: &[nalgebra::Vector3<f64>],
    b: &[nalgebra::Vector3<f64>],
    axis: &nalgebra::Vector3<f64>,
) -> f64 {
    let area: f64 = a.iter().zip(b).map(|(a, b)| -a.cross(b).dot(axis)).sum();
    let scale: f64 = a.iter().zip(b).map(|(a, b)| a.norm() * b.norm()).sum();
    if area.abs() <= WHIRL_ZERO * scale {
        0.0
    } else {
        area.signum()
    }
}

/// Orbit area below this part of `Σ|aᵢ||bᵢ|` is no whirl.
const WHIRL_ZERO: f64 = 1e-6;
