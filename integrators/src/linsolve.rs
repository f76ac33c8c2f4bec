//! Sparse LU solves: the structure (ordering, elimination structure) is
//! analysed once per sparsity pattern; every Newton iteration only
//! refactors numerically, into buffers allocated once. Two backends, chosen
//! per pattern: a band LU after a reverse Cuthill–McKee renumbering
//! ([`crate::band_lu`]) when the band is narrow — beam mechanisms, where it
//! measured several times faster — and faer's general sparse LU otherwise.
//! A long band is factorised in two halves at once
//! ([`crate::band_split`]); the operations are the same for any number of
//! threads, so results do not depend on the thread count.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};

use crate::band_lu::{equilibrating_scale, BandLu, BandStructure};
use crate::band_split::{SplitBandLu, SPLIT_MIN_UNKNOWNS};

/// Shift `σ`, relative to the equilibrated tangent's norm `‖B‖∞`, of the
/// inverse iteration that finds the null direction of an exactly singular
/// tangent ([`SparseLu::condition_estimate`]): `B + σI` is regular (`σ` is
/// far above round-off), and two steps of the iteration grow the null
/// direction by `1/σ` each against `1/(λ + σ)` for a direction of
/// eigenvalue `λ`, so the null direction dominates wherever the held parts'
/// stiffness is above `σ`.
pub const NULL_SHIFT: f64 = 1e-10;

/// A matrix in a solver's pattern: its values with the pattern.
#[derive(Clone, Copy)]
pub struct TangentRef<'a> {
    /// The CSC pattern.
    pub pattern: &'a SymbolicSparseColMat<usize>,
    /// The CSC values.
    pub values: &'a [f64],
}

impl TangentRef<'_> {
    /// The equilibrating scale `dᵢ = |aᵢᵢ|^-½` (the mean diagonal where a
    /// diagonal entry is zero; see [`equilibrating_scale`]).
    pub fn equilibration(&self) -> Vec<f64> {
        let n = self.pattern.nrows();
        let (col_ptr, row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut diag = vec![0.0f64; n];
        for (j, d) in diag.iter_mut().enumerate() {
            let range = col_ptr[j]..col_ptr[j + 1];
            if let Some(k) = row_idx[range.clone()].iter().position(|&r| r == j) {
                *d = self.values[range.start + k];
            }
        }
        equilibrating_scale(&diag)
    }

    /// `‖D A D‖∞` for the scale `d` of [`TangentRef::equilibration`].
    pub fn scaled_norm(&self, d: &[f64]) -> f64 {
        let n = self.pattern.nrows();
        let (col_ptr, row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut rows = vec![0.0f64; n];
        for j in 0..n {
            for k in col_ptr[j]..col_ptr[j + 1] {
                rows[row_idx[k]] += self.values[k].abs() * d[row_idx[k]] * d[j];
            }
        }
        rows.iter().fold(0.0f64, |m, &v| m.max(v))
    }

    /// The product `A x`.
    pub fn product(&self, x: &[f64]) -> Vec<f64> {
        let n = self.pattern.nrows();
        let (col_ptr, row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut y = vec![0.0f64; n];
        for (j, &xj) in x.iter().enumerate().take(n) {
            for k in col_ptr[j]..col_ptr[j + 1] {
                y[row_idx[k]] += self.values[k] * xj;
            }
        }
        y
    }
}

/// Smallest equilibrated pivot, as a fraction of the largest, that leaves
/// a converged solve's condition estimate out
/// ([`crate::tolerances::Tolerances::pivot_alarm`]).
pub const PIVOT_ALARM: f64 = crate::tolerances::TOLERANCES.pivot_alarm;

/// Largest band storage, relative to the pattern's stored entries, for which
/// the band backend is chosen: beyond it the band's zeros cost more than a
/// general sparse LU's bookkeeping.
pub const BAND_STORAGE_RATIO: usize = 8;

/// faer's general sparse LU: symbolic analysis and buffers.
struct GeneralLu {
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
}

/// The factorisation a solver uses for its pattern.
enum Backend {
    Band(Box<BandLu>),
    /// A long band in two halves ([`crate::band_split`]).
    Split(Box<SplitBandLu>),
    General(Box<GeneralLu>),
}

/// A sparse LU solver bound to one sparsity pattern.
pub struct SparseLu {
    pattern: SymbolicSparseColMat<usize>,
    backend: Backend,
    factored: bool,
    /// Whether the current factorisation passed a singularity check (see
    /// [`SparseLu::checked_regular`]).
    regular: bool,
    /// The key of the factorised matrix's form (see [`SparseLu::key`]).
    key: f64,
}

impl SparseLu {
    /// Analysis of a square pattern: the band backend when the renumbered
    /// band's storage is at most [`BAND_STORAGE_RATIO`] times the pattern's
    /// entries — in two halves from [`SPLIT_MIN_UNKNOWNS`] unknowns on —,
    /// faer's general sparse LU otherwise.
    pub fn new(pattern: SymbolicSparseColMat<usize>) -> Result<Self, String> {
        let band = BandStructure::of(&pattern);
        if band.fits() && band.storage() <= BAND_STORAGE_RATIO * pattern.row_idx().len().max(1) {
            if pattern.nrows() >= SPLIT_MIN_UNKNOWNS {
                if let Some(lu) = SplitBandLu::new(&pattern, band.clone()) {
                    return Ok(Self::with(pattern, Backend::Split(Box::new(lu))));
                }
            }
            let lu = BandLu::new(&pattern, band);
            return Ok(Self::with(pattern, Backend::Band(Box::new(lu))));
        }
        Self::general(pattern)
    }

    /// A solver with faer's general sparse LU whatever the pattern.
    pub fn general(pattern: SymbolicSparseColMat<usize>) -> Result<Self, String> {
        let symbolic = factorize_symbolic_lu(pattern.as_ref(), Default::default())
            .map_err(|e| format!("symbolic LU failed: {e:?}"))?;
        let req: StackReq =
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default());
        let sreq: StackReq = symbolic.solve_in_place_scratch::<f64>(1, Par::Seq);
        let lu = GeneralLu {
            symbolic,
            numeric: NumericLu::new(),
            factor_mem: MemBuffer::new(req),
            solve_mem: MemBuffer::new(sreq),
        };
        Ok(Self::with(pattern, Backend::General(Box::new(lu))))
    }

    fn with(pattern: SymbolicSparseColMat<usize>, backend: Backend) -> Self {
        Self {
            pattern,
            backend,
            factored: false,
            regular: false,
            key: f64::NAN,
        }
    }

    /// Whether this solver uses the band backend.
    pub fn is_band(&self) -> bool {
        matches!(self.backend, Backend::Band(_) | Backend::Split(_))
    }

    /// The pattern the solver was built for.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    /// Numeric factorisation of the matrix with this pattern and `values`.
    pub fn factor(&mut self, values: &[f64]) -> Result<(), String> {
        self.factored = false;
        self.regular = false;
        self.key = f64::NAN;
        match &mut self.backend {
            Backend::Band(lu) => lu.factor(values),
            Backend::Split(lu) => lu.factor(values),
            Backend::General(lu) => {
                let mat = SparseColMatRef::new(self.pattern.as_ref(), values);
                lu.symbolic
                    .factorize_numeric_lu(
                        &mut lu.numeric,
                        mat,
                        Par::Seq,
                        MemStack::new(&mut lu.factor_mem),
                        Default::default(),
                    )
                    .map_err(|e| format!("numeric LU failed: {e:?}"))?;
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Whether the current factorisation's pivots say nothing against its
    /// regularity: the band backends' smallest equilibrated pivot is above
    /// [`PIVOT_ALARM`] of the largest. `false` for the general backend (it
    /// does not say), where the condition estimate decides.
    pub fn pivots_healthy(&self) -> bool {
        self.factored
            && match &self.backend {
                Backend::Band(lu) => lu.pivot_ratio() > PIVOT_ALARM,
                Backend::Split(lu) => lu.pivot_ratio() > PIVOT_ALARM,
                Backend::General(_) => false,
            }
    }

    /// The key its owner attached to the current factorisation
    /// ([`SparseLu::set_key`]; none after a plain [`SparseLu::factor`]):
    /// modified Newton reuses a factorisation only for a system with the
    /// same key (`NaN` never matches).
    pub fn key(&self) -> Option<f64> {
        (self.factored && !self.key.is_nan()).then_some(self.key)
    }

    /// Whether the current factorisation was found regular by its owner
    /// ([`SparseLu::set_regular`]; no after a new [`SparseLu::factor`]).
    /// Newton uses it to skip the singularity check at the start of a solve
    /// that follows one whose solution was checked: see
    /// [`crate::newton::solve`].
    pub fn checked_regular(&self) -> bool {
        self.factored && self.regular
    }

    /// Records that the current factorisation passed a singularity check.
    pub fn set_regular(&mut self) {
        self.regular = true;
    }

    /// Attaches `key` to the current factorisation.
    pub fn set_key(&mut self, key: f64) {
        self.key = key;
    }

    /// Solves `A x = rhs` in place with the last factorisation. Returns an
    /// error when there is none or when the solution is not finite (a zero
    /// pivot: the mechanism is singular).
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        if !self.factored {
            return Err("no factorisation".into());
        }
        let n = rhs.len();
        match &mut self.backend {
            Backend::Band(lu) => lu.solve(rhs),
            Backend::Split(lu) => lu.solve(rhs),
            Backend::General(lu) => {
                faer::sparse::linalg::lu::LuRef::new_unchecked(&lu.symbolic, &lu.numeric)
                    .solve_in_place_with_conj(
                        Conj::No,
                        MatMut::from_column_major_slice_mut(rhs, n, 1),
                        Par::Seq,
                        MemStack::new(&mut lu.solve_mem),
                    );
            }
        }
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(
                "zero pivot: the tangent is singular (is every rigid-body motion supported?)"
                    .into(),
            )
        }
    }

    /// An estimate of the condition number of the matrix `values` (this
    /// solver's pattern, last factorised) and the direction of its smallest
    /// singular value: two steps of inverse iteration on the symmetrically
    /// equilibrated matrix `B = D A D`, `D = diag(|aᵢᵢ|^-½)` (so that mixed
    /// units of translations and rotations do not count as ill-conditioning),
    /// from a fixed pseudo-random start. `κ ≈ ‖B‖∞ ‖B⁻¹y‖∞` with `‖y‖∞ = 1`,
    /// a lower bound of `κ∞(B)` that reaches it when a null direction
    /// dominates — which is what a mechanism (an unsupported rigid motion, a
    /// DOF with neither stiffness nor mass) gives: `κ ≳ 1/ε`. Returns
    /// `(κ, x)` with `x` the direction in the original unknowns, scaled to
    /// `‖x‖∞ = 1`; `κ = ∞` when a solve is not finite (an exactly zero
    /// pivot), and `x` then the direction the same iteration finds on
    /// `B + σI`, `σ` = [`NULL_SHIFT`] `‖B‖∞` (`shifted_null_direction`;
    /// zero where that fails too).
    pub fn condition_estimate(&mut self, values: &[f64]) -> (f64, Vec<f64>) {
        let tangent = TangentRef {
            pattern: &self.pattern,
            values,
        };
        let d = tangent.equilibration();
        let norm = tangent.scaled_norm(&d);
        match self.inverse_iteration(&d) {
            Some((growth, x)) => (norm * growth, x),
            None => (f64::INFINITY, self.shifted_null_direction(values, &d, norm)),
        }
    }

    /// Two steps of inverse iteration with the factorisation at hand on
    /// `B = D A D` (`d` the diagonal of `D`): the growth `‖B⁻¹y‖∞` of the
    /// last step and the direction `D B⁻¹y` in the original unknowns,
    /// scaled to `‖x‖∞ = 1` (see [`Self::condition_estimate`]); `None`
    /// where a solve is not finite.
    fn inverse_iteration(&mut self, d: &[f64]) -> Option<(f64, Vec<f64>)> {
        // A fixed start with components of both signs and unequal sizes.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut y: Vec<f64> = (0..d.len())
            .map(|_| {
                seed = seed
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let mut growth = 0.0;
        for _ in 0..2 {
            let top = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // B⁻¹ y = D⁻¹ A⁻¹ D⁻¹ y (with y scaled to ‖y‖∞ = 1).
            let mut z: Vec<f64> = y.iter().zip(d).map(|(v, di)| v / top / di).collect();
            self.solve(&mut z).ok()?;
            y = z.iter().zip(d).map(|(v, di)| v / di).collect();
            growth = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        }
        // B v = D A D v ≈ 0 ⇒ A (D v) ≈ 0: the direction in the unknowns.
        let mut x: Vec<f64> = y.iter().zip(d).map(|(v, di)| v * di).collect();
        let top = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if top > 0.0 && top.is_finite() {
            x.iter_mut().for_each(|v| *v /= top);
        }
        Some((growth, x))
    }

    /// The null direction of an exactly singular `values` (equilibrating
    /// scale `d`, `‖B‖∞ = norm`): the inverse iteration on `B + σI`,
    /// `σ = NULL_SHIFT · norm`, which a zero pivot does not stop and which
    /// still draws the start towards the null space by `1/σ` against at
    /// most `1/(λ + σ)` for any other direction. The shifted factors are
    /// dropped: the solver holds no factorisation afterwards. Zeros where
    /// the shifted matrix cannot be factorised either.
    fn shifted_null_direction(&mut self, values: &[f64], d: &[f64], norm: f64) -> Vec<f64> {
        let n = d.len();
        let mut shifted = values.to_vec();
        let (col_ptr, row_idx) = (self.pattern.col_ptr(), self.pattern.row_idx());
        for (j, dj) in d.iter().enumerate() {
            let range = col_ptr[j]..col_ptr[j + 1];
            if let Some(k) = row_idx[range.clone()].iter().position(|&r| r == j) {
                shifted[range.start + k] += NULL_SHIFT * norm / (dj * dj);
            }
        }
        let found = match self.factor(&shifted) {
            Ok(()) => self.inverse_iteration(d).map(|(_, x)| x),
            Err(_) => None,
        };
        self.factored = false;
        found
            .filter(|x| x.iter().all(|v| v.is_finite()))
            .unwrap_or_else(|| vec![0.0; n])
    }
}
