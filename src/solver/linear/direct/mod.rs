//! Sparse direct solver for the implicit MPM tangent system `K x = b`, backed by faer 0.24.
//!
//! `K` arrives in compressed columns (or as triplets, duplicates summed). The symbolic
//! factorization (fill-reducing ordering + elimination structure) is cached and reused while
//! the sparsity pattern is unchanged. Symmetric matrices go LLᵀ → intranodal LBLᵀ → LU;
//! general ones go to LU.
//! Every numeric factorization is checked with one probe solve (see [`CHECK_BACKWARD_TOL`]
//! and [`CHECK_FORWARD_TOL`]) so that singular or unstably factored matrices give an error
//! instead of a garbage solution; [`DirectSolver::factorize_and_solve`] solves a right-hand
//! side together with the probe (one pass over the factor for both).
//!
//! The files, by concept: `symbolic` (the analysis and its cache, the
//! matrix [`Structure`]), `ordering` (the fill-reducing ordering given to
//! it), `numeric` (the factorizations and solves, their parallelism),
//! `check` (the probe check), `csc` (the compressed-column input:
//! products, triplets, the mirrored triangle) and `error`. Nothing here
//! knows of nodes: a node ordering comes in as a permutation.

mod check;
mod csc;
mod error;
mod numeric;
mod ordering;
mod symbolic;

pub use check::{CHECK_BACKWARD_TOL, CHECK_FORWARD_TOL};
pub use csc::spmv;
pub use error::SolveError;
pub use numeric::{cholesky_parallelism, parallelism, Method, PARALLEL_MEAN_COLUMN};
pub use ordering::Ordering;
pub use symbolic::Structure;

use super::Index;
use csc::{check_entries, csc_from_triplets, mirror_lower};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use numeric::Numeric;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use symbolic::Symbolic;

/// Sparse direct solver holding the symbolic factorizations and the pattern they belong to.
pub struct DirectSolver {
    /// The factors of the previous factorization: their buffers are refilled
    /// instead of allocated again.
    kept: Numeric,
    symbolic: Symbolic,
    numeric: Numeric,
    statistics: Statistics,
}

/// What a direct solver did so far (summary.json's `direct`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Statistics {
    /// Numeric factorizations (each LLᵀ, LBLᵀ or LU attempt that succeeded).
    pub factorizations: usize,
    /// Symbolic analyses (a new pattern or ordering).
    pub symbolic_analyses: usize,
    /// Stored entries of the largest Cholesky-family factor (LLᵀ or LBLᵀ,
    /// supernodal: dense blocks counted whole); 0 if only LU was used.
    pub largest_factor_entries: usize,
}

impl Default for DirectSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl DirectSolver {
    /// Empty solver: no pattern, no factorization.
    pub fn new() -> Self {
        Self {
            kept: Numeric::None,
            symbolic: Symbolic::default(),
            numeric: Numeric::None,
            statistics: Statistics::default(),
        }
    }

    /// Factorize K given in compressed columns (its lower triangle for
    /// `Symmetric`, rows sorted within each column); reuses the symbolic
    /// factorization when the pattern equals the previous one. Symmetric: LLᵀ,
    /// else LBLᵀ, else LU; General: LU. On error no factorization is kept.
    pub fn factorize(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        structure: Structure,
        ordering: Ordering,
    ) -> Result<Method, SolveError> {
        self.factorize_with(a, structure, ordering, None)
            .map(|(method, _)| method)
    }

    /// [`Self::factorize`], then the solution of `K x = b`: the right-hand
    /// side rides along with the probe check's solve (two columns in one pass
    /// over the factor instead of two passes), so a Newton correction pays for
    /// the check with a second column only.
    pub fn factorize_and_solve(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        structure: Structure,
        ordering: Ordering,
        b: &[f64],
    ) -> Result<(Method, Vec<f64>), SolveError> {
        if b.len() != a.nrows() {
            self.retire_numeric();
            let msg = format!(
                "right-hand side has length {}, expected {}",
                b.len(),
                a.nrows()
            );
            return Err(SolveError::InvalidInput(msg));
        }
        let (method, x) = self.factorize_with(a, structure, ordering, Some(b))?;
        Ok((method, x.ok_or(SolveError::NotFactorized)?))
    }

    /// The factorization with its check; with `b`, also the solution of K x = b.
    fn factorize_with(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        structure: Structure,
        ordering: Ordering,
        b: Option<&[f64]>,
    ) -> Result<(Method, Option<Vec<f64>>), SolveError> {
        self.retire_numeric();
        check_entries(a, structure)?;
        if let Ordering::Given(perm) = ordering {
            if perm.len() != a.nrows() {
                let msg = format!("ordering of length {}, expected {}", perm.len(), a.nrows());
                return Err(SolveError::InvalidInput(msg));
            }
        }
        (self.symbolic).update(a.nrows(), structure, a.symbolic(), ordering, None)?;
        let (method, x) = match structure {
            Structure::General => self.factor_lu(a, b),
            Structure::Symmetric => self.factor_symmetric(a, b),
        }?;
        self.statistics.factorizations += 1;
        let entries = match &self.numeric {
            Numeric::Llt(values) | Numeric::Lblt { values, .. } => values.len(),
            _ => 0,
        };
        let largest = &mut self.statistics.largest_factor_entries;
        *largest = (*largest).max(entries);
        Ok((method, x))
    }

    /// The structure of the last pattern factorized or analysed.
    pub fn structure(&self) -> Option<Structure> {
        self.symbolic.structure()
    }

    /// The symbolic Cholesky factorization of the lower-triangle pattern
    /// `lower` with `ordering`, unless the solver already holds it: what the
    /// next [`Self::factorize`] of a symmetric K with this pattern and ordering
    /// would compute first, done ahead (e.g. while K's values are assembled).
    /// The solver keeps the handle `lower` (not a copy) as its pattern.
    pub fn analyse(
        &mut self,
        lower: &Arc<SymbolicSparseColMat<Index>>,
        ordering: Ordering,
    ) -> Result<(), SolveError> {
        let n = lower.nrows();
        if let Ordering::Given(perm) = ordering {
            if perm.len() != n {
                let msg = format!("ordering of length {}, expected {n}", perm.len());
                return Err(SolveError::InvalidInput(msg));
            }
        }
        let view = (**lower).as_ref();
        let shared = Arc::clone(lower);
        if !(self.symbolic).update(n, Structure::Symmetric, view, ordering, Some(shared))? {
            self.retire_numeric();
        }
        self.ensure_chol(view)
    }

    /// The current factors become the kept buffers of the next factorization
    /// (nothing to solve with until then).
    fn retire_numeric(&mut self) {
        let factors = std::mem::replace(&mut self.numeric, Numeric::None);
        if factors.is_some() {
            self.kept = factors;
        }
    }

    /// [`Self::factorize`] of K given as triplets (duplicates summed; with
    /// `Symmetric` only those with row ≥ column are read).
    pub fn factorize_triplets(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        structure: Structure,
    ) -> Result<Method, SolveError> {
        self.numeric = Numeric::None;
        let a = csc_from_triplets(n, triplets, structure)?;
        self.factorize(a.as_ref(), structure, Ordering::Amd)
    }

    /// Solve `K x = b` with the last factorization; `b` is left untouched and `x` returned.
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>, SolveError> {
        let n = match (self.symbolic.order(), self.numeric.is_some()) {
            (Some(n), true) => n,
            _ => return Err(SolveError::NotFactorized),
        };
        if b.len() != n {
            let msg = format!("right-hand side has length {}, expected {n}", b.len());
            return Err(SolveError::InvalidInput(msg));
        }
        let mut x = b.to_vec();
        (self.numeric).solve_columns(&self.symbolic, &mut x, n, 1)?;
        Ok(x)
    }

    /// Drop the symbolic factorizations but keep the buffers: the next
    /// factorization analyses its pattern anew, as after a pattern change
    /// (the first Newton iteration of a step whose stencils changed).
    pub fn forget_pattern(&mut self) {
        self.symbolic.forget();
    }

    /// How many symbolic factorizations (Cholesky or LU analyses) were computed so far.
    pub fn symbolic_count(&self) -> usize {
        self.statistics.symbolic_analyses
    }

    /// The counts and the largest factor so far.
    pub fn statistics(&self) -> Statistics {
        self.statistics
    }

    /// Continue the counts of an earlier solver (a restart).
    pub fn restore_statistics(&mut self, s: Statistics) {
        self.statistics = s;
    }

    /// LLᵀ, then LBLᵀ, then LU on the mirrored full matrix; `lower` holds the lower triangle.
    fn factor_symmetric(
        &mut self,
        lower: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<(Method, Option<Vec<f64>>), SolveError> {
        self.ensure_chol(lower.symbolic())?;
        if let Ok(x) = self.try_llt(lower, b) {
            return Ok((Method::Llt, x));
        }
        if let Ok(x) = self.try_lblt(lower, b) {
            return Ok((Method::Ldlt, x));
        }
        let full = mirror_lower(lower)?;
        self.factor_lu(full.as_ref(), b)
    }

    /// The symbolic Cholesky of the lower triangle unless cached, counted.
    fn ensure_chol(
        &mut self,
        lower: faer::sparse::SymbolicSparseColMatRef<Index>,
    ) -> Result<(), SolveError> {
        if self.symbolic.ensure_chol(lower)? {
            self.statistics.symbolic_analyses += 1;
        }
        Ok(())
    }

    /// Numeric LLᵀ with the cached symbolic factorization (into the kept
    /// factor's buffer when there is one), then the probe check.
    fn try_llt(
        &mut self,
        lower: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let sym = self
            .symbolic
            .chol
            .as_ref()
            .ok_or(SolveError::NotFactorized)?;
        let kept = std::mem::replace(&mut self.kept, Numeric::None);
        self.numeric = numeric::llt(sym, lower, kept)?;
        self.check(lower, true, b)
    }

    /// Numeric intranodal LBLᵀ with the cached symbolic factorization, then the probe check.
    fn try_lblt(
        &mut self,
        lower: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let sym = self
            .symbolic
            .chol
            .as_ref()
            .ok_or(SolveError::NotFactorized)?;
        self.numeric = numeric::lblt(sym, lower)?;
        self.check(lower, true, b)
    }

    /// Symbolic (cached) + numeric LU of the full matrix `a`, then the probe check.
    fn factor_lu(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<(Method, Option<Vec<f64>>), SolveError> {
        if self.symbolic.ensure_lu(a)? {
            self.statistics.symbolic_analyses += 1;
        }
        let sym = self.symbolic.lu.as_ref().ok_or(SolveError::NotFactorized)?;
        self.numeric = numeric::lu(sym, a)?;
        let x = self.check(a, false, b)?;
        Ok((Method::Lu, x))
    }

    /// Probe check of the current factors (`check::probe`); on an error no
    /// factorization is kept. With `b`, `K x = b` is solved in the same pass
    /// and x returned.
    fn check(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        sym: bool,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let result = check::probe(&self.numeric, &self.symbolic, a, sym, b);
        if result.is_err() {
            self.numeric = Numeric::None;
        }
        result
    }
}

#[cfg(test)]
mod tests;
