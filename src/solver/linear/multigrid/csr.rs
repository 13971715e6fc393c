//! A sparse matrix in compressed rows: the coarse operators, the
//! prolongations and restrictions, an unsymmetric fine tangent.

use crate::solver::linear::Index;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use rayon::prelude::*;

/// Rows per parallel task.
pub(super) const ROWS_PER_TASK: usize = 256;

/// A sparse matrix in compressed rows, columns ascending within each row.
#[derive(Clone, Debug, Default)]
pub struct Csr {
    pub rows: usize,
    pub cols: usize,
    pub row_ptr: Vec<usize>,
    pub col: Vec<u32>,
    pub val: Vec<f64>,
}

impl Csr {
    /// The matrix of a compressed-column one (every entry stored): its
    /// transpose's pattern, read as rows, is its own.
    pub fn from_csc(a: SparseColMatRef<Index, f64>) -> Csr {
        let (n, m) = (a.nrows(), a.ncols());
        let t = Transposed::of(a.col_ptr(), |k| a.row_idx()[k] as usize, n);
        Csr {
            rows: n,
            cols: m,
            row_ptr: t.row_ptr,
            col: t.col,
            val: t.pos.iter().map(|&k| a.val()[k as usize]).collect(),
        }
    }

    pub fn nnz(&self) -> usize {
        self.col.len()
    }

    pub(super) fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        (&self.col[r.clone()], &self.val[r])
    }

    /// y = A x, rows in parallel (each row summed in column order).
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(ROWS_PER_TASK)
            .for_each(|(i, yi)| {
                let (c, v) = self.row(i);
                *yi = c.iter().zip(v).map(|(&j, a)| a * x[j as usize]).sum();
            });
    }

    /// Aᵀ as a matrix of its own.
    pub fn transpose(&self) -> Csr {
        let t = Transposed::of(&self.row_ptr, |k| self.col[k] as usize, self.cols);
        Csr {
            rows: self.cols,
            cols: self.rows,
            row_ptr: t.row_ptr,
            col: t.col,
            val: t.pos.iter().map(|&k| self.val[k as usize]).collect(),
        }
    }

    /// The diagonal blocks of the unknowns `block` (row-major values).
    pub(super) fn block_values(&self, block: &[usize]) -> Vec<f64> {
        let mut out = Vec::with_capacity(block.len() * block.len());
        for &i in block {
            let (c, v) = self.row(i);
            for &j in block {
                out.push(c.binary_search(&(j as u32)).map_or(0.0, |k| v[k]));
            }
        }
        out
    }

    /// The lower triangle (or the whole matrix) in compressed columns, for the
    /// direct solver. For a symmetric matrix the lower triangle's columns are
    /// the upper triangle's rows.
    pub(super) fn to_csc(&self, symmetric: bool) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
        let t = if symmetric {
            self.clone()
        } else {
            self.transpose()
        };
        // Rows of t are the columns of the matrix; keep rows ≥ column if symmetric.
        let mut col_ptr: Vec<Index> = vec![0];
        let (mut rows, mut vals): (Vec<Index>, Vec<f64>) = (Vec::new(), Vec::new());
        for j in 0..t.rows {
            let (c, v) = t.row(j);
            for (&i, &a) in c.iter().zip(v) {
                if !symmetric || i as usize >= j {
                    rows.push(i);
                    vals.push(a);
                }
            }
            col_ptr.push(rows.len() as Index);
        }
        let n = self.rows;
        (
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows),
            vals,
        )
    }
}

/// A transposed pattern with the positions of its entries in the original:
/// for each row i, the columns j ascending and where entry (i, j) is stored in
/// the compressed lines it came from: the transpose of a matrix in compressed
/// rows ([`Csr::transpose`]) or columns ([`Csr::from_csc`]).
#[derive(Debug)]
struct Transposed {
    row_ptr: Vec<usize>,
    col: Vec<u32>,
    pos: Vec<u32>,
}

impl Transposed {
    /// The transpose of the pattern of `lines` compressed lines (`ptr`, and
    /// `index(k)` < `n` the index within its line of entry k): counted, then
    /// filled in line order, so each row's columns come out ascending.
    /// (Sequential: a parallel version by chunks of rows measured slower on two
    /// cores, the pass being bound by memory.)
    fn of<I: faer::Index>(ptr: &[I], index: impl Fn(usize) -> usize, n: usize) -> Transposed {
        let lines = ptr.len() - 1;
        let ptr = |j: usize| ptr[j].zx();
        // Within the memory limit of any scene (48 GB of entries).
        assert!(ptr(lines) <= u32::MAX as usize, "positions beyond 32 bits");
        let mut row_ptr = vec![0usize; n + 1];
        for k in 0..ptr(lines) {
            row_ptr[index(k) + 1] += 1;
        }
        for i in 0..n {
            row_ptr[i + 1] += row_ptr[i];
        }
        let mut next = row_ptr.clone();
        let len = row_ptr[n];
        let (mut col, mut pos) = (vec![0u32; len], vec![0u32; len]);
        for j in 0..lines {
            for k in ptr(j)..ptr(j + 1) {
                let at = &mut next[index(k)];
                col[*at] = j as u32;
                pos[*at] = k as u32;
                *at += 1;
            }
        }
        Transposed { row_ptr, col, pos }
    }
}
