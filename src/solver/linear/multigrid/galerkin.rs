//! The Galerkin products A_{l+1} = P_lᵀ A_l P_l of the coarse operators
//! (Trottenberg, Oosterlee & Schüller 2001, §A.2.4), over any operator read
//! row by row ([`Rows`]).

use super::csr::{Csr, ROWS_PER_TASK};
use rayon::prelude::*;

/// A square matrix read row by row, each row's columns ascending: what the
/// Galerkin triple product needs of an operator.
pub trait Rows: Sync {
    /// f(j, a_ij) for the stored entries of row i, j ascending.
    fn for_each_in_row(&self, i: usize, f: impl FnMut(u32, f64));
}

impl Rows for Csr {
    fn for_each_in_row(&self, i: usize, mut f: impl FnMut(u32, f64)) {
        let (c, v) = self.row(i);
        c.iter().zip(v).for_each(|(&j, &a)| f(j, a));
    }
}

/// A_c = R A P with R = Pᵀ (Galerkin): every coarse row i is Σ_k R_ik Σ_j A_kj P_j·,
/// summed in the fixed order of k, j and P's columns, into a dense accumulator;
/// the coarse row's pattern is every column reached (kept when a sum cancels,
/// so it depends only on the patterns).
pub fn galerkin(r: &Csr, a: &impl Rows, p: &Csr) -> Csr {
    let n = r.rows;
    let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (0..n.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .map_init(
            || (vec![0.0; p.cols], vec![false; p.cols], Vec::<u32>::new()),
            |(acc, seen, touched), chunk| {
                let rows = chunk * ROWS_PER_TASK..((chunk + 1) * ROWS_PER_TASK).min(n);
                let (mut len, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
                for i in rows {
                    touched.clear();
                    let (rc, rv) = r.row(i);
                    for (&k, &rik) in rc.iter().zip(rv) {
                        a.for_each_in_row(k as usize, |j, akj| {
                            let ra = rik * akj;
                            let (pc, pv) = p.row(j as usize);
                            for (&l, &pjl) in pc.iter().zip(pv) {
                                let l = l as usize;
                                if !seen[l] {
                                    seen[l] = true;
                                    touched.push(l as u32);
                                }
                                acc[l] += ra * pjl;
                            }
                        });
                    }
                    touched.sort_unstable();
                    for &l in touched.iter() {
                        cols.push(l);
                        vals.push(acc[l as usize]);
                        acc[l as usize] = 0.0;
                        seen[l as usize] = false;
                    }
                    len.push(touched.len());
                }
                (len, cols, vals)
            },
        )
        .collect();
    // Each chunk is freed once copied: the operator is not held twice.
    let nnz = chunks.iter().map(|c| c.1.len()).sum();
    let mut out = Csr {
        rows: n,
        cols: p.cols,
        row_ptr: Vec::with_capacity(n + 1),
        col: Vec::with_capacity(nnz),
        val: Vec::with_capacity(nnz),
    };
    out.row_ptr.push(0);
    for (len, cols, vals) in chunks {
        for l in len {
            out.row_ptr.push(out.row_ptr.last().unwrap() + l);
        }
        out.col.extend(cols);
        out.val.extend(vals);
    }
    out
}
