//! Preconditioners for the Krylov solvers: point Jacobi, block Jacobi (one small
//! dense block per node), and a direct factorization of a matrix that may be
//! older than the operator (a lagged tangent).

use super::direct::DirectSolver;
use super::iterative::Preconditioner;
use nalgebra::DMatrix;

/// M = diag(d). Non-positive or non-finite entries are replaced by the mean of
/// the positive ones, so M stays SPD (CG needs that) and the scaling stays sane.
#[derive(Clone, Debug)]
pub struct Jacobi {
    inverse: Vec<f64>,
}

impl Jacobi {
    pub fn new(diagonal: Vec<f64>) -> Jacobi {
        let positive: Vec<f64> = diagonal
            .iter()
            .copied()
            .filter(|d| *d > 0.0 && d.is_finite())
            .collect();
        let fallback = if positive.is_empty() {
            1.0
        } else {
            positive.iter().sum::<f64>() / positive.len() as f64
        };
        let inverse = diagonal
            .iter()
            .map(|&d| {
                if d > 0.0 && d.is_finite() {
                    1.0 / d
                } else {
                    1.0 / fallback
                }
            })
            .collect();
        Jacobi { inverse }
    }
}

impl Preconditioner for Jacobi {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        for ((zi, ri), di) in z.iter_mut().zip(r).zip(&self.inverse) {
            *zi = ri * di;
        }
    }
}

/// M = blockdiag(B_1, …, B_k): each block couples a few unknowns (the free
/// components of one node). A block that cannot be inverted falls back to the
/// inverse of its diagonal.
#[derive(Clone, Debug, Default)]
pub struct BlockJacobi {
    /// Unknowns of each block, concatenated; block b owns index[start[b]..start[b+1]].
    index: Vec<usize>,
    start: Vec<usize>,
    /// Row-major inverses, concatenated (size² entries per block).
    inverse: Vec<f64>,
}

impl BlockJacobi {
    /// Blocks as (unknowns, row-major values) pairs; the unknowns of different
    /// blocks must not overlap.
    pub fn new<'a>(blocks: impl Iterator<Item = (&'a [usize], &'a [f64])>) -> BlockJacobi {
        let mut out = BlockJacobi {
            start: vec![0],
            ..Default::default()
        };
        for (unknowns, values) in blocks {
            let k = unknowns.len();
            if k == 0 {
                continue;
            }
            let block = DMatrix::from_row_slice(k, k, values);
            let usable = |m: &DMatrix<f64>| m.iter().all(|v| v.is_finite());
            let inv = block
                .clone()
                .try_inverse()
                .filter(usable)
                .unwrap_or_else(|| {
                    let mut d = DMatrix::<f64>::zeros(k, k);
                    for i in 0..k {
                        let v = block[(i, i)];
                        d[(i, i)] = if v != 0.0 && v.is_finite() {
                            1.0 / v
                        } else {
                            1.0
                        };
                    }
                    d
                });
            out.index.extend_from_slice(unknowns);
            out.start.push(out.index.len());
            for i in 0..k {
                for j in 0..k {
                    out.inverse.push(inv[(i, j)]);
                }
            }
        }
        out
    }
}

impl Preconditioner for BlockJacobi {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
        let mut offset = 0;
        for b in 0..self.start.len() - 1 {
            let idx = &self.index[self.start[b]..self.start[b + 1]];
            let k = idx.len();
            let inv = &self.inverse[offset..offset + k * k];
            for (i, &row) in idx.iter().enumerate() {
                z[row] = (0..k).map(|j| inv[i * k + j] * r[idx[j]]).sum();
            }
            offset += k * k;
        }
    }
}

/// M = K_lagged, applied through its sparse factorization.
pub struct Factorized<'a>(pub &'a DirectSolver);

impl Preconditioner for Factorized<'_> {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        match self.0.solve(r) {
            Ok(x) => z.copy_from_slice(&x),
            // Only reachable if the caller hands over an unfactorized solver; an
            // identity step keeps the Krylov solve defined.
            Err(_) => z.copy_from_slice(r),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_jacobi_inverts_its_blocks_and_leaves_the_rest() {
        // Two 2×2 blocks on unknowns {0, 2} and {1, 3}; unknown 4 untouched.
        let b0 = [4.0, 1.0, 2.0, 3.0];
        let b1 = [2.0, -1.0, -1.0, 2.0];
        let blocks = [(&[0usize, 2][..], &b0[..]), (&[1usize, 3][..], &b1[..])];
        let m = BlockJacobi::new(blocks.into_iter());
        let r = [1.0, 2.0, 3.0, 4.0, 5.0];
        let mut z = [0.0; 5];
        m.apply(&r, &mut z);
        // B0 (z0, z2) = (1, 3); B1 (z1, z3) = (2, 4).
        assert!((4.0 * z[0] + z[2] - 1.0).abs() < 1e-14);
        assert!((2.0 * z[0] + 3.0 * z[2] - 3.0).abs() < 1e-14);
        assert!((2.0 * z[1] - z[3] - 2.0).abs() < 1e-14);
        assert!((-z[1] + 2.0 * z[3] - 4.0).abs() < 1e-14);
        assert_eq!(z[4], 5.0);
        // A singular block falls back to its diagonal.
        let s = [1.0, 1.0, 1.0, 1.0];
        let m = BlockJacobi::new([(&[0usize, 1][..], &s[..])].into_iter());
        m.apply(&[2.0, 3.0], &mut z[..2]);
        assert_eq!(&z[..2], &[2.0, 3.0]);
    }

    #[test]
    fn jacobi_replaces_non_positive_entries() {
        let m = Jacobi::new(vec![2.0, 0.0, 4.0, f64::NAN]);
        let mut z = [0.0; 4];
        m.apply(&[2.0, 3.0, 4.0, 3.0], &mut z);
        assert_eq!(z, [1.0, 1.0, 1.0, 1.0]);
    }
}
