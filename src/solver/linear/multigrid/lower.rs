//! A symmetric matrix kept as its lower triangle in compressed columns
//! ([`LowerSymmetric`]), and read by rows through the node graph
//! ([`LowerRows`]).

use super::csr::{Csr, ROWS_PER_TASK};
use super::galerkin::Rows;
use crate::solver::linear::node_pattern::NodeLists;
use crate::solver::linear::Index;
use faer::sparse::SymbolicSparseColMat;
use rayon::prelude::*;
use std::sync::Arc;

/// A symmetric matrix kept as the direct solver keeps it, its lower triangle
/// in compressed columns: the coarse levels with their row indices, the fine
/// tangent with the column pointers of the step's pattern and the node graph
/// that gives its rows ([`RowIndex`]).
///
/// The first Galerkin product reads it by rows ([`LowerRows`]); the
/// smoother's blocks are read from the columns, and products y = A x go over
/// the stored triangle once (below), reading less memory than the whole
/// matrix.
#[derive(Debug)]
pub struct LowerSymmetric {
    col_ptr: Arc<[Index]>,
    rows: RowIndex,
    pub(super) values: Vec<f64>,
}

/// Where the rows of a [`LowerSymmetric`] come from.
#[derive(Debug)]
enum RowIndex {
    /// Stored, one per entry (the coarse levels).
    Stored(Vec<Index>),
    /// The node graph of the fine tangent's pattern (rows ≥ the column of the
    /// unknowns of each neighbour node, `node_pattern`): 4 bytes per entry
    /// less, 20 MiB of the 2D 320² block's multigrid.
    Nodes(Arc<NodeLists>),
}

/// Columns per parallel task of [`LowerSymmetric::apply`]: fixed, so the sums
/// do not depend on the number of threads.
pub(super) const COLUMNS_PER_TASK: usize = 2048;

impl LowerSymmetric {
    /// The symmetric fine tangent of the column pointers `col_ptr` of its
    /// lower triangle and its `values`, its rows given by the node graph
    /// (`Operator::fine` checks that the graph describes the pattern).
    pub(super) fn on_nodes(
        col_ptr: Arc<[Index]>,
        values: Vec<f64>,
        graph: Arc<NodeLists>,
    ) -> LowerSymmetric {
        LowerSymmetric {
            col_ptr,
            rows: RowIndex::Nodes(graph),
            values,
        }
    }

    pub(super) fn rows(&self) -> usize {
        self.col_ptr.len() - 1
    }

    /// The positions of column j's entries.
    fn column(&self, j: usize) -> std::ops::Range<usize> {
        self.col_ptr[j] as usize..self.col_ptr[j + 1] as usize
    }

    /// f(k, i) for the entries of column j: position k, row i, ascending.
    fn for_each_in_column(&self, j: usize, f: impl FnMut(usize, usize)) {
        let from = self.row_nodes(j..j + 1).next().expect("a column");
        self.for_each_in_column_of(j, from, f)
    }

    /// `for_each_in_column` with the nodes of column j's rows given
    /// (`row_nodes`).
    pub(super) fn for_each_in_column_of(
        &self,
        j: usize,
        from: &[u32],
        mut f: impl FnMut(usize, usize),
    ) {
        match &self.rows {
            RowIndex::Stored(rows) => self.column(j).for_each(|k| f(k, rows[k] as usize)),
            RowIndex::Nodes(g) => g.for_each_in_column(&self.col_ptr, from, j, j, f),
        }
    }

    /// For each column of `cols` in turn, the nodes its rows come from: the
    /// neighbours of the column's node from itself on (found once per node);
    /// none when the rows are stored.
    fn row_nodes(&self, cols: std::ops::Range<usize>) -> impl Iterator<Item = &[u32]> + '_ {
        let graph = match &self.rows {
            RowIndex::Nodes(g) if !cols.is_empty() => Some(&**g),
            _ => None,
        };
        let mut node = graph.map_or(0, |g| g.node_of(cols.start));
        let mut from: &[u32] = graph.map_or(&[], |g| g.neighbours_from(node, cols.start));
        cols.map(move |j| {
            if let Some(g) = graph.filter(|g| g.first[node + 1] <= j) {
                while g.first[node + 1] <= j {
                    node += 1;
                }
                from = g.neighbours_from(node, j);
            }
            from
        })
    }

    /// The last row of column j (`from` as in `for_each_in_column_of`), if
    /// it has entries.
    fn last_row(&self, j: usize, from: &[u32]) -> Option<usize> {
        match &self.rows {
            RowIndex::Stored(rows) => rows[self.column(j)].last().map(|&r| r as usize),
            RowIndex::Nodes(g) => g.last_row(from, j),
        }
    }

    /// The position of entry (r, c), r ≥ c, if stored.
    fn position(&self, r: usize, c: usize) -> Option<usize> {
        match &self.rows {
            RowIndex::Stored(rows) => {
                let column = self.column(c);
                let at = rows[column.clone()].binary_search(&(r as Index)).ok()?;
                Some(column.start + at)
            }
            RowIndex::Nodes(g) => {
                g.position(&self.col_ptr, (g.node_of(r), r), (g.node_of(c), c), c)
            }
        }
    }

    /// Both triangles' stored entries.
    pub(super) fn nnz(&self) -> usize {
        let diagonal = (0..self.rows())
            .filter(|&j| self.position(j, j).is_some())
            .count();
        2 * self.values.len() - diagonal
    }

    /// y = A x = L x + Lᵀ x − D x over the stored triangle L. Chunks of
    /// columns in parallel: chunk c gathers (Lᵀ x)_j of its columns j (column j
    /// from the diagonal down, in row order) and scatters L_ij x_j, i > j, into
    /// its own buffer over the rows it reaches, in column order; row i then
    /// adds the buffers that reach it, chunk by chunk. Fixed chunks and orders:
    /// the same bits on any number of threads.
    pub(super) fn apply(&self, x: &[f64], y: &mut [f64]) {
        let values = &self.values;
        let scattered: Vec<(usize, Vec<f64>)> = y
            .par_chunks_mut(COLUMNS_PER_TASK)
            .enumerate()
            .map(|(c, y)| {
                let lo = c * COLUMNS_PER_TASK;
                let hi = lo + y.len();
                let reach = (lo..hi)
                    .zip(self.row_nodes(lo..hi))
                    .filter_map(|(j, from)| self.last_row(j, from))
                    .fold(lo, |m, r| m.max(r + 1));
                let mut buffer = vec![0.0; reach - lo];
                for ((j, from), yj) in (lo..hi).zip(self.row_nodes(lo..hi)).zip(y.iter_mut()) {
                    let mut sum = 0.0;
                    self.for_each_in_column_of(j, from, |k, i| {
                        let a = values[k];
                        sum += a * x[i];
                        if i > j {
                            buffer[i - lo] += a * x[j];
                        }
                    });
                    *yj = sum;
                }
                (lo, buffer)
            })
            .collect();
        // reach[c]: the end of the furthest buffer of chunks up to c (non-decreasing).
        let reach: Vec<usize> = (scattered.iter())
            .scan(0, |m, (lo, b)| {
                *m = (*m).max(lo + b.len());
                Some(*m)
            })
            .collect();
        y.par_iter_mut()
            .enumerate()
            .with_min_len(ROWS_PER_TASK)
            .for_each(|(i, yi)| {
                let (first, own) = (reach.partition_point(|&end| end <= i), i / COLUMNS_PER_TASK);
                for (lo, buffer) in scattered.get(first..=own).unwrap_or_default() {
                    if let Some(b) = buffer.get(i - lo) {
                        *yi += b;
                    }
                }
            });
    }

    /// The diagonal block over the unknowns `block` (row-major values), each
    /// entry (i, j) from column min(i, j) of the triangle.
    pub(super) fn block_values(&self, block: &[usize]) -> Vec<f64> {
        // A block of one node's unknowns, the node coupled to itself: column
        // c holds rows c.. of the node first.
        let own = match (&self.rows, block.first()) {
            (RowIndex::Nodes(g), Some(&u)) => {
                let b = g.node_of(u);
                g.self_coupled(b) && block.iter().all(|u| g.columns(b).contains(u))
            }
            _ => false,
        };
        let entry = |i: usize, j: usize| {
            let (r, c) = (i.max(j), i.min(j));
            let at = match own {
                true => Some(self.col_ptr[c] as usize + r - c),
                false => self.position(r, c),
            };
            at.map_or(0.0, |k| self.values[k])
        };
        (block.iter())
            .flat_map(|&i| block.iter().map(move |&j| entry(i, j)))
            .collect()
    }

    /// The triangle in compressed columns with its row indices, for the
    /// direct solver.
    pub(super) fn to_csc(&self) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
        let rows = match &self.rows {
            RowIndex::Stored(rows) => rows.clone(),
            RowIndex::Nodes(_) => {
                let mut rows = vec![0; self.values.len()];
                for j in 0..self.rows() {
                    self.for_each_in_column(j, |k, i| rows[k] = i as Index);
                }
                rows
            }
        };
        let n = self.rows();
        let pattern = SymbolicSparseColMat::new_checked(n, n, self.col_ptr.to_vec(), None, rows);
        (pattern, self.values.clone())
    }
}

/// The rows of the symmetric fine tangent stored as its lower triangle, found
/// through the node graph its pattern was built from (unknowns numbered node
/// by node, node a coupling all its unknowns to all those of its neighbours):
/// row i of node a is (i, j) for the unknowns j < i of a's neighbours b ≤ a,
/// found once in b's first column, then column i from its diagonal down.
/// These are the entries, values and order of row i of the whole matrix in
/// compressed rows, so the Galerkin operators are those of that matrix;
/// nothing is stored (a transposed pattern of the triangle, 8 bytes per
/// entry, was the 2D multigrid's largest own array).
pub struct LowerRows<'a> {
    a: &'a LowerSymmetric,
    graph: &'a NodeLists,
    /// Per node a, for each neighbour b ≤ a (the first entries of a's
    /// neighbour list): where a's rows start in b's first column, from its
    /// top (node a's are `down[down_start[a]..]`). Built once per product
    /// (4 bytes per such pair, dropped after it) instead of a search for every
    /// row each time the product reads it.
    down: Vec<u32>,
    down_start: Vec<usize>,
    /// Per node: whether it couples to itself (its own rows open its columns).
    own: Vec<bool>,
}

impl<'a> LowerRows<'a> {
    /// The rows of `a`, if its rows come from a node graph.
    pub fn new(a: &'a LowerSymmetric) -> Result<LowerRows<'a>, String> {
        let RowIndex::Nodes(graph) = &a.rows else {
            return Err("a lower triangle without its node graph".into());
        };
        let own: Vec<bool> = (0..graph.nodes())
            .into_par_iter()
            .map(|b| graph.self_coupled(b))
            .collect();
        let mut down_start = Vec::with_capacity(graph.nodes() + 1);
        down_start.push(0);
        for node in 0..graph.nodes() {
            down_start.push(down_start[node] + graph.lower_neighbours(node).len());
        }
        let down: Vec<u32> = (0..graph.nodes())
            .into_par_iter()
            .flat_map_iter(|node| {
                let i = graph.first[node];
                graph.lower_neighbours(node).iter().map(move |&b| {
                    let lo = graph.first[b as usize];
                    (graph.position(&a.col_ptr, (node, i), (b as usize, lo), lo))
                        .map_or(u32::MAX, |at| (at - a.col_ptr[lo] as usize) as u32)
                })
            })
            .collect();
        Ok(LowerRows {
            a,
            graph,
            down,
            down_start,
            own,
        })
    }
}

impl Rows for LowerRows<'_> {
    fn for_each_in_row(&self, i: usize, mut f: impl FnMut(u32, f64)) {
        let (g, values, col_ptr) = (self.graph, &self.a.values, &self.a.col_ptr);
        let node = g.node_of(i);
        let shift = i - g.first[node];
        for (t, &b) in g.lower_neighbours(node).iter().enumerate() {
            let b = b as usize;
            let (lo, hi) = (g.first[b], g.first[b + 1].min(i));
            let down = self.down[self.down_start[node] + t];
            if lo == hi || down == u32::MAX {
                continue;
            }
            // Column lo holds b's own unknowns from lo on (if b couples to
            // itself), then those of b's neighbours after b: row i sits
            // `down + shift` entries from its top, and one entry higher in
            // each next column of b.
            let down = down as usize + shift;
            let own = usize::from(self.own[b]);
            for (t, j) in (lo..hi).enumerate() {
                let k = col_ptr[j] as usize + down - own * t;
                f(j as u32, values[k]);
            }
        }
        let from = g.neighbours_from(node, i);
        self.a
            .for_each_in_column_of(i, from, |k, r| f(r as u32, values[k]));
    }
}

impl Csr {
    /// The symmetric matrix of this one's upper triangle, kept as its lower
    /// triangle in compressed columns ([`LowerSymmetric`]): the entries j ≥ i
    /// of row i are the rows ≥ i of column i. Compacted in place and shrunk:
    /// half the entries. (The two triangles of a Galerkin operator of a
    /// symmetric matrix differ by round-off; the upper one is kept, as `to_csc`
    /// keeps it for the coarse factorization.)
    pub(super) fn into_lower_symmetric(mut self) -> LowerSymmetric {
        let n = self.rows;
        assert_eq!(n, self.cols, "a symmetric matrix is square");
        let mut col_ptr: Vec<Index> = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut at = 0;
        for i in 0..n {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                if self.col[k] as usize >= i {
                    (self.col[at], self.val[at]) = (self.col[k], self.val[k]);
                    at += 1;
                }
            }
            col_ptr.push(at as Index);
        }
        self.col.truncate(at);
        self.col.shrink_to_fit();
        self.val.truncate(at);
        self.val.shrink_to_fit();
        LowerSymmetric {
            col_ptr: col_ptr.into(),
            rows: RowIndex::Stored(self.col),
            values: self.val,
        }
    }
}
