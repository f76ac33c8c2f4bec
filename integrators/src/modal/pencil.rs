//! Sparse symmetric matrices over the assembled tangent's pattern: the
//! tangent and the mass of a linearisation, their symmetric parts, products
//! and dense copies.

use faer::sparse::SymbolicSparseColMat;
use faer::Mat;

/// Relative asymmetry `max|Kᵢⱼ − Kⱼᵢ| / max|Kᵢⱼ|` below which a tangent is
/// symmetric: the exact tangent of a conservative system at an equilibrium
/// is symmetric, up to its residual (the Newton tolerance) and round-off.
pub(crate) const SYMMETRIC: f64 = 1e-7;

/// A matrix of the tangent's pattern (compressed columns) with the
/// index of every stored entry's transpose.
pub(crate) struct Pattern {
    /// The compressed-column structure.
    pub symbolic: SymbolicSparseColMat<usize>,
    /// For each stored entry `(i, j)`, the index of `(j, i)`.
    transpose: Vec<usize>,
}

impl Pattern {
    /// The pattern `symbolic` (structurally symmetric: every block of the
    /// assembly couples a set of equations both ways).
    pub fn new(symbolic: SymbolicSparseColMat<usize>) -> Result<Self, String> {
        let transpose = crate::stability::transpose_positions(&symbolic)?;
        Ok(Self {
            symbolic,
            transpose,
        })
    }

    /// The order of the matrices.
    pub fn n(&self) -> usize {
        self.symbolic.ncols()
    }

    /// Replaces `values` by their symmetric part `½(K + Kᵀ)` and returns the
    /// relative asymmetry `max|Kᵢⱼ − Kⱼᵢ| / max|Kᵢⱼ|` they had.
    pub fn symmetrize(&self, values: &mut [f64]) -> f64 {
        let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut worst = 0.0f64;
        let original = values.to_vec();
        for (k, v) in values.iter_mut().enumerate() {
            let t = original[self.transpose[k]];
            worst = worst.max((original[k] - t).abs());
            *v = 0.5 * (original[k] + t);
        }
        if scale > 0.0 {
            worst / scale
        } else {
            0.0
        }
    }

    /// `out = K x` for the values `k`.
    pub fn product(&self, k: &[f64], x: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        for (j, xj) in x.iter().enumerate() {
            for p in col_ptr[j]..col_ptr[j + 1] {
                out[row_idx[p]] += k[p] * xj;
            }
        }
    }

    /// `xᵀ K y` for the values `k`.
    pub fn form(&self, k: &[f64], x: &[f64], y: &[f64]) -> f64 {
        let mut ky = vec![0.0; y.len()];
        self.product(k, y, &mut ky);
        x.iter().zip(&ky).map(|(a, b)| a * b).sum()
    }

    /// The dense matrix of the values `k`.
    pub fn dense(&self, k: &[f64]) -> Mat<f64> {
        let n = self.n();
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        let mut m = Mat::zeros(n, n);
        for j in 0..n {
            for p in col_ptr[j]..col_ptr[j + 1] {
                m[(row_idx[p], j)] += k[p];
            }
        }
        m
    }

    /// The diagonal of the values `k`.
    pub fn diagonal(&self, k: &[f64]) -> Vec<f64> {
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        (0..self.n())
            .map(|j| {
                (col_ptr[j]..col_ptr[j + 1])
                    .filter(|&p| row_idx[p] == j)
                    .map(|p| k[p])
                    .sum()
            })
            .collect()
    }

    /// The values of `D K D` for the diagonal `d`.
    pub fn scaled(&self, k: &[f64], d: &[f64]) -> Vec<f64> {
        let (col_ptr, row_idx) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        let mut out = k.to_vec();
        for j in 0..self.n() {
            for p in col_ptr[j]..col_ptr[j + 1] {
                out[p] *= d[row_idx[p]] * d[j];
            }
        }
        out
    }

    /// `a + s b` entry by entry.
    pub fn combine(a: &[f64], s: f64, b: &[f64]) -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + s * y).collect()
    }
}
