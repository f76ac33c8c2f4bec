//! Sparse LU solves with faer: the symbolic factorisation (fill-reducing
//! ordering, elimination structure) is computed once per sparsity pattern;
//! every Newton iteration only refactors numerically, into buffers allocated
//! once. Sequential inside (`Par::Seq`), so results do not depend on the
//! thread count; the parallelism lives in assembly.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};

/// A sparse LU solver bound to one sparsity pattern.
pub struct SparseLu {
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    factored: bool,
}

impl SparseLu {
    /// Symbolic analysis of a square pattern.
    pub fn new(pattern: SymbolicSparseColMat<usize>) -> Result<Self, String> {
        let symbolic = factorize_symbolic_lu(pattern.as_ref(), Default::default())
            .map_err(|e| format!("symbolic LU failed: {e:?}"))?;
        let req: StackReq =
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default());
        let sreq: StackReq = symbolic.solve_in_place_scratch::<f64>(1, Par::Seq);
        Ok(Self {
            pattern,
            symbolic,
            numeric: NumericLu::new(),
            factor_mem: MemBuffer::new(req),
            solve_mem: MemBuffer::new(sreq),
            factored: false,
        })
    }

    /// The pattern the solver was built for.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }

    /// Numeric factorisation of the matrix with this pattern and `values`.
    pub fn factor(&mut self, values: &[f64]) -> Result<(), String> {
        let mat = SparseColMatRef::new(self.pattern.as_ref(), values);
        self.factored = false;
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.factor_mem),
                Default::default(),
            )
            .map_err(|e| format!("numeric LU failed: {e:?}"))?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = rhs` in place with the last factorisation. Returns an
    /// error when there is none or when the solution is not finite (a zero
    /// pivot: the mechanism is singular).
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), String> {
        if !self.factored {
            return Err("no factorisation".into());
        }
        let n = rhs.len();
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.solve_mem),
        );
        if rhs.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(
                "zero pivot: the tangent is singular (is every rigid-body motion supported?)"
                    .into(),
            )
        }
    }
}
