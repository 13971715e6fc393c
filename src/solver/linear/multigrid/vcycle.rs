//! The V-cycle preconditioner over a hierarchy of transfers: the Galerkin
//! operators of every level, a smoother on each but the coarsest, and the
//! sparse direct solver on the coarsest (its diagonal shifted when singular).

use super::csr::Csr;
use super::operator::{Fine, Operator};
use super::smoother::{chebyshev, Smoother};
use crate::solver::linear::direct::{DirectSolver, Ordering, Structure};
use crate::solver::linear::iterative::Preconditioner;
use faer::sparse::SparseColMatRef;

/// The diagonal shift of a singular coarsest operator, relative to its mean
/// diagonal entry (module doc).
pub const COARSE_SHIFT: f64 = 1e-8;

/// The transfer from one level to the next coarser one, fixed while the active
/// nodes are.
#[derive(Clone, Debug)]
pub struct Transfer {
    /// P: rows are the unknowns of the finer level, columns those of the coarser.
    pub prolongation: Csr,
    /// The unknowns of each node of the finer level (the smoother's blocks).
    pub fine_blocks: Vec<Vec<usize>>,
}

/// The V-cycle preconditioner; build it once per hierarchy ([`Multigrid::new`]),
/// refresh it with each new fine operator ([`Multigrid::refresh`]).
pub struct Multigrid {
    transfers: Vec<Transfer>,
    /// Pᵀ of every transfer.
    restrictions: Vec<Csr>,
    /// The operator of every level in use, finest first (the last one factorized).
    operators: Vec<Operator>,
    smoothers: Vec<Smoother>,
    coarse: DirectSolver,
}

/// Sizes of a refreshed hierarchy, for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// Unknowns of every level, finest first.
    pub unknowns: Vec<usize>,
    /// Stored entries of every level's operator (both triangles).
    pub entries: Vec<usize>,
    /// The coarsest operator's diagonal shift relative to its mean diagonal (0
    /// unless it was singular).
    pub coarse_shift: f64,
}

impl Multigrid {
    /// A hierarchy of the given transfers (finest first).
    pub fn new(transfers: Vec<Transfer>) -> Multigrid {
        Multigrid {
            restrictions: transfers
                .iter()
                .map(|t| t.prolongation.transpose())
                .collect(),
            transfers,
            operators: Vec::new(),
            smoothers: Vec::new(),
            coarse: DirectSolver::new(),
        }
    }

    /// Galerkin operators, smoothers and the coarse factorization for the fine
    /// operator `a` (both triangles); `symmetric` selects LLᵀ/LBLᵀ or LU on the
    /// coarsest level. The coarse symbolic factorization is kept while its
    /// pattern is unchanged (`DirectSolver`). If the coarsest operator cannot be
    /// factorized (a coarse space that lost its rank at a ragged boundary), the
    /// next finer level becomes the coarsest.
    pub fn refresh(&mut self, a: impl Into<Fine>, symmetric: bool) -> Result<Shape, String> {
        // On an error no operator is kept.
        self.release();
        let mut operators = vec![Operator::fine(a.into())?];
        for (t, r) in self.transfers.iter().zip(&self.restrictions) {
            let coarse = (operators.last().unwrap()).galerkin(r, &t.prolongation)?;
            operators.push(Operator::Rows(coarse));
        }
        // Once the products are formed no level is read by rows again: a
        // symmetric coarse level keeps its lower triangle only.
        if symmetric {
            operators[1..]
                .iter_mut()
                .for_each(Operator::keep_lower_triangle);
        }
        let mut used = self.transfers.len();
        let shift = loop {
            let a = &operators[used];
            let factorized =
                (self.factorize_coarse(a, symmetric, 0.0).map(|_| 0.0)).or_else(|_| {
                    self.factorize_coarse(a, symmetric, COARSE_SHIFT)
                        .map(|_| COARSE_SHIFT)
                });
            match factorized {
                Ok(shift) => break shift,
                Err(e) if used == 0 => return Err(format!("coarse factorization failed: {e}")),
                Err(_) => used -= 1,
            }
        };
        let shape = Shape {
            unknowns: operators[..=used].iter().map(|a| a.rows()).collect(),
            entries: operators[..=used].iter().map(|a| a.nnz()).collect(),
            coarse_shift: shift,
        };
        operators.truncate(used + 1);
        self.smoothers = operators[..used]
            .iter()
            .zip(&self.transfers)
            .map(|(a, t)| Smoother::new(a, &t.fine_blocks))
            .collect();
        self.operators = operators;
        Ok(shape)
    }

    /// Drop the operators and smoothers of the last refresh (the hierarchy
    /// stays): call it before assembling the next fine operator, so that the old
    /// and the new ones are never held together.
    pub fn release(&mut self) {
        self.operators = Vec::new();
        self.smoothers = Vec::new();
    }

    /// Factorize `a` as the coarsest operator, its diagonal raised by `shift`
    /// times the mean |a_ii|.
    fn factorize_coarse(
        &mut self,
        a: &Operator,
        symmetric: bool,
        shift: f64,
    ) -> Result<(), String> {
        let (pattern, mut values) = a.to_csc(symmetric);
        if shift > 0.0 {
            let (col_ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
            let diagonal: Vec<usize> = (0..a.rows())
                .filter_map(|j| {
                    (col_ptr[j] as usize..col_ptr[j + 1] as usize).find(|&k| rows[k] as usize == j)
                })
                .collect();
            let mean = diagonal.iter().map(|&k| values[k].abs()).sum::<f64>() / a.rows() as f64;
            for k in diagonal {
                values[k] += shift * mean * values[k].signum();
            }
        }
        let matrix = SparseColMatRef::new(pattern.as_ref(), &values);
        self.coarse
            .factorize(matrix, Structure::of(symmetric), Ordering::Amd)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    /// Levels of the hierarchy (with the coarsest), whether or not in use.
    pub fn built_levels(&self) -> usize {
        self.transfers.len() + 1
    }

    /// Levels in use (with the coarsest).
    #[cfg(test)]
    pub fn depth(&self) -> usize {
        self.operators.len()
    }

    /// The fine operator of the last refresh.
    pub fn fine_operator(&self) -> &Operator {
        &self.operators[0]
    }

    /// x = V-cycle(b) from level l on.
    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64]) {
        if l == self.smoothers.len() {
            match self.coarse.solve(b) {
                Ok(y) => x.copy_from_slice(&y),
                Err(_) => x.copy_from_slice(b),
            }
            return;
        }
        let (a, smoother) = (&self.operators[l], &self.smoothers[l]);
        let (p, restriction) = (&self.transfers[l].prolongation, &self.restrictions[l]);
        x.iter_mut().for_each(|v| *v = 0.0);
        chebyshev(a, smoother, b, x);
        // r = b − A x, restricted.
        let mut r = vec![0.0; b.len()];
        a.apply(x, &mut r);
        r.iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
        let mut rc = vec![0.0; p.cols];
        restriction.apply(&r, &mut rc);
        let mut xc = vec![0.0; p.cols];
        self.cycle(l + 1, &rc, &mut xc);
        p.apply(&xc, &mut r);
        x.iter_mut().zip(&r).for_each(|(xi, ci)| *xi += ci);
        chebyshev(a, smoother, b, x);
    }
}

impl Preconditioner for Multigrid {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        self.cycle(0, r, z);
    }
}
