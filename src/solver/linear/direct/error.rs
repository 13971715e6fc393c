//! The direct solver's errors, and faer's mapped onto them.

use faer::dyn_stack::{MemBuffer, StackReq};
use faer::sparse::linalg::LuError;
use faer::sparse::CreationError;

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

/// Allocate a faer workspace.
pub(super) fn buffer(req: StackReq) -> Result<MemBuffer, SolveError> {
    MemBuffer::try_new(req).map_err(|_| SolveError::Backend("out of memory for workspace".into()))
}

/// Map a faer error that is not about the matrix values.
pub(super) fn backend<E: std::fmt::Debug>(e: E) -> SolveError {
    SolveError::Backend(format!("{e:?}"))
}

/// Map a triplet-conversion error.
pub(super) fn creation_error(e: CreationError) -> SolveError {
    match e {
        CreationError::OutOfBounds { row, col } => {
            SolveError::InvalidInput(format!("triplet index ({row}, {col}) out of bounds"))
        }
        CreationError::Generic(e) => backend(e),
    }
}

/// Map a sparse LU error.
pub(super) fn lu_error(e: LuError) -> SolveError {
    match e {
        LuError::SymbolicSingular { index } => {
            SolveError::Singular(format!("LU: structurally singular at step {index}"))
        }
        LuError::Generic(e) => backend(e),
    }
}
