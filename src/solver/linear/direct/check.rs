//! The probe check of every numeric factorization: one solve `K y = K v` for a
//! fixed `v`, so that a singular or unstably factored matrix gives an error
//! instead of a garbage solution.

use super::csc::spmv;
use super::error::SolveError;
use super::numeric::Numeric;
use super::symbolic::Symbolic;
use crate::solver::linear::Index;
use faer::sparse::SparseColMatRef;

/// Largest accepted normwise backward error `‖K y − b‖ / (‖|K||y|‖ + ‖b‖)` of the probe solve.
pub const CHECK_BACKWARD_TOL: f64 = 1e-10;
/// Largest accepted relative forward error `‖y − v‖∞ / ‖v‖∞` of the probe solve `K y = K v`;
/// beyond it the matrix is treated as numerically singular (condition number ≳ 1e13).
pub const CHECK_FORWARD_TOL: f64 = 1e-3;

/// The probe solve with the factors `numeric` of `symbolic`: solve `K y = K v`
/// for a fixed `v`; reject non-finite results, a large backward error
/// (unstable) or a large forward error (singular). With `b`, `K x = b` is
/// solved in the same pass and x returned.
pub(super) fn probe(
    numeric: &Numeric,
    symbolic: &Symbolic,
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
    numeric.solve_columns(symbolic, &mut columns, n, 1 + usize::from(b.is_some()))?;
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

/// Deterministic probe vector entry in [0.5, 1.5), not aligned with grid structure.
fn probe_entry(i: usize) -> f64 {
    0.5 + ((i as u64).wrapping_mul(2_654_435_761) % 1_000_003) as f64 / 1_000_003.0
}

/// `max_i |a_i|`.
fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, t| m.max(t.abs()))
}

/// `max_i |a_i − b_i|`.
fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (s, t)| m.max((s - t).abs()))
}
