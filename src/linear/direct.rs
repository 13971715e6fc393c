//! Sparse direct solver for the implicit MPM tangent system `K x = b`, backed by faer 0.24.
//!
//! `K` arrives as triplets (duplicates summed). The symbolic factorization (fill-reducing
//! ordering + elimination structure) is cached and reused while the sparsity pattern is
//! unchanged. Symmetric matrices go LLᵀ → intranodal LBLᵀ → LU; general ones go to LU.
//! Every numeric factorization is checked with one probe solve (see [`CHECK_BACKWARD_TOL`]
//! and [`CHECK_FORWARD_TOL`]) so that singular or unstably factored matrices give an error
//! instead of a garbage solution.

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
use faer::sparse::{CreationError, SparseColMat, SparseColMatRef, Triplet};
use faer::{Conj, MatMut, Par, Side};

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

/// Factorization that was used by the last successful [`DirectSolver::factorize`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
        match self {
            Method::Llt => "llt",
            Method::Ldlt => "ldlt",
            Method::Lu => "lu",
        }
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

/// Sorted, deduplicated pattern of the last factorized matrix (key of the symbolic cache).
struct Pattern {
    n: usize,
    structure: Structure,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
}

/// Numeric factors of the last successful factorization.
#[allow(clippy::large_enum_variant)] // one instance per solver: size is irrelevant
enum Numeric {
    None,
    Llt(Vec<f64>),
    Lblt {
        values: Vec<f64>,
        subdiag: Vec<f64>,
        fwd: Vec<usize>,
        inv: Vec<usize>,
    },
    Lu(NumericLu<usize, f64>),
}

/// Sparse direct solver holding the symbolic factorizations and the pattern they belong to.
pub struct DirectSolver {
    pattern: Option<Pattern>,
    chol: Option<SymbolicCholesky<usize>>,
    lu: Option<SymbolicLu<usize>>,
    numeric: Numeric,
    symbolic_count: usize,
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
            pattern: None,
            chol: None,
            lu: None,
            numeric: Numeric::None,
            symbolic_count: 0,
        }
    }

    /// Factorize K given as triplets (duplicates summed); reuses the symbolic factorization
    /// when the pattern (the sorted, deduplicated set of (row, col)) equals the previous one.
    /// On error the previous factorization is discarded ([`Self::solve`] gives `NotFactorized`).
    pub fn factorize(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        structure: Structure,
    ) -> Result<Method, SolveError> {
        self.numeric = Numeric::None;
        let a = build_csc(n, triplets, structure)?;
        self.update_pattern(n, structure, a.as_ref());
        match structure {
            Structure::General => self.factor_lu(a.as_ref()),
            Structure::Symmetric => self.factor_symmetric(a.as_ref()),
        }
    }

    /// Solve `K x = b` with the last factorization; `b` is left untouched and `x` returned.
    pub fn solve(&self, b: &[f64]) -> Result<Vec<f64>, SolveError> {
        let n = self.pattern.as_ref().ok_or(SolveError::NotFactorized)?.n;
        if b.len() != n {
            let msg = format!("right-hand side has length {}, expected {n}", b.len());
            return Err(SolveError::InvalidInput(msg));
        }
        let mut x = b.to_vec();
        let par = faer::get_global_parallelism();
        let rhs = MatMut::from_column_major_slice_mut(&mut x, n, 1);
        match &self.numeric {
            Numeric::None => return Err(SolveError::NotFactorized),
            Numeric::Lu(num) => self.solve_lu(num, rhs, par)?,
            chol => self.solve_chol(chol, rhs, par)?,
        }
        Ok(x)
    }

    /// How many symbolic factorizations (Cholesky or LU analyses) were computed so far.
    pub fn symbolic_count(&self) -> usize {
        self.symbolic_count
    }

    /// Keep the cached symbolic factorizations iff the new pattern equals the stored one.
    fn update_pattern(&mut self, n: usize, structure: Structure, a: SparseColMatRef<usize, f64>) {
        let (col_ptr, row_idx) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let same = self.pattern.as_ref().is_some_and(|p| {
            p.n == n && p.structure == structure && p.col_ptr == col_ptr && p.row_idx == row_idx
        });
        if !same {
            self.chol = None;
            self.lu = None;
            self.pattern = Some(Pattern {
                n,
                structure,
                col_ptr: col_ptr.to_vec(),
                row_idx: row_idx.to_vec(),
            });
        }
    }

    /// LLᵀ, then LBLᵀ, then LU on the mirrored full matrix; `lower` holds the lower triangle.
    fn factor_symmetric(
        &mut self,
        lower: SparseColMatRef<usize, f64>,
    ) -> Result<Method, SolveError> {
        self.ensure_chol(lower)?;
        if self.try_llt(lower).is_ok() {
            return Ok(Method::Llt);
        }
        if self.try_lblt(lower).is_ok() {
            return Ok(Method::Ldlt);
        }
        let full = mirror_lower(lower)?;
        self.factor_lu(full.as_ref())
    }

    /// Compute the symbolic Cholesky (AMD ordering) of the lower triangle unless cached.
    fn ensure_chol(&mut self, lower: SparseColMatRef<usize, f64>) -> Result<(), SolveError> {
        if self.chol.is_none() {
            let params = CholeskySymbolicParams::default();
            let sym = factorize_symbolic_cholesky(
                lower.symbolic(),
                Side::Lower,
                SymmetricOrdering::Amd,
                params,
            )
            .map_err(backend)?;
            self.chol = Some(sym);
            self.symbolic_count += 1;
        }
        Ok(())
    }

    /// Compute the symbolic LU (COLAMD ordering) of the full matrix unless cached.
    fn ensure_lu(&mut self, a: SparseColMatRef<usize, f64>) -> Result<(), SolveError> {
        if self.lu.is_none() {
            let sym = factorize_symbolic_lu(a.symbolic(), LuSymbolicParams::default())
                .map_err(backend)?;
            self.lu = Some(sym);
            self.symbolic_count += 1;
        }
        Ok(())
    }

    /// Numeric LLᵀ with the cached symbolic factorization, then the probe check.
    fn try_llt(&mut self, lower: SparseColMatRef<usize, f64>) -> Result<(), SolveError> {
        let sym = self.chol.as_ref().ok_or(SolveError::NotFactorized)?;
        let par = faer::get_global_parallelism();
        let mut values = vec![0.0; sym.len_val()];
        let mut mem = buffer(sym.factorize_numeric_llt_scratch::<f64>(par, Default::default()))?;
        let stack = MemStack::new(&mut mem);
        sym.factorize_numeric_llt(
            &mut values,
            lower,
            Side::Lower,
            Default::default(),
            par,
            stack,
            Default::default(),
        )
        .map_err(|e| SolveError::Singular(format!("LLT: {e:?}")))?;
        self.numeric = Numeric::Llt(values);
        self.check(lower, true)
    }

    /// Numeric intranodal LBLᵀ with the cached symbolic factorization, then the probe check.
    fn try_lblt(&mut self, lower: SparseColMatRef<usize, f64>) -> Result<(), SolveError> {
        let sym = self.chol.as_ref().ok_or(SolveError::NotFactorized)?;
        let (n, par) = (sym.nrows(), faer::get_global_parallelism());
        let mut values = vec![0.0; sym.len_val()];
        let mut subdiag = vec![0.0; n];
        let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
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
        self.check(lower, true)
    }

    /// Symbolic (cached) + numeric LU of the full matrix `a`, then the probe check.
    fn factor_lu(&mut self, a: SparseColMatRef<usize, f64>) -> Result<Method, SolveError> {
        self.ensure_lu(a)?;
        let sym = self.lu.as_ref().ok_or(SolveError::NotFactorized)?;
        let par = faer::get_global_parallelism();
        let mut num = NumericLu::new();
        let mut mem = buffer(sym.factorize_numeric_lu_scratch::<f64>(par, Default::default()))?;
        let stack = MemStack::new(&mut mem);
        sym.factorize_numeric_lu(&mut num, a, par, stack, Default::default())
            .map_err(lu_error)?;
        self.numeric = Numeric::Lu(num);
        self.check(a, false)?;
        Ok(Method::Lu)
    }

    /// Solve in place with the Cholesky-family factors (LLᵀ or LBLᵀ).
    fn solve_chol(&self, num: &Numeric, rhs: MatMut<f64>, par: Par) -> Result<(), SolveError> {
        let sym = self.chol.as_ref().ok_or(SolveError::NotFactorized)?;
        let mut mem = buffer(sym.solve_in_place_scratch::<f64>(1, par))?;
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
        num: &NumericLu<usize, f64>,
        rhs: MatMut<f64>,
        par: Par,
    ) -> Result<(), SolveError> {
        let sym = self.lu.as_ref().ok_or(SolveError::NotFactorized)?;
        let mut mem = buffer(sym.solve_in_place_scratch::<f64>(1, par))?;
        LuRef::new_unchecked(sym, num).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut mem),
        );
        Ok(())
    }

    /// Probe check of the current factors: solve `K y = K v` for a fixed `v`; reject
    /// non-finite results, a large backward error (unstable) or a large forward error (singular).
    fn check(&mut self, a: SparseColMatRef<usize, f64>, sym: bool) -> Result<(), SolveError> {
        let result = self.probe(a, sym);
        if result.is_err() {
            self.numeric = Numeric::None;
        }
        result
    }

    /// The probe solve of [`Self::check`], without the cleanup.
    fn probe(&self, a: SparseColMatRef<usize, f64>, sym: bool) -> Result<(), SolveError> {
        let v: Vec<f64> = (0..a.nrows()).map(probe_entry).collect();
        let b = spmv(a, sym, &v, false);
        let y = self.solve(&b)?;
        if y.iter().any(|t| !t.is_finite()) {
            return Err(SolveError::Singular("non-finite probe solution".into()));
        }
        let ky = spmv(a, sym, &y, false);
        let abs_ky = spmv(a, sym, &y.iter().map(|t| t.abs()).collect::<Vec<_>>(), true);
        let res = max_abs_diff(&ky, &b);
        let backward = res / (max_abs(&abs_ky) + max_abs(&b)).max(f64::MIN_POSITIVE);
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
        Ok(())
    }
}

/// Deterministic probe vector entry in [0.5, 1.5), not aligned with grid structure.
fn probe_entry(i: usize) -> f64 {
    0.5 + ((i as u64).wrapping_mul(2_654_435_761) % 1_000_003) as f64 / 1_000_003.0
}

/// `y = A x` (or `|A| x` when `abs`); with `sym`, `a` holds the lower triangle of a symmetric matrix.
fn spmv(a: SparseColMatRef<usize, f64>, sym: bool, x: &[f64], abs: bool) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
            let v = if abs { v.abs() } else { v };
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

/// Build the CSC matrix (duplicates summed by faer); lower triangle only for `Symmetric`.
fn build_csc(
    n: usize,
    triplets: &[(usize, usize, f64)],
    structure: Structure,
) -> Result<SparseColMat<usize, f64>, SolveError> {
    if let Some(&(r, c, v)) = triplets.iter().find(|t| !t.2.is_finite()) {
        return Err(SolveError::InvalidInput(format!(
            "non-finite value {v} at ({r}, {c})"
        )));
    }
    let keep = |t: &&(usize, usize, f64)| structure == Structure::General || t.0 >= t.1;
    let entries: Vec<Triplet<usize, usize, f64>> = triplets
        .iter()
        .filter(keep)
        .map(|&(r, c, v)| Triplet::new(r, c, v))
        .collect();
    SparseColMat::try_new_from_triplets(n, n, &entries).map_err(creation_error)
}

/// Full symmetric matrix from its lower triangle (for the LU fallback).
fn mirror_lower(
    lower: SparseColMatRef<usize, f64>,
) -> Result<SparseColMat<usize, f64>, SolveError> {
    let mut entries = Vec::with_capacity(2 * lower.compute_nnz());
    for j in 0..lower.ncols() {
        for (&i, &v) in lower.row_idx_of_col_raw(j).iter().zip(lower.val_of_col(j)) {
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
