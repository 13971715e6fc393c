//! The operator of one level of the hierarchy, and the fine operator as
//! handed to the multigrid.

use super::csr::Csr;
use super::galerkin::galerkin;
use super::lower::{LowerRows, LowerSymmetric};
use crate::solver::linear::node_pattern::NodeLists;
use crate::solver::linear::Index;
use faer::sparse::SymbolicSparseColMat;
use rayon::prelude::*;
use std::sync::Arc;

/// The fine operator handed to [`Multigrid::refresh`]: a matrix in compressed
/// rows, or a symmetric tangent as assembled, by the column pointers of the
/// lower triangle of its shared pattern (rows ≥ column, ascending), its values
/// and the node graph the pattern was built from (its rows follow from it,
/// `node_pattern`).
#[derive(Debug)]
pub enum Fine {
    Rows(Csr),
    Lower(Arc<[Index]>, Vec<f64>, Arc<NodeLists>),
}

impl From<Csr> for Fine {
    fn from(a: Csr) -> Self {
        Fine::Rows(a)
    }
}

/// The operator of one level: a matrix in compressed rows (the coarse levels,
/// unsymmetric fine tangents), or a symmetric fine tangent as assembled
/// ([`LowerSymmetric`]).
#[derive(Debug)]
pub enum Operator {
    Rows(Csr),
    Lower(LowerSymmetric),
}

impl Operator {
    /// The fine operator of `a`; a lower triangle only if the node graph
    /// describes it (checked by the number of entries: the pattern is built
    /// from the graph, `Pattern::col_ptr`, so a mismatch is a wrong graph).
    pub(super) fn fine(a: Fine) -> Result<Operator, String> {
        let (col_ptr, values, graph) = match a {
            Fine::Rows(a) => return Ok(Operator::Rows(a)),
            Fine::Lower(col_ptr, values, graph) => (col_ptr, values, graph),
        };
        let n = col_ptr.len() - 1;
        let unknowns = |b: usize| graph.columns(b).len();
        let entries: usize = (0..graph.nodes())
            .into_par_iter()
            .map(|b| {
                (graph.lower_neighbours(b).iter().map(|&c| c as usize))
                    .map(|c| match c == b {
                        true => unknowns(b) * (unknowns(b) + 1) / 2,
                        false => unknowns(b) * unknowns(c),
                    })
                    .sum::<usize>()
            })
            .sum();
        let described =
            graph.unknowns() == n && col_ptr[n] as usize == values.len() && entries == values.len();
        if !described {
            return Err(format!(
                "the node graph ({} unknowns) does not describe the tangent's pattern ({n} \
                 unknowns, {} entries)",
                graph.unknowns(),
                values.len()
            ));
        }
        Ok(Operator::Lower(LowerSymmetric::on_nodes(
            col_ptr, values, graph,
        )))
    }

    pub fn rows(&self) -> usize {
        match self {
            Operator::Rows(a) => a.rows,
            Operator::Lower(a) => a.rows(),
        }
    }

    /// Stored entries, both triangles.
    pub fn nnz(&self) -> usize {
        match self {
            Operator::Rows(a) => a.nnz(),
            Operator::Lower(a) => a.nnz(),
        }
    }

    /// y = A x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        match self {
            Operator::Rows(a) => a.apply(x, y),
            Operator::Lower(a) => a.apply(x, y),
        }
    }

    pub(super) fn block_values(&self, block: &[usize]) -> Vec<f64> {
        match self {
            Operator::Rows(a) => a.block_values(block),
            Operator::Lower(a) => a.block_values(block),
        }
    }

    /// Pᵀ A P (R = Pᵀ); a lower triangle is read by rows through its node
    /// graph ([`LowerRows`]).
    pub(super) fn galerkin(&self, r: &Csr, p: &Csr) -> Result<Csr, String> {
        match self {
            Operator::Rows(a) => Ok(galerkin(r, a, p)),
            Operator::Lower(a) => Ok(galerkin(r, &LowerRows::new(a)?, p)),
        }
    }

    /// A symmetric operator in compressed rows kept as its lower triangle
    /// ([`Csr::into_lower_symmetric`]).
    pub(super) fn keep_lower_triangle(&mut self) {
        if let Operator::Rows(a) = self {
            *self = Operator::Lower(std::mem::take(a).into_lower_symmetric());
        }
    }

    /// The lower triangle (or the whole matrix) in compressed columns.
    pub(super) fn to_csc(&self, symmetric: bool) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
        match self {
            Operator::Rows(a) => a.to_csc(symmetric),
            Operator::Lower(a) => a.to_csc(),
        }
    }
}
