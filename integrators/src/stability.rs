//! Stability of a static equilibrium: the number of negative eigenvalues of
//! the converged reduced tangent.
//!
//! An equilibrium is stable when the tangent (the second variation of the
//! potential) is positive definite. Load control follows whatever branch
//! Newton lands on: past a bifurcation (the lateral buckling of a frame, the
//! Euler load of a column) a symmetric model stays on the fundamental,
//! unstable branch with no sign in the residual. The count of negative
//! eigenvalues says so. By Sylvester's law of inertia it equals the number of
//! negative pivots `dᵢ` of any factorisation `P K Pᵀ = L D Lᵀ`: here faer's
//! simplicial `LDLᵀ` with a fill-reducing (AMD) ordering, of the symmetric
//! part `½(K + Kᵀ)` — at an equilibrium under conservative loads the tangent
//! is symmetric up to the residual, and its symmetric part is the second
//! variation.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Par, Side};

/// For each stored entry `(i, j)` of a structurally symmetric pattern, the
/// index of `(j, i)`; an error when the pattern is not symmetric.
pub(crate) fn transpose_positions(
    pattern: &SymbolicSparseColMat<usize>,
) -> Result<Vec<usize>, String> {
    let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
    let mut transpose = vec![usize::MAX; row_idx.len()];
    for j in 0..pattern.ncols() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let i = row_idx[k];
            let range = col_ptr[i]..col_ptr[i + 1];
            let p = row_idx[range.clone()]
                .iter()
                .position(|&r| r == j)
                .ok_or("the tangent's pattern is not symmetric")?;
            transpose[k] = range.start + p;
        }
    }
    Ok(transpose)
}

/// Counts negative pivots of the symmetric part of matrices of one pattern.
pub struct InertiaCount {
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// For each stored entry `(i, j)`, the index of `(j, i)`.
    transpose: Vec<usize>,
    symmetric: Vec<f64>,
    factor: Vec<f64>,
    mem: MemBuffer,
}

impl InertiaCount {
    /// Symbolic analysis of a structurally symmetric pattern (the assembled
    /// tangent's: every block couples a set of equations both ways).
    pub fn new(pattern: SymbolicSparseColMat<usize>) -> Result<Self, String> {
        let transpose = transpose_positions(&pattern)?;
        let row_idx = pattern.row_idx();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            params,
        )
        .map_err(|e| format!("symbolic LDLT failed: {e:?}"))?;
        let req = symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
        Ok(Self {
            factor: vec![0.0; symbolic.len_val()],
            symmetric: vec![0.0; row_idx.len()],
            transpose,
            symbolic,
            pattern,
            mem: MemBuffer::new(req),
        })
    }

    /// Number of negative eigenvalues of `½(K + Kᵀ)` for the CSC values
    /// `values` of this pattern; `None` when a pivot is exactly zero (a
    /// singular matrix: the count is not defined).
    pub fn negative_eigenvalues(&mut self, values: &[f64]) -> Option<usize> {
        for (k, s) in self.symmetric.iter_mut().enumerate() {
            *s = 0.5 * (values[k] + values[self.transpose[k]]);
        }
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &self.symmetric);
        self.symbolic
            .factorize_numeric_ldlt(
                &mut self.factor,
                mat,
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .ok()?;
        let SymbolicCholeskyRaw::Simplicial(simplicial) = self.symbolic.raw() else {
            return None;
        };
        let (col_ptr, row_idx) = (simplicial.col_ptr(), simplicial.row_idx());
        let mut negative = 0;
        for j in 0..simplicial.nrows() {
            let d = (col_ptr[j]..col_ptr[j + 1])
                .find(|&k| row_idx[k] == j)
                .map(|k| self.factor[k])?;
            if !d.is_finite() || d == 0.0 {
                return None;
            }
            if d < 0.0 {
                negative += 1;
            }
        }
        Some(negative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// A symmetric tridiagonal matrix `tridiag(1, a, 1)` of size `n` has
    /// eigenvalues `a + 2 cos(kπ/(n+1))`, k = 1..n: the count is known.
    fn count(a: f64, n: usize) -> Option<usize> {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, a));
            if i + 1 < n {
                t.push(Triplet::new(i, i + 1, 1.0));
                t.push(Triplet::new(i + 1, i, 1.0));
            }
        }
        let m = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
        let mut c = InertiaCount::new(m.symbolic().to_owned().unwrap()).unwrap();
        c.negative_eigenvalues(m.val())
    }

    #[test]
    fn counts_negative_eigenvalues_of_a_known_spectrum() {
        let n = 12;
        for a in [3.0, 1.5, 0.3, -0.7, -1.9, -3.0] {
            let exact = (1..=n)
                .filter(|&k| {
                    a + 2.0 * (k as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos() < 0.0
                })
                .count();
            assert_eq!(count(a, n), Some(exact), "a = {a}");
        }
    }

    #[test]
    fn the_symmetric_part_is_what_counts() {
        // [[1, 4], [0, 1]]: symmetric part [[1, 2], [2, 1]] has eigenvalues 3, −1.
        let t = [
            Triplet::new(0, 0, 1.0),
            Triplet::new(0, 1, 4.0),
            Triplet::new(1, 0, 0.0),
            Triplet::new(1, 1, 1.0),
        ];
        let m = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(2, 2, &t).unwrap();
        let mut c = InertiaCount::new(m.symbolic().to_owned().unwrap()).unwrap();
        assert_eq!(c.negative_eigenvalues(m.val()), Some(1));
    }
}
