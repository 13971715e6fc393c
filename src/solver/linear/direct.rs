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

use super::Index;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, IntranodeLbltRef, LltRef,
    SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::LuError;
use faer::sparse::{
    CreationError, SparseColMat, SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef,
    Triplet,
};
use faer::{Conj, MatMut, Par, Side};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The number of tasks faer splits a factorization or solve into. faer divides
/// the supernodal elimination tree and its dense kernels by this count, not by
/// the threads there are, so a fixed count rounds the same on any number of
/// threads (`factors_do_not_depend_on_the_number_of_threads`; with the pool's
/// thread count instead, 1 and 2 threads give different last bits) and still
/// lets two cores share the work.
const FACTOR_TASKS: usize = 2;

/// faer's parallelism for [`FACTOR_TASKS`] tasks on the current rayon pool
/// (LU; Cholesky-family factors choose by size, [`cholesky_parallelism`]).
pub fn parallelism() -> Par {
    Par::rayon(FACTOR_TASKS)
}

/// The mean number of entries per column of L from which a Cholesky-family
/// factorization runs with [`FACTOR_TASKS`] tasks instead of sequentially.
/// Measured on 2 cores (docs/performance.md, quiet machine): at 163, 242 and
/// 580 entries per column (2D blocks 64² and 160², 3D 12³) the second task
/// made faer's numeric Cholesky 2.5×, 1.35× and 1.15× slower; at 1,199 (3D
/// 20³) it made it 1.35× faster. Large dense supernodes are what it splits.
pub const PARALLEL_MEAN_COLUMN: usize = 800;

/// faer's parallelism for the numeric factorization and solves with `sym`:
/// sequential for sparse factors, [`FACTOR_TASKS`] tasks for dense ones. It
/// depends on the pattern only, so the results do not depend on the threads.
pub fn cholesky_parallelism(sym: &SymbolicCholesky<Index>) -> Par {
    if sym.len_val() >= PARALLEL_MEAN_COLUMN * sym.nrows() {
        Par::rayon(FACTOR_TASKS)
    } else {
        Par::Seq
    }
}

/// Largest accepted normwise backward error `‖K y − b‖ / (‖|K||y|‖ + ‖b‖)` of the probe solve.
pub const CHECK_BACKWARD_TOL: f64 = 1e-10;
/// Largest accepted relative forward error `‖y − v‖∞ / ‖v‖∞` of the probe solve `K y = K v`;
/// beyond it the matrix is treated as numerically singular (condition number ≳ 1e13).
pub const CHECK_FORWARD_TOL: f64 = 1e-3;

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

/// Factorization that was used by the last successful [`DirectSolver::factorize`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum Method {
    /// Sparse Cholesky `LLᵀ` (symmetric positive definite).
    Llt,
    /// Sparse `LBLᵀ` (faer's intranodal Bunch–Kaufman; plain `LDLᵀ` in simplicial mode).
    Ldlt,
    /// Sparse LU with partial (row) pivoting and COLAMD column ordering.
    Lu,
}

impl Method {
    /// Short name for logs (newton.csv).
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

/// Errors of the direct solver.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// [`DirectSolver::solve`] was called before a successful factorization.
    #[error("no successful factorization to solve with")]
    NotFactorized,
    /// The matrix is (numerically) singular or every factorization failed its check.
    #[error("singular matrix: {0}")]
    Singular(String),
    /// Bad input: index out of range, non-finite value, wrong right-hand-side length.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// Failure inside faer that is not about the matrix values (allocation, overflow).
    #[error("sparse backend failure: {0}")]
    Backend(String),
}

/// The fill-reducing ordering of the symbolic Cholesky factorization.
#[derive(Clone, Copy, Debug)]
pub enum Ordering<'a> {
    /// faer's approximate minimum degree on the scalar matrix.
    Amd,
    /// A permutation of the unknowns (`perm[new] = old`), e.g. from
    /// `super::ordering`.
    Given(&'a [usize]),
}

/// Sorted, deduplicated pattern of the last factorized or analysed matrix and
/// the ordering given with it (key of the symbolic cache).
struct Pattern {
    n: usize,
    structure: Structure,
    /// The caller's own pattern when it came through [`DirectSolver::analyse`]
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

/// Numeric factors of the last successful factorization.
#[allow(clippy::large_enum_variant)] // one instance per solver: size is irrelevant
enum Numeric {
    None,
    Llt(Vec<f64>),
    Lblt {
        values: Vec<f64>,
        subdiag: Vec<f64>,
        fwd: Vec<Index>,
        inv: Vec<Index>,
    },
    Lu(Box<NumericLu<Index, f64>>),
}

/// Sparse direct solver holding the symbolic factorizations and the pattern they belong to.
pub struct DirectSolver {
    /// The factors of the previous factorization: their buffers are refilled
    /// instead of allocated again.
    kept: Numeric,
    pattern: Option<Pattern>,
    chol: Option<SymbolicCholesky<Index>>,
    lu: Option<SymbolicLu<Index>>,
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
            pattern: None,
            chol: None,
            lu: None,
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
        self.update_pattern(a.nrows(), structure, a.symbolic(), ordering, None)?;
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
        self.pattern.as_ref().map(|p| p.structure)
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
        if !self.update_pattern(n, Structure::Symmetric, view, ordering, Some(shared))? {
            self.retire_numeric();
        }
        self.ensure_chol(view)
    }

    /// The current factors become the kept buffers of the next factorization
    /// (nothing to solve with until then).
    fn retire_numeric(&mut self) {
        let factors = std::mem::replace(&mut self.numeric, Numeric::None);
        if !matches!(factors, Numeric::None) {
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
        let n = match (&self.pattern, &self.numeric) {
            (Some(p), Numeric::Llt(_) | Numeric::Lblt { .. } | Numeric::Lu(_)) => p.n,
            _ => return Err(SolveError::NotFactorized),
        };
        if b.len() != n {
            let msg = format!("right-hand side has length {}, expected {n}", b.len());
            return Err(SolveError::InvalidInput(msg));
        }
        let mut x = b.to_vec();
        self.solve_columns(&mut x, n, 1)?;
        Ok(x)
    }

    /// Solve in place for `ncols` right-hand sides stored column after column in `x`.
    fn solve_columns(&self, x: &mut [f64], n: usize, ncols: usize) -> Result<(), SolveError> {
        let rhs = MatMut::from_column_major_slice_mut(x, n, ncols);
        match (&self.numeric, &self.chol) {
            (Numeric::Lu(num), _) => self.solve_lu(num, rhs, parallelism()),
            (chol, Some(sym)) => self.solve_chol(chol, rhs, cholesky_parallelism(sym)),
            (_, None) => Err(SolveError::NotFactorized),
        }
    }

    /// Drop the symbolic factorizations but keep the buffers: the next
    /// factorization analyses its pattern anew, as after a pattern change
    /// (the first Newton iteration of a step whose stencils changed).
    pub fn forget_pattern(&mut self) {
        self.pattern = None;
        self.chol = None;
        self.lu = None;
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

    /// Keep the cached symbolic factorizations iff the new pattern and ordering
    /// equal the stored ones; returns whether they do. A new pattern is kept
    /// as `shared` when given, else copied (an error only if that allocation fails).
    fn update_pattern(
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

    /// Compute the symbolic Cholesky of the lower triangle unless cached (with
    /// the given ordering, else AMD).
    fn ensure_chol(&mut self, lower: SymbolicSparseColMatRef<Index>) -> Result<(), SolveError> {
        if self.chol.is_none() {
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
            let sym = factorize_symbolic_cholesky(lower, Side::Lower, ordering, params)
                .map_err(backend)?;
            self.chol = Some(sym);
            self.statistics.symbolic_analyses += 1;
        }
        Ok(())
    }

    /// Compute the symbolic LU (COLAMD ordering) of the full matrix unless cached.
    fn ensure_lu(&mut self, a: SparseColMatRef<Index, f64>) -> Result<(), SolveError> {
        if self.lu.is_none() {
            let sym = factorize_symbolic_lu(a.symbolic(), LuSymbolicParams::default())
                .map_err(backend)?;
            self.lu = Some(sym);
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
        let sym = self.chol.take().ok_or(SolveError::NotFactorized)?;
        let par = cholesky_parallelism(&sym);
        // faer overwrites every value of the factor, so the old buffer serves
        // (grown if the new pattern needs more).
        // A larger factor gets a buffer of its exact size, the old one freed first.
        let len = sym.len_val();
        let mut values = match std::mem::replace(&mut self.kept, Numeric::None) {
            Numeric::Llt(mut v) if v.capacity() >= len => {
                v.resize(len, 0.0);
                v
            }
            _ => vec![0.0; len],
        };
        // The workspace is allocated per factorization, not kept: kept, it sat
        // beside the next assembly, the step's peak (61 MiB at 2×10⁵ unknowns
        // in 2D: 1.58 → 1.49× the factor). Its page faults cost 6–8 % of a
        // later Newton iteration at 5×10⁴ unknowns (docs/performance.md).
        let req = sym.factorize_numeric_llt_scratch::<f64>(par, Default::default());
        let mut work = match buffer(req) {
            Ok(work) => work,
            Err(e) => {
                self.chol = Some(sym);
                return Err(e);
            }
        };
        let result = sym
            .factorize_numeric_llt(
                &mut values,
                lower,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut work),
                Default::default(),
            )
            .map(|_| ());
        drop(work); // before the check's solves
        self.chol = Some(sym);
        result.map_err(|e| SolveError::Singular(format!("LLT: {e:?}")))?;
        self.numeric = Numeric::Llt(values);
        self.check(lower, true, b)
    }

    /// Numeric intranodal LBLᵀ with the cached symbolic factorization, then the probe check.
    fn try_lblt(
        &mut self,
        lower: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let sym = self.chol.as_ref().ok_or(SolveError::NotFactorized)?;
        let (n, par) = (sym.nrows(), cholesky_parallelism(sym));
        let mut values = vec![0.0; sym.len_val()];
        let mut subdiag = vec![0.0; n];
        let (mut fwd, mut inv): (Vec<Index>, Vec<Index>) = (vec![0; n], vec![0; n]);
        let req = sym.factorize_numeric_intranode_lblt_scratch::<f64>(par, Default::default());
        let mut mem = buffer(req)?;
        let stack = MemStack::new(&mut mem);
        sym.factorize_numeric_intranode_lblt(
            &mut values,
            &mut subdiag,
            &mut fwd,
            &mut inv,
            lower,
            Side::Lower,
            par,
            stack,
            Default::default(),
        );
        self.numeric = Numeric::Lblt {
            values,
            subdiag,
            fwd,
            inv,
        };
        self.check(lower, true, b)
    }

    /// Symbolic (cached) + numeric LU of the full matrix `a`, then the probe check.
    fn factor_lu(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        b: Option<&[f64]>,
    ) -> Result<(Method, Option<Vec<f64>>), SolveError> {
        self.ensure_lu(a)?;
        let sym = self.lu.as_ref().ok_or(SolveError::NotFactorized)?;
        let par = parallelism();
        let mut num = NumericLu::new();
        let mut mem = buffer(sym.factorize_numeric_lu_scratch::<f64>(par, Default::default()))?;
        let stack = MemStack::new(&mut mem);
        sym.factorize_numeric_lu(&mut num, a, par, stack, Default::default())
            .map_err(lu_error)?;
        self.numeric = Numeric::Lu(Box::new(num));
        let x = self.check(a, false, b)?;
        Ok((Method::Lu, x))
    }

    /// Solve in place with the Cholesky-family factors (LLᵀ or LBLᵀ).
    fn solve_chol(&self, num: &Numeric, rhs: MatMut<f64>, par: Par) -> Result<(), SolveError> {
        let sym = self.chol.as_ref().ok_or(SolveError::NotFactorized)?;
        let mut mem = buffer(sym.solve_in_place_scratch::<f64>(rhs.ncols(), par))?;
        let stack = MemStack::new(&mut mem);
        match num {
            Numeric::Llt(values) => {
                LltRef::new(sym, values).solve_in_place_with_conj(Conj::No, rhs, par, stack)
            }
            Numeric::Lblt {
                values,
                subdiag,
                fwd,
                inv,
            } => {
                let perm = PermRef::new_checked(fwd, inv, sym.nrows());
                IntranodeLbltRef::new(sym, values, subdiag, perm).solve_in_place_with_conj(
                    Conj::No,
                    rhs,
                    par,
                    stack,
                )
            }
            _ => return Err(SolveError::NotFactorized),
        }
        Ok(())
    }

    /// Solve in place with the LU factors.
    fn solve_lu(
        &self,
        num: &NumericLu<Index, f64>,
        rhs: MatMut<f64>,
        par: Par,
    ) -> Result<(), SolveError> {
        let sym = self.lu.as_ref().ok_or(SolveError::NotFactorized)?;
        let mut mem = buffer(sym.solve_in_place_scratch::<f64>(rhs.ncols(), par))?;
        LuRef::new_unchecked(sym, num).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut mem),
        );
        Ok(())
    }

    /// Probe check of the current factors: solve `K y = K v` for a fixed `v`; reject
    /// non-finite results, a large backward error (unstable) or a large forward error
    /// (singular). With `b`, `K x = b` is solved in the same pass and x returned.
    fn check(
        &mut self,
        a: SparseColMatRef<Index, f64>,
        sym: bool,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let result = self.probe(a, sym, b);
        if result.is_err() {
            self.numeric = Numeric::None;
        }
        result
    }

    /// The probe solve of [`Self::check`], without the cleanup.
    fn probe(
        &self,
        a: SparseColMatRef<Index, f64>,
        sym: bool,
        b: Option<&[f64]>,
    ) -> Result<Option<Vec<f64>>, SolveError> {
        let n = a.nrows();
        let v: Vec<f64> = (0..n).map(probe_entry).collect();
        let kv = spmv(a, sym, &v, false);
        // Columns [K v | b], solved together.
        let mut columns = kv.clone();
        columns.extend_from_slice(b.unwrap_or_default());
        self.solve_columns(&mut columns, n, 1 + usize::from(b.is_some()))?;
        let x = b.map(|_| columns.split_off(n));
        let y = columns;
        if y.iter().any(|t| !t.is_finite()) {
            return Err(SolveError::Singular("non-finite probe solution".into()));
        }
        let ky = spmv(a, sym, &y, false);
        let abs_ky = spmv(a, sym, &y.iter().map(|t| t.abs()).collect::<Vec<_>>(), true);
        let res = max_abs_diff(&ky, &kv);
        let backward = res / (max_abs(&abs_ky) + max_abs(&kv)).max(f64::MIN_POSITIVE);
        if backward > CHECK_BACKWARD_TOL {
            return Err(SolveError::Singular(format!(
                "probe backward error {backward:.2e}"
            )));
        }
        let forward = max_abs_diff(&y, &v) / max_abs(&v);
        if forward > CHECK_FORWARD_TOL {
            return Err(SolveError::Singular(format!(
                "probe forward error {forward:.2e}"
            )));
        }
        Ok(x)
    }
}

/// The inverse of a permutation.
fn inverse(perm: &[usize]) -> Vec<Index> {
    let mut inv = vec![0; perm.len()];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new as Index;
    }
    inv
}

/// Deterministic probe vector entry in [0.5, 1.5), not aligned with grid structure.
fn probe_entry(i: usize) -> f64 {
    0.5 + ((i as u64).wrapping_mul(2_654_435_761) % 1_000_003) as f64 / 1_000_003.0
}

/// `y = A x` (or `|A| x` when `abs`); with `sym`, `a` holds the lower triangle of a symmetric matrix.
pub fn spmv(a: SparseColMatRef<Index, f64>, sym: bool, x: &[f64], abs: bool) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let (i, v) = (i as usize, if abs { v.abs() } else { v });
            y[i] += v * x[j];
            if sym && i != j {
                y[j] += v * x[i];
            }
        }
    }
    y
}

/// `max_i |a_i|`.
fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, t| m.max(t.abs()))
}

/// `max_i |a_i − b_i|`.
fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (s, t)| m.max((s - t).abs()))
}

/// Non-finite values, and entries above the diagonal of a `Symmetric` matrix, are
/// invalid input.
fn check_entries(a: SparseColMatRef<Index, f64>, structure: Structure) -> Result<(), SolveError> {
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            if !v.is_finite() {
                return Err(SolveError::InvalidInput(format!(
                    "non-finite value {v} at ({i}, {j})"
                )));
            }
            if structure == Structure::Symmetric && (i as usize) < j {
                let msg =
                    "Symmetric structure reads the lower triangle, but an upper entry was given";
                return Err(SolveError::InvalidInput(msg.into()));
            }
        }
    }
    Ok(())
}

/// The CSC matrix of triplets (duplicates summed); lower triangle only for
/// `Symmetric`.
fn csc_from_triplets(
    n: usize,
    triplets: &[(usize, usize, f64)],
    structure: Structure,
) -> Result<SparseColMat<Index, f64>, SolveError> {
    if let Some(&(r, c, v)) = triplets.iter().find(|t| !t.2.is_finite()) {
        return Err(SolveError::InvalidInput(format!(
            "non-finite value {v} at ({r}, {c})"
        )));
    }
    let upper_only = structure == Structure::Symmetric
        && triplets.iter().any(|t| t.0 < t.1)
        && !triplets.iter().any(|t| t.0 > t.1);
    if upper_only {
        let msg = "Symmetric structure reads the lower triangle, but only upper entries were given";
        return Err(SolveError::InvalidInput(msg.into()));
    }
    if n > Index::MAX as usize {
        return Err(SolveError::InvalidInput(format!(
            "{n} unknowns, more than 32-bit indices number"
        )));
    }
    let entries: Vec<Triplet<Index, Index, f64>> = triplets
        .iter()
        .filter(|t| structure == Structure::General || t.0 >= t.1)
        .map(|&(r, c, v)| Triplet::new(r as Index, c as Index, v))
        .collect();
    SparseColMat::try_new_from_triplets(n, n, &entries).map_err(creation_error)
}

/// Full symmetric matrix from its lower triangle (for the LU fallback).
fn mirror_lower(
    lower: SparseColMatRef<Index, f64>,
) -> Result<SparseColMat<Index, f64>, SolveError> {
    let mut entries = Vec::with_capacity(2 * lower.compute_nnz());
    for j in 0..lower.ncols() {
        for (&i, &v) in lower.row_idx_of_col_raw(j).iter().zip(lower.val_of_col(j)) {
            let j = j as Index;
            entries.push(Triplet::new(i, j, v));
            if i != j {
                entries.push(Triplet::new(j, i, v));
            }
        }
    }
    let n = lower.nrows();
    SparseColMat::try_new_from_triplets(n, n, &entries).map_err(creation_error)
}

/// Allocate a faer workspace.
fn buffer(req: StackReq) -> Result<MemBuffer, SolveError> {
    MemBuffer::try_new(req).map_err(|_| SolveError::Backend("out of memory for workspace".into()))
}

/// Map a faer error that is not about the matrix values.
fn backend<E: std::fmt::Debug>(e: E) -> SolveError {
    SolveError::Backend(format!("{e:?}"))
}

/// Map a triplet-conversion error.
fn creation_error(e: CreationError) -> SolveError {
    match e {
        CreationError::OutOfBounds { row, col } => {
            SolveError::InvalidInput(format!("triplet index ({row}, {col}) out of bounds"))
        }
        CreationError::Generic(e) => backend(e),
    }
}

/// Map a sparse LU error.
fn lu_error(e: LuError) -> SolveError {
    match e {
        LuError::SymbolicSingular { index } => {
            SolveError::Singular(format!("LU: structurally singular at step {index}"))
        }
        LuError::Generic(e) => backend(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    type Trip = Vec<(usize, usize, f64)>;

    /// `y = K x` straight from the triplets (full matrix, duplicates add up).
    fn apply(n: usize, t: &[(usize, usize, f64)], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; n];
        for &(i, j, v) in t {
            y[i] += v * x[j];
        }
        y
    }

    fn norm(a: &[f64]) -> f64 {
        a.iter().map(|t| t * t).sum::<f64>().sqrt()
    }

    fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
        let d: Vec<f64> = a.iter().zip(b).map(|(s, t)| s - t).collect();
        norm(&d) / norm(b)
    }

    /// Smooth-ish known solution.
    fn x_star(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| (0.37 * i as f64).sin() + 0.1 * (i % 5) as f64)
            .collect()
    }

    /// Factorize, solve against x*, return (method, relative error, relative residual).
    fn check_solve(
        s: &mut DirectSolver,
        n: usize,
        t: &[(usize, usize, f64)],
        st: Structure,
    ) -> (Method, f64, f64) {
        let method = s.factorize_triplets(n, t, st).expect("factorize");
        let xs = x_star(n);
        let b = apply(n, t, &xs);
        let x = s.solve(&b).expect("solve");
        let res = rel_diff(&apply(n, t, &x), &b);
        (method, rel_diff(&x, &xs), res)
    }

    /// 1D Laplacian assembled from 2x2 element matrices, grounded at both ends (SPD).
    fn laplace_1d(n: usize, ground: bool) -> Trip {
        let mut t = Vec::new();
        for e in 0..n - 1 {
            let (a, b) = (e, e + 1);
            t.extend([(a, a, 1.0), (a, b, -1.0), (b, a, -1.0), (b, b, 1.0)]);
        }
        if ground {
            t.extend([(0, 0, 1.0), (n - 1, n - 1, 1.0)]);
        }
        t
    }

    /// 2D 5-point Laplacian (Dirichlet), diagonal `4 * scale - shift`.
    /// An SPD matrix shaped like a 3D elastic tangent: the 27-point stencil of
    /// an m³ node grid (strictly diagonally dominant) ⊗ a 3×3 SPD block coupling
    /// the components (1, 2, 1 tridiagonal), 3 unknowns per node.
    fn elastic_like_3d(m: usize) -> Trip {
        let block = [[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]];
        let id = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
        let range = |i: usize| i.saturating_sub(1)..(i + 2).min(m);
        let mut t = Vec::new();
        for (i, j, k) in
            (0..m).flat_map(|i| (0..m).flat_map(move |j| (0..m).map(move |k| (i, j, k))))
        {
            for (p, q, r) in
                range(i).flat_map(|p| range(j).flat_map(move |q| range(k).map(move |r| (p, q, r))))
            {
                let w = if (p, q, r) == (i, j, k) { 26.5 } else { -1.0 };
                for (a, row) in block.iter().enumerate() {
                    for (b, &v) in row.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                        t.push((3 * id(i, j, k) + a, 3 * id(p, q, r) + b, w * v));
                    }
                }
            }
        }
        t
    }

    fn laplace_2d(m: usize, scale: f64, shift: f64) -> Trip {
        let id = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                t.push((id(i, j), id(i, j), 4.0 * scale - shift));
                if i > 0 {
                    t.push((id(i, j), id(i - 1, j), -1.0));
                }
                if i + 1 < m {
                    t.push((id(i, j), id(i + 1, j), -1.0));
                }
                if j > 0 {
                    t.push((id(i, j), id(i, j - 1), -1.0));
                }
                if j + 1 < m {
                    t.push((id(i, j), id(i, j + 1), -1.0));
                }
            }
        }
        t
    }

    /// 3D 7-point Laplacian (Dirichlet).
    fn laplace_3d(m: usize) -> Trip {
        let id = |i: usize, j: usize, k: usize| (i * m + j) * m + k;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                for k in 0..m {
                    let p = id(i, j, k);
                    t.push((p, p, 6.0));
                    let nb = [
                        (i > 0, (i.wrapping_sub(1), j, k)),
                        (i + 1 < m, (i + 1, j, k)),
                        (j > 0, (i, j.wrapping_sub(1), k)),
                        (j + 1 < m, (i, j + 1, k)),
                        (k > 0, (i, j, k.wrapping_sub(1))),
                        (k + 1 < m, (i, j, k + 1)),
                    ];
                    for (ok, (a, b, c)) in nb {
                        if ok {
                            t.push((p, id(a, b, c), -1.0));
                        }
                    }
                }
            }
        }
        t
    }

    #[test]
    fn laplace_1d_with_duplicates_uses_llt() {
        let n = 1000;
        let t = laplace_1d(n, true);
        let mut s = DirectSolver::new();
        let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
        eprintln!(
            "1D Laplacian n={n}: method {method:?}, rel error {err:.2e}, rel residual {res:.2e}"
        );
        assert_eq!(method, Method::Llt);
        assert!(err < 1e-10, "relative error {err}");
        assert_eq!(s.symbolic_count(), 1);
    }

    #[test]
    fn lower_triangle_only_gives_same_solution() {
        let n = 200;
        let full = laplace_1d(n, true);
        let lower: Trip = full.iter().copied().filter(|t| t.0 >= t.1).collect();
        let b = apply(n, &full, &x_star(n));
        let mut s = DirectSolver::new();
        s.factorize_triplets(n, &full, Structure::Symmetric)
            .unwrap();
        let x_full = s.solve(&b).unwrap();
        s.factorize_triplets(n, &lower, Structure::Symmetric)
            .unwrap();
        assert_eq!(x_full, s.solve(&b).unwrap());
        assert_eq!(s.symbolic_count(), 1, "same lower pattern");
    }

    #[test]
    fn laplace_2d_symbolic_reuse() {
        let m = 100;
        let n = m * m;
        let mut s = DirectSolver::new();
        let t = laplace_2d(m, 1.0, 0.0);
        let t0 = Instant::now();
        let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
        let first = t0.elapsed();
        eprintln!("2D Laplacian n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, first factorize+solve {first:?}");
        assert_eq!(method, Method::Llt);
        assert!(err < 1e-10, "relative error {err}");
        assert_eq!(s.symbolic_count(), 1);

        let t2 = laplace_2d(m, 2.0, 0.0);
        let t0 = Instant::now();
        let (method, err, res) = check_solve(&mut s, n, &t2, Structure::Symmetric);
        let second = t0.elapsed();
        eprintln!("  values changed: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, refactorize+solve {second:?}");
        assert_eq!(method, Method::Llt);
        assert!(err < 1e-10, "relative error {err}");
        assert_eq!(
            s.symbolic_count(),
            1,
            "symbolic factorization must be reused"
        );

        let mut t3 = t2.clone();
        t3.extend([(0, n - 1, -0.5), (n - 1, 0, -0.5)]);
        let (method, err, _) = check_solve(&mut s, n, &t3, Structure::Symmetric);
        assert_eq!(method, Method::Llt);
        assert!(err < 1e-10, "relative error {err}");
        assert_eq!(s.symbolic_count(), 2, "pattern changed");
    }

    #[test]
    fn timing_2d_100x100() {
        let m = 100;
        let n = m * m;
        let t = laplace_2d(m, 1.0, 0.0);
        let mut s = DirectSolver::new();
        let t0 = Instant::now();
        s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
        let first = t0.elapsed();
        let mut times = Vec::new();
        for _ in 0..5 {
            let t0 = Instant::now();
            s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
            times.push(t0.elapsed());
        }
        let b = vec![1.0; n];
        let t0 = Instant::now();
        let _ = s.solve(&b).unwrap();
        let solve = t0.elapsed();
        eprintln!("100x100: first factorize (symbolic+numeric+check) {first:?}, reuse {times:?}, solve {solve:?}");
        assert_eq!(s.symbolic_count(), 1);
    }

    #[test]
    fn laplace_minus_shift_is_indefinite() {
        let m = 30;
        let n = m * m;
        let t = laplace_2d(m, 1.0, 1.2345);
        let mut s = DirectSolver::new();
        let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
        eprintln!(
            "shifted Laplacian n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}"
        );
        assert_ne!(method, Method::Llt);
        assert!(res < 1e-8, "relative residual {res}");
    }

    #[test]
    fn saddle_point_is_indefinite() {
        // [[A, Bᵀ], [B, 0]], A = 1D Laplacian (n_a), B sums pairs of consecutive unknowns.
        let (na, nb) = (400, 100);
        let n = na + nb;
        let mut t = laplace_1d(na, true);
        for k in 0..nb {
            for j in [4 * k, 4 * k + 1] {
                t.extend([(na + k, j, 1.0), (j, na + k, 1.0)]);
            }
        }
        let mut s = DirectSolver::new();
        let (method, err, res) = check_solve(&mut s, n, &t, Structure::Symmetric);
        eprintln!("saddle point n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}, symbolic {}", s.symbolic_count());
        assert_ne!(method, Method::Llt);
        assert!(res < 1e-8, "relative residual {res}");
    }

    /// -eps u'' + c u' on a uniform grid, first-order upwinding (c > 0), Dirichlet ends.
    fn convection_diffusion(n: usize, eps: f64, c: f64) -> Trip {
        let h = 1.0 / (n + 1) as f64;
        let (d, lo, up) = (
            2.0 * eps / (h * h) + c / h,
            -eps / (h * h) - c / h,
            -eps / (h * h),
        );
        let mut t = Vec::new();
        for i in 0..n {
            t.push((i, i, d));
            if i > 0 {
                t.push((i, i - 1, lo));
            }
            if i + 1 < n {
                t.push((i, i + 1, up));
            }
        }
        t
    }

    #[test]
    fn nonsymmetric_uses_lu_and_reuses_symbolic() {
        let n = 1000;
        let t = convection_diffusion(n, 0.01, 1.0);
        let mut s = DirectSolver::new();
        let (method, err, res) = check_solve(&mut s, n, &t, Structure::General);
        eprintln!(
            "convection-diffusion n={n}: {method:?}, rel error {err:.2e}, rel residual {res:.2e}"
        );
        assert_eq!(method, Method::Lu);
        assert!(err < 1e-10, "relative error {err}");
        let t2 = convection_diffusion(n, 0.001, 2.0);
        let (method, err, _) = check_solve(&mut s, n, &t2, Structure::General);
        assert_eq!(method, Method::Lu);
        assert!(err < 1e-10, "relative error {err}");
        assert_eq!(s.symbolic_count(), 1);
    }

    #[test]
    fn singular_matrices_give_errors() {
        let n = 300;
        let mut s = DirectSolver::new();
        // General: row k is all zeros (column k keeps its entries).
        let k = 150;
        let t: Trip = convection_diffusion(n, 0.01, 1.0)
            .into_iter()
            .filter(|e| e.0 != k)
            .collect();
        let r = s.factorize_triplets(n, &t, Structure::General);
        eprintln!("zero row (general): {r:?}");
        assert!(matches!(r, Err(SolveError::Singular(_))));
        assert!(matches!(
            s.solve(&vec![1.0; n]),
            Err(SolveError::NotFactorized)
        ));
        // General: row k holds an explicit 0 on the diagonal only.
        let mut t0 = t.clone();
        t0.retain(|e| e.1 != k);
        t0.push((k, k, 0.0));
        let r = s.factorize_triplets(n, &t0, Structure::General);
        eprintln!("zero row+column with explicit zero diagonal (general): {r:?}");
        assert!(matches!(r, Err(SolveError::Singular(_))));
        // Symmetric: zero row and column.
        let t: Trip = laplace_1d(n, true)
            .into_iter()
            .filter(|e| e.0 != k && e.1 != k)
            .collect();
        let r = s.factorize_triplets(n, &t, Structure::Symmetric);
        eprintln!("zero row and column (symmetric): {r:?}");
        assert!(matches!(r, Err(SolveError::Singular(_))));
        // Symmetric: pure-Neumann Laplacians, 1D and 2D.
        let r = s.factorize_triplets(n, &laplace_1d(n, false), Structure::Symmetric);
        eprintln!("pure Neumann 1D: {r:?}");
        assert!(matches!(r, Err(SolveError::Singular(_))));
        let m = 40;
        let mut t = laplace_2d(m, 1.0, 0.0);
        for (i, j, v) in t.iter_mut() {
            if i == j {
                let (a, b) = (*i / m, *i % m);
                *v = [a > 0, a + 1 < m, b > 0, b + 1 < m]
                    .iter()
                    .filter(|&&x| x)
                    .count() as f64;
            }
        }
        let r = s.factorize_triplets(m * m, &t, Structure::Symmetric);
        eprintln!("pure Neumann 2D: {r:?}");
        assert!(matches!(r, Err(SolveError::Singular(_))));
    }

    /// The Newton path (`factorize_and_solve`: the right-hand side solved
    /// with the probe as a second column) gives the solution of factorize +
    /// solve to round-off, with the same method, for each method; a singular
    /// matrix is refused as by `factorize`.
    #[test]
    fn factorize_and_solve_agrees_with_factorize_then_solve() {
        let cases: Vec<(usize, Trip, Structure, Method)> = vec![
            (
                10_000,
                laplace_2d(100, 1.0, 0.0),
                Structure::Symmetric,
                Method::Llt,
            ),
            (
                900,
                laplace_2d(30, 1.0, 1.2345),
                Structure::Symmetric,
                Method::Ldlt,
            ),
            (
                300,
                convection_diffusion(300, 0.01, 1.0),
                Structure::General,
                Method::Lu,
            ),
        ];
        for (n, t, structure, expected) in cases {
            let b = apply(n, &t, &x_star(n));
            let a = csc_from_triplets(n, &t, structure).unwrap();
            let mut plain = DirectSolver::new();
            let method = plain
                .factorize(a.as_ref(), structure, Ordering::Amd)
                .unwrap();
            let x = plain.solve(&b).unwrap();
            let mut fused = DirectSolver::new();
            let (method_fused, x_fused) = fused
                .factorize_and_solve(a.as_ref(), structure, Ordering::Amd, &b)
                .unwrap();
            assert_eq!(method, expected);
            assert_eq!(method_fused, expected);
            let d = rel_diff(&x_fused, &x);
            eprintln!("{expected:?}, n = {n}: fused against plain {d:.2e}");
            assert!(d < 1e-13, "{expected:?}: {d:.2e}");
            assert!(rel_diff(&x_fused, &x_star(n)) < 1e-8);
            // The fused solver can also solve again.
            assert!(rel_diff(&fused.solve(&b).unwrap(), &x) < 1e-13);
        }
        let m = 40;
        let t: Trip = laplace_1d(m, false);
        let a = csc_from_triplets(m, &t, Structure::Symmetric).unwrap();
        let mut s = DirectSolver::new();
        let r = s.factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &[1.0; 40]);
        assert!(matches!(r, Err(SolveError::Singular(_))), "{r:?}");
        assert!(matches!(
            s.solve(&[1.0; 40]),
            Err(SolveError::NotFactorized)
        ));
        let r = s.factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &[1.0; 3]);
        assert!(matches!(r, Err(SolveError::InvalidInput(_))), "{r:?}");
    }

    #[test]
    fn invalid_input_is_reported() {
        let mut s = DirectSolver::new();
        assert!(matches!(s.solve(&[1.0]), Err(SolveError::NotFactorized)));
        let r = s.factorize_triplets(3, &[(0, 0, 1.0), (3, 0, 1.0)], Structure::General);
        assert!(matches!(r, Err(SolveError::InvalidInput(_))));
        let r = s.factorize_triplets(2, &[(0, 0, 1.0), (1, 1, f64::NAN)], Structure::General);
        assert!(matches!(r, Err(SolveError::InvalidInput(_))));
        let upper = [(0, 0, 2.0), (0, 1, -1.0), (1, 1, 2.0)];
        let r = s.factorize_triplets(2, &upper, Structure::Symmetric);
        assert!(matches!(r, Err(SolveError::InvalidInput(_))));
        s.factorize_triplets(2, &[(0, 0, 2.0), (1, 1, 4.0)], Structure::Symmetric)
            .unwrap();
        assert!(matches!(s.solve(&[1.0]), Err(SolveError::InvalidInput(_))));
        let x = s.solve(&[1.0, 1.0]).unwrap();
        assert!((x[0] - 0.5).abs() < 1e-15 && (x[1] - 0.25).abs() < 1e-15);
        for st in [Structure::Symmetric, Structure::General] {
            assert!(s.factorize_triplets(0, &[], st).is_ok());
            assert!(s.solve(&[]).unwrap().is_empty());
        }
    }

    #[test]
    fn deterministic_results() {
        let cases: Vec<(usize, Trip, Structure)> = vec![
            (10_000, laplace_2d(100, 1.0, 0.0), Structure::Symmetric),
            (27_000, laplace_3d(30), Structure::Symmetric),
            (900, laplace_2d(30, 1.0, 1.2345), Structure::Symmetric),
            (27_000, laplace_3d(30), Structure::General),
        ];
        for (n, t, st) in cases {
            let b = apply(n, &t, &x_star(n));
            let mut s1 = DirectSolver::new();
            let m1 = s1.factorize_triplets(n, &t, st).unwrap();
            let x1 = s1.solve(&b).unwrap();
            let x1b = s1.solve(&b).unwrap();
            s1.factorize_triplets(n, &t, st).unwrap();
            let x1c = s1.solve(&b).unwrap();
            let mut s2 = DirectSolver::new();
            let m2 = s2.factorize_triplets(n, &t, st).unwrap();
            let x2 = s2.solve(&b).unwrap();
            eprintln!(
                "determinism n={n} {st:?}: {m1:?}, rel error {:.2e}",
                rel_diff(&x1, &x_star(n))
            );
            assert_eq!(m1, m2);
            assert_eq!(x1, x1b);
            assert_eq!(x1, x1c);
            assert_eq!(x1, x2);
        }
    }

    /// A solver that factored another matrix first (its factor buffer and
    /// workspace are refilled, grown or not) gives bit for bit the solution
    /// of a fresh one: simplicial (small) and supernodal factors.
    #[test]
    fn kept_buffers_give_the_same_factors() {
        let cases: Vec<(usize, Trip)> = vec![
            (900, laplace_2d(30, 1.0, 1.2345)),
            (10_000, laplace_2d(100, 1.0, 0.0)),
            (8_000, laplace_3d(20)),
        ];
        for (n, t) in &cases {
            let b = apply(*n, t, &x_star(*n));
            let mut fresh = DirectSolver::new();
            fresh
                .factorize_triplets(*n, t, Structure::Symmetric)
                .unwrap();
            let x = fresh.solve(&b).unwrap();
            for (m, other) in &cases {
                let mut reused = DirectSolver::new();
                reused
                    .factorize_triplets(*m, other, Structure::Symmetric)
                    .unwrap();
                reused
                    .factorize_triplets(*n, t, Structure::Symmetric)
                    .unwrap();
                assert_eq!(reused.solve(&b).unwrap(), x, "n = {n} after m = {m}");
            }
        }
    }

    /// An analysis done ahead is the one the factorization uses: one symbolic
    /// factorization, the same solution bits, the old factors' buffer kept.
    #[test]
    fn an_analysis_ahead_serves_the_factorization() {
        let (n, t) = (2_500, laplace_2d(50, 1.0, 0.0));
        let b = apply(n, &t, &x_star(n));
        let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
        let mut plain = DirectSolver::new();
        plain
            .factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
            .unwrap();
        let x = plain.solve(&b).unwrap();
        let mut ahead = DirectSolver::new();
        // A factorization of another pattern first, whose buffer is then kept.
        ahead
            .factorize_triplets(900, &laplace_2d(30, 1.0, 0.0), Structure::Symmetric)
            .unwrap();
        let shared = Arc::new(a.symbolic().to_owned().unwrap());
        ahead.analyse(&shared, Ordering::Amd).unwrap();
        assert_eq!(ahead.symbolic_count(), 2);
        assert!(
            ahead.solve(&b).is_err(),
            "no factors of the new pattern yet"
        );
        ahead
            .factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
            .unwrap();
        assert_eq!(ahead.symbolic_count(), 2, "the analysis was not repeated");
        assert_eq!(ahead.solve(&b).unwrap(), x);
        // A matrix on the shared arrays themselves (the Newton path) is known
        // to have the analysed pattern: no new analysis, the same solution.
        let on_shared = SparseColMatRef::new((*shared).as_ref(), a.val());
        let (_, x_shared) = ahead
            .factorize_and_solve(on_shared, Structure::Symmetric, Ordering::Amd, &b)
            .unwrap();
        assert_eq!(ahead.symbolic_count(), 2);
        assert_eq!(x_shared, x);
    }

    /// A given ordering is used (the solution agrees with AMD's to round-off)
    /// and kept with the symbolic factorization while it does not change.
    #[test]
    fn a_given_ordering_is_used_and_kept() {
        let n = 10_000;
        let t = laplace_2d(100, 1.0, 0.0);
        let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
        let b = apply(n, &t, &x_star(n));
        let reversed: Vec<usize> = (0..n).rev().collect();
        let mut s = DirectSolver::new();
        s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&reversed))
            .unwrap();
        let x = s.solve(&b).unwrap();
        assert!(rel_diff(&x, &x_star(n)) < 1e-10);
        s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&reversed))
            .unwrap();
        assert_eq!(s.symbolic_count(), 1);
        s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Amd)
            .unwrap();
        assert_eq!(s.symbolic_count(), 2, "another ordering, another analysis");
        let short = vec![0; n - 1];
        assert!(matches!(
            s.factorize(a.as_ref(), Structure::Symmetric, Ordering::Given(&short)),
            Err(SolveError::InvalidInput(_))
        ));
    }

    /// A supernodal factorization large enough to run in parallel gives the
    /// same solution, bit for bit, on one thread and on two.
    #[test]
    fn factors_do_not_depend_on_the_number_of_threads() {
        let m = 16;
        let elastic_like = elastic_like_3d(m);
        let n3 = 3 * m * m * m;
        // The elasticity-like block is dense enough for two faer tasks, the
        // Laplacians are factorized sequentially: both paths are checked.
        let sym = |n: usize, t: &Trip| {
            let a = csc_from_triplets(n, t, Structure::Symmetric).unwrap();
            let params = CholeskySymbolicParams::default();
            factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Amd, params)
                .unwrap()
        };
        let two_tasks = sym(n3, &elastic_like);
        let mean = two_tasks.len_val() / n3;
        assert!(
            matches!(cholesky_parallelism(&two_tasks), Par::Rayon(_)),
            "mean column count {mean} should take two tasks"
        );
        assert!(matches!(
            cholesky_parallelism(&sym(27_000, &laplace_3d(30))),
            Par::Seq
        ));
        for (n, t) in [
            (n3, elastic_like),
            (27_000, laplace_3d(30)),
            (40_000, laplace_2d(200, 1.0, 0.0)),
        ] {
            let b = apply(n, &t, &x_star(n));
            let solve = |threads: usize| {
                crate::parallel::on_threads(threads, || {
                    let mut s = DirectSolver::new();
                    s.factorize_triplets(n, &t, Structure::Symmetric).unwrap();
                    let a = csc_from_triplets(n, &t, Structure::Symmetric).unwrap();
                    let mut fused = DirectSolver::new();
                    let (_, x) = fused
                        .factorize_and_solve(a.as_ref(), Structure::Symmetric, Ordering::Amd, &b)
                        .unwrap();
                    (s.solve(&b).unwrap(), x)
                })
            };
            let one = solve(1);
            assert!(one == solve(2), "n = {n}: 1 and 2 threads differ");
            assert!(one == solve(3), "n = {n}: 1 and 3 threads differ");
        }
    }
}
