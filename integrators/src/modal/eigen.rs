//! The largest eigenvalues of a symmetric-definite pencil `B y = μ A y`
//! (`A` positive definite, `B` symmetric): what both the vibration modes
//! (shift-invert, `A = K + sM`, `B = M`, `μ = 1/(ω² + s)`) and the buckling
//! modes (`A = K_material`, `B = −K_geometric`, `μ = 1/λ`) are.
//!
//! Two solvers, one answer. **Dense** (faer): `A = LLᵀ`,
//! `C = L⁻¹BL⁻ᵀ`, the symmetric eigen-decomposition of `C`, `y = L⁻ᵀu` —
//! every eigenvalue to round-off of the largest `|μ|`, `O(n³)`. **Sparse**:
//! faer's Krylov–Schur (restarted Arnoldi) on the operator `A⁻¹B` applied
//! by the sparse LU of `A`, then a Rayleigh–Ritz step in the `A`-inner
//! product on the span of the converged vectors (real and imaginary parts:
//! repeated eigenvalues, such as the two bending planes of a round section,
//! come out as a basis of their space, A-orthonormal) — `O(n)` per
//! iteration on a chain. The sparse solver is checked against the dense one.

use super::pencil::Pattern;
use crate::linsolve::SparseLu;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::matrix_free::eigen::{partial_eigen, partial_eigen_scratch, PartialEigenParams};
use faer::matrix_free::LinOp;
use faer::{c64, Mat, MatMut, MatRef, Par, Side};
use std::sync::Mutex;

/// Unknowns up to which the dense solver is used.
pub const DENSE_UNKNOWNS: usize = 600;

/// Relative tolerance of the Krylov iteration's converged Ritz pairs.
const KRYLOV_TOLERANCE: f64 = 1e-12;

/// Extra Ritz vectors asked of the Krylov iteration beyond those wanted (a
/// cluster that straddles the last wanted eigenvalue is then whole).
const KRYLOV_EXTRA: usize = 6;

/// A vector whose `A`-norm after orthogonalisation falls below this part of
/// its norm before lies in the span of the others (Rayleigh–Ritz).
const DEPENDENT: f64 = 1e-8;

/// Passes of subspace iteration that polish the Krylov iteration's Ritz
/// space.
const SUBSPACE_PASSES: usize = 4;

/// Backward error `‖By − μAy‖ / ((|μ|‖A‖ + ‖B‖)‖y‖)` (Frobenius norms)
/// above which a sparse mode is refused rather than reported: the pair is
/// then not the exact one of any pencil that close to this one.
const MODE_RESIDUAL: f64 = 1e-10;

/// Eigenvalues `μ` (descending) and their vectors.
pub(crate) type Eigenpairs = (Vec<f64>, Vec<Vec<f64>>);

/// Which solver found the eigenpairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EigenSolver {
    /// Dense symmetric eigen-decomposition (faer).
    Dense,
    /// Sparse shift-invert Krylov–Schur with a Rayleigh–Ritz step.
    Sparse,
}

impl EigenSolver {
    /// The name results record (`"dense"`, `"sparse"`).
    pub fn name(self) -> &'static str {
        match self {
            EigenSolver::Dense => "dense",
            EigenSolver::Sparse => "sparse",
        }
    }

    /// The solver for `n` unknowns.
    pub fn for_unknowns(n: usize) -> Self {
        if n <= DENSE_UNKNOWNS {
            EigenSolver::Dense
        } else {
            EigenSolver::Sparse
        }
    }
}

/// Why a pencil has no answer.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum PencilError {
    /// `A` is not positive definite.
    NotDefinite,
    /// The solver failed (the message says how).
    Failed(String),
}

/// The `count` largest eigenvalues `μ` of `B y = μ A y`, descending, with
/// their `A`-orthonormal vectors.
pub(crate) fn largest(
    pattern: &Pattern,
    (a, b): (&[f64], &[f64]),
    count: usize,
    solver: EigenSolver,
) -> Result<Eigenpairs, PencilError> {
    let count = count.min(pattern.n());
    // Symmetric diagonal scaling `D A D`, `D = diag(A)^-½`: translations and
    // rotations in model units (and sections whose rotary inertia is
    // orders below their mass) otherwise cost digits in the factorisation.
    let d = pattern.diagonal(a);
    if d.iter().any(|v| v.is_nan() || *v <= 0.0) {
        return Err(PencilError::NotDefinite);
    }
    let d: Vec<f64> = d.iter().map(|v| 1.0 / v.sqrt()).collect();
    let (sa, sb) = (pattern.scaled(a, &d), pattern.scaled(b, &d));
    let (values, mut vectors) = match solver {
        EigenSolver::Dense => dense(pattern, (&sa, &sb), count)?,
        EigenSolver::Sparse => sparse(pattern, (&sa, &sb), count)?,
    };
    for y in &mut vectors {
        y.iter_mut().zip(&d).for_each(|(v, s)| *v *= s);
    }
    Ok((values, vectors))
}

/// The dense solver (see the module docs).
fn dense(
    pattern: &Pattern,
    (a, b): (&[f64], &[f64]),
    count: usize,
) -> Result<Eigenpairs, PencilError> {
    let n = pattern.n();
    let am = pattern.dense(a);
    let llt = am.llt(Side::Lower).map_err(|_| PencilError::NotDefinite)?;
    let l = llt.L();
    let mut x = pattern.dense(b);
    l.solve_lower_triangular_in_place(&mut x);
    let mut c = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut c);
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| PencilError::Failed(format!("dense eigen-decomposition failed: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let mut values = Vec::with_capacity(count);
    let mut vectors = Vec::with_capacity(count);
    for k in (n - count..n).rev() {
        let mut y = u.col(k).to_owned();
        l.transpose()
            .solve_upper_triangular_in_place(y.as_mat_mut());
        values.push(s[k]);
        vectors.push((0..n).map(|i| y[i]).collect());
    }
    Ok((values, vectors))
}

/// The operator `A⁻¹B` applied by the sparse LU of `A`.
struct ShiftInvert<'p> {
    pattern: &'p Pattern,
    b: &'p [f64],
    lu: Mutex<SparseLu>,
}

impl std::fmt::Debug for ShiftInvert<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShiftInvert(n = {})", self.pattern.n())
    }
}

impl LinOp<f64> for ShiftInvert<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.pattern.n()
    }
    fn ncols(&self) -> usize {
        self.pattern.n()
    }
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _: Par, _: &mut MemStack) {
        let n = self.pattern.n();
        let mut lu = self.lu.lock().unwrap_or_else(|p| p.into_inner());
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..rhs.ncols() {
            (0..n).for_each(|i| x[i] = rhs[(i, j)]);
            self.pattern.product(self.b, &x, &mut y);
            // A non-finite solve stays non-finite and fails the residual check.
            let _ = lu.solve(&mut y);
            (0..n).for_each(|i| out[(i, j)] = y[i]);
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, s: &mut MemStack) {
        self.apply(out, rhs, par, s)
    }
}

/// The sparse solver (see the module docs).
fn sparse(
    pattern: &Pattern,
    (a, b): (&[f64], &[f64]),
    count: usize,
) -> Result<Eigenpairs, PencilError> {
    let n = pattern.n();
    let mut lu = SparseLu::new(pattern.symbolic.clone()).map_err(PencilError::Failed)?;
    lu.factor(a).map_err(|_| PencilError::NotDefinite)?;
    let op = ShiftInvert {
        pattern,
        b,
        lu: Mutex::new(lu),
    };
    let wanted = (count + KRYLOV_EXTRA).min(n);
    let params = PartialEigenParams::default();
    let mut mem = MemBuffer::new(partial_eigen_scratch(&op, wanted, Par::Seq, params));
    let mut vecs = Mat::<c64>::zeros(n, wanted);
    let mut vals = vec![c64::new(0.0, 0.0); wanted];
    // A fixed start: the same modes on every run and thread count.
    let v0 = faer::Col::from_fn(n, |i| 1.0 + ((i * 7919) % 101) as f64 / 101.0);
    let info = partial_eigen(
        vecs.as_mut(),
        &mut vals,
        &op,
        v0.as_ref(),
        KRYLOV_TOLERANCE,
        Par::Seq,
        MemStack::new(&mut mem),
        params,
    );
    if info.n_converged_eigen < count {
        return Err(PencilError::Failed(format!(
            "the Krylov iteration converged {} of the {count} eigenpairs asked",
            info.n_converged_eigen
        )));
    }
    let mut candidates = Vec::new();
    for j in 0..info.n_converged_eigen {
        candidates.push((0..n).map(|i| vecs[(i, j)].re).collect());
        candidates.push((0..n).map(|i| vecs[(i, j)].im).collect());
    }
    // A single-vector Krylov space holds one direction of each repeated
    // eigenvalue (the second bending plane of a round section arrives only
    // through round-off): fixed pseudo-random vectors join the space, and
    // subspace iteration on it divides the error of the wanted vectors by
    // `μ_wanted/μ_next` per pass, repeated eigenvalues together.
    candidates.extend((0..count).map(|c| {
        (0..n)
            .map(|i| (((i + 1) * (c + 3) * 2_654_435_761) % 1_000_003) as f64 / 1_000_003.0 - 0.5)
            .collect()
    }));
    let mut basis = a_orthonormal(pattern, a, candidates)?;
    for _ in 0..SUBSPACE_PASSES {
        let op = &op;
        let applied: Vec<Vec<f64>> = basis
            .iter()
            .map(|q| {
                let mut out = Mat::<f64>::zeros(n, 1);
                let rhs = MatRef::from_column_major_slice(q, n, 1);
                op.apply(out.as_mut(), rhs, Par::Seq, MemStack::new(&mut []));
                (0..n).map(|i| out[(i, 0)]).collect()
            })
            .collect();
        basis = a_orthonormal(pattern, a, applied)?;
    }
    ritz(pattern, (a, b), &basis, count)
}

/// An `A`-orthonormal basis of the span of `candidates` (modified
/// Gram–Schmidt, twice; a vector already in the span is dropped).
fn a_orthonormal(
    pattern: &Pattern,
    a: &[f64],
    candidates: Vec<Vec<f64>>,
) -> Result<Vec<Vec<f64>>, PencilError> {
    let n = pattern.n();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut av = vec![0.0; n];
    for mut v in candidates {
        let before = pattern.form(a, &v, &v).max(0.0).sqrt();
        if before == 0.0 || !before.is_finite() {
            continue;
        }
        for _ in 0..2 {
            pattern.product(a, &v, &mut av);
            for q in &basis {
                let c: f64 = q.iter().zip(&av).map(|(x, y)| x * y).sum();
                v.iter_mut().zip(q).for_each(|(x, y)| *x -= c * y);
            }
        }
        let after = pattern.form(a, &v, &v);
        if after.is_nan() || after <= 0.0 {
            return Err(PencilError::NotDefinite);
        }
        if after.sqrt() > DEPENDENT * before {
            let s = 1.0 / after.sqrt();
            basis.push(v.iter().map(|x| x * s).collect());
        }
    }
    Ok(basis)
}

/// Rayleigh–Ritz on the `A`-orthonormal `basis`: the `count` largest
/// eigenvalues of `VᵀBV`, their vectors `V u`, each checked by its backward error.
fn ritz(
    pattern: &Pattern,
    (a, b): (&[f64], &[f64]),
    basis: &[Vec<f64>],
    count: usize,
) -> Result<Eigenpairs, PencilError> {
    let (n, m) = (pattern.n(), basis.len());
    if m < count {
        return Err(PencilError::Failed(format!(
            "the Krylov iteration spans {m} independent vectors, fewer than the {count} asked"
        )));
    }
    let mut bv = vec![vec![0.0; n]; m];
    for (q, out) in basis.iter().zip(bv.iter_mut()) {
        pattern.product(b, q, out);
    }
    let c = Mat::from_fn(m, m, |i, j| {
        let s: f64 = basis[i].iter().zip(&bv[j]).map(|(x, y)| x * y).sum();
        let t: f64 = basis[j].iter().zip(&bv[i]).map(|(x, y)| x * y).sum();
        0.5 * (s + t)
    });
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| PencilError::Failed(format!("Ritz eigen-decomposition failed: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let (mut values, mut vectors) = (Vec::new(), Vec::new());
    let (mut ay, mut by) = (vec![0.0; n], vec![0.0; n]);
    let frobenius = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (norm_a, norm_b) = (frobenius(a), frobenius(b));
    for k in (m - count..m).rev() {
        let mut y = vec![0.0; n];
        for (r, q) in basis.iter().enumerate() {
            y.iter_mut().zip(q).for_each(|(x, v)| *x += u[(r, k)] * v);
        }
        pattern.product(a, &y, &mut ay);
        pattern.product(b, &y, &mut by);
        let mu = s[k];
        let res = by
            .iter()
            .zip(&ay)
            .map(|(x, z)| (x - mu * z).powi(2))
            .sum::<f64>()
            .sqrt();
        let scale = (mu.abs() * norm_a + norm_b) * frobenius(&y);
        if res.is_nan() || res > MODE_RESIDUAL * scale {
            return Err(PencilError::Failed(format!(
                "eigenpair {} did not converge (backward error {:.1e})",
                m - k,
                res / scale
            )));
        }
        values.push(mu);
        vectors.push(y);
    }
    Ok((values, vectors))
}
