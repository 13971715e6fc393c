//! Sparse matrices in compressed columns as the solver takes them: products,
//! the check of the entries, triplets, the mirrored lower triangle.

use super::error::{creation_error, SolveError};
use super::symbolic::Structure;
use crate::solver::linear::Index;
use faer::sparse::{SparseColMat, SparseColMatRef, Triplet};

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

/// Non-finite values, and entries above the diagonal of a `Symmetric` matrix, are
/// invalid input.
pub(super) fn check_entries(
    a: SparseColMatRef<Index, f64>,
    structure: Structure,
) -> Result<(), SolveError> {
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
pub(super) fn csc_from_triplets(
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
pub(super) fn mirror_lower(
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
