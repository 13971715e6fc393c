//! The numeric factorization and the solves: LLᵀ, intranodal LBLᵀ and LU
//! on a symbolic analysis (`super::symbolic`), run with a fixed number of
//! faer tasks so that the factors do not depend on the threads.

use super::error::{buffer, lu_error, SolveError};
use super::symbolic::Symbolic;
use crate::solver::linear::Index;
use faer::dyn_stack::MemStack;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{IntranodeLbltRef, LltRef, SymbolicCholesky};
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu};
use faer::sparse::SparseColMatRef;
use faer::{Conj, MatMut, Par, Side};

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

/// Factorization that was used by the last successful `DirectSolver::factorize`.
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

/// Numeric factors of the last successful factorization.
#[allow(clippy::large_enum_variant)] // one instance per solver: size is irrelevant
pub(super) enum Numeric {
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

/// Numeric LLᵀ of the lower triangle `lower` with the symbolic factorization
/// `sym`, into the buffer of the `kept` factors when they are an LLᵀ factor
/// large enough.
pub(super) fn llt(
    sym: &SymbolicCholesky<Index>,
    lower: SparseColMatRef<Index, f64>,
    kept: Numeric,
) -> Result<Numeric, SolveError> {
    let par = cholesky_parallelism(sym);
    // faer overwrites every value of the factor, so the old buffer serves
    // (grown if the new pattern needs more).
    // A larger factor gets a buffer of its exact size, the old one freed first.
    let len = sym.len_val();
    let mut values = match kept {
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
    let mut work = buffer(req)?;
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
    result.map_err(|e| SolveError::Singular(format!("LLT: {e:?}")))?;
    Ok(Numeric::Llt(values))
}

/// Numeric intranodal LBLᵀ of the lower triangle `lower` with the symbolic
/// factorization `sym`.
pub(super) fn lblt(
    sym: &SymbolicCholesky<Index>,
    lower: SparseColMatRef<Index, f64>,
) -> Result<Numeric, SolveError> {
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
    Ok(Numeric::Lblt {
        values,
        subdiag,
        fwd,
        inv,
    })
}

/// Numeric LU of the full matrix `a` with the symbolic factorization `sym`.
pub(super) fn lu(
    sym: &SymbolicLu<Index>,
    a: SparseColMatRef<Index, f64>,
) -> Result<Numeric, SolveError> {
    let par = parallelism();
    let mut num = NumericLu::new();
    let mut mem = buffer(sym.factorize_numeric_lu_scratch::<f64>(par, Default::default()))?;
    let stack = MemStack::new(&mut mem);
    sym.factorize_numeric_lu(&mut num, a, par, stack, Default::default())
        .map_err(lu_error)?;
    Ok(Numeric::Lu(Box::new(num)))
}

impl Numeric {
    /// Whether these are factors to solve with.
    pub(super) fn is_some(&self) -> bool {
        !matches!(self, Numeric::None)
    }

    /// Solve in place for `ncols` right-hand sides stored column after column
    /// in `x`, with these factors of the analysis `symbolic`.
    pub(super) fn solve_columns(
        &self,
        symbolic: &Symbolic,
        x: &mut [f64],
        n: usize,
        ncols: usize,
    ) -> Result<(), SolveError> {
        let rhs = MatMut::from_column_major_slice_mut(x, n, ncols);
        match (self, &symbolic.chol) {
            (Numeric::Lu(num), _) => solve_lu(symbolic, num, rhs, parallelism()),
            (chol, Some(sym)) => solve_chol(sym, chol, rhs, cholesky_parallelism(sym)),
            (_, None) => Err(SolveError::NotFactorized),
        }
    }
}

/// Solve in place with the Cholesky-family factors (LLᵀ or LBLᵀ).
fn solve_chol(
    sym: &SymbolicCholesky<Index>,
    num: &Numeric,
    rhs: MatMut<f64>,
    par: Par,
) -> Result<(), SolveError> {
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
    symbolic: &Symbolic,
    num: &NumericLu<Index, f64>,
    rhs: MatMut<f64>,
    par: Par,
) -> Result<(), SolveError> {
    let sym = symbolic.lu.as_ref().ok_or(SolveError::NotFactorized)?;
    let mut mem = buffer(sym.solve_in_place_scratch::<f64>(rhs.ncols(), par))?;
    LuRef::new_unchecked(sym, num).solve_in_place_with_conj(
        Conj::No,
        rhs,
        par,
        MemStack::new(&mut mem),
    );
    Ok(())
}
