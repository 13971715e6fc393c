//! The symbolic analysis: the elimination structure of the pattern with its
//! fill-reducing ordering (Cholesky) or column ordering (LU), cached with the
//! pattern it belongs to and reused while the pattern and ordering are
//! unchanged.

use super::error::{backend, SolveError};
use super::ordering::{inverse, Ordering};
use crate::solver::linear::Index;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use std::sync::Arc;

/// Structure the caller promises for `K`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Structure {
    /// `K = Kᵀ`: only triplets with `row >= col` (lower triangle) are read, so the caller
    /// may pass the full matrix or its lower triangle (never the upper one alone).
    Symmetric,
    /// No structure assumed: all triplets are read and sparse LU is used.
    General,
}

impl Structure {
    /// Symmetric when the assembly says the matrix is, else general.
    pub fn of(symmetric: bool) -> Structure {
        if symmetric {
            Structure::Symmetric
        } else {
            Structure::General
        }
    }
}

/// Sorted, deduplicated pattern of the last factorized or analysed matrix and
/// the ordering given with it (key of the symbolic cache).
struct Pattern {
    n: usize,
    structure: Structure,
    /// The caller's own pattern when it came through `DirectSolver::analyse`
    /// (no copy), else a copy.
    columns: Arc<SymbolicSparseColMat<Index>>,
    perm: Option<Vec<usize>>,
}

/// Whether `a` has the columns `stored`: the same arrays (a matrix on the
/// shared pattern: they are immutable and kept alive by the handle), or equal
/// ones.
fn same_columns(stored: &SymbolicSparseColMat<Index>, a: SymbolicSparseColMatRef<Index>) -> bool {
    let same =
        |x: &[Index], y: &[Index]| (x.as_ptr() == y.as_ptr() && x.len() == y.len()) || x == y;
    same(stored.col_ptr(), a.col_ptr()) && same(stored.row_idx(), a.row_idx())
}

/// The symbolic factorizations and the pattern they belong to.
#[derive(Default)]
pub(super) struct Symbolic {
    pattern: Option<Pattern>,
    pub(super) chol: Option<SymbolicCholesky<Index>>,
    pub(super) lu: Option<SymbolicLu<Index>>,
}

impl Symbolic {
    /// The order of the last pattern factorized or analysed.
    pub(super) fn order(&self) -> Option<usize> {
        self.pattern.as_ref().map(|p| p.n)
    }

    /// The structure of the last pattern factorized or analysed.
    pub(super) fn structure(&self) -> Option<Structure> {
        self.pattern.as_ref().map(|p| p.structure)
    }

    /// Drop the symbolic factorizations and their pattern.
    pub(super) fn forget(&mut self) {
        self.pattern = None;
        self.chol = None;
        self.lu = None;
    }

    /// Keep the cached symbolic factorizations iff the new pattern and ordering
    /// equal the stored ones; returns whether they do. A new pattern is kept
    /// as `shared` when given, else copied (an error only if that allocation fails).
    pub(super) fn update(
        &mut self,
        n: usize,
        structure: Structure,
        a: SymbolicSparseColMatRef<Index>,
        ordering: Ordering,
        shared: Option<Arc<SymbolicSparseColMat<Index>>>,
    ) -> Result<bool, SolveError> {
        let perm = match ordering {
            Ordering::Amd => None,
            Ordering::Given(p) => Some(p),
        };
        let same = self.pattern.as_ref().is_some_and(|p| {
            p.n == n
                && p.structure == structure
                && p.perm.as_deref() == perm
                && same_columns(&p.columns, a)
        });
        if !same {
            self.chol = None;
            self.lu = None;
            // The old pattern goes first (it may be as large as the new one).
            self.pattern = None;
            let columns = match shared {
                Some(shared) => shared,
                None => Arc::new(a.to_owned().map_err(backend)?),
            };
            self.pattern = Some(Pattern {
                n,
                structure,
                columns,
                perm: perm.map(|p| p.to_vec()),
            });
        }
        Ok(same)
    }

    /// Compute the symbolic Cholesky of the lower triangle unless cached (with
    /// the given ordering, else AMD); returns whether it was computed.
    pub(super) fn ensure_chol(
        &mut self,
        lower: SymbolicSparseColMatRef<Index>,
    ) -> Result<bool, SolveError> {
        if self.chol.is_some() {
            return Ok(false);
        }
        let params = CholeskySymbolicParams::default();
        let perm = self.pattern.as_ref().and_then(|p| p.perm.as_ref());
        let fwd: Option<Vec<Index>> = perm.map(|p| p.iter().map(|&i| i as Index).collect());
        let inv = perm.map(|p| inverse(p));
        let ordering = match (&fwd, &inv) {
            (Some(fwd), Some(inv)) => {
                SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, fwd.len()))
            }
            _ => SymmetricOrdering::Amd,
        };
        let sym = factorize_symbolic_cholesky(lower, faer::Side::Lower, ordering, params)
            .map_err(backend)?;
        self.chol = Some(sym);
        Ok(true)
    }

    /// Compute the symbolic LU (COLAMD ordering) of the full matrix unless
    /// cached; returns whether it was computed.
    pub(super) fn ensure_lu(&mut self, a: SparseColMatRef<Index, f64>) -> Result<bool, SolveError> {
        if self.lu.is_some() {
            return Ok(false);
        }
        let sym =
            factorize_symbolic_lu(a.symbolic(), LuSymbolicParams::default()).map_err(backend)?;
        self.lu = Some(sym);
        Ok(true)
    }
}
