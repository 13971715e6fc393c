//! The fill-reducing ordering of a symmetric factorization: faer's minimum
//! degree on the scalar matrix, or a given permutation (the node orderings
//! of `solver::linear::ordering`).

use crate::solver::linear::Index;

/// The fill-reducing ordering of the symbolic Cholesky factorization.
#[derive(Clone, Copy, Debug)]
pub enum Ordering<'a> {
    /// faer's approximate minimum degree on the scalar matrix.
    Amd,
    /// A permutation of the unknowns (`perm[new] = old`), e.g. from
    /// `solver::linear::ordering`.
    Given(&'a [usize]),
}

/// The inverse of a permutation.
pub(super) fn inverse(perm: &[usize]) -> Vec<Index> {
    let mut inv = vec![0; perm.len()];
    for (new, &old) in perm.iter().enumerate() {
        inv[old] = new as Index;
    }
    inv
}
