//! Multigrid V-cycle preconditioner over given prolongations: the algebra of the
//! geometric multigrid of the implicit solver (its prolongations come from the
//! background grid, `solver::implicit::coarsening`).
//!
//! With prolongations P_l from level l + 1 to level l (rows: unknowns of level l)
//! and the fine operator A_0, the coarse operators are Galerkin products
//!
//!   A_{l+1} = P_lᵀ A_l P_l                   (Trottenberg, Oosterlee & Schüller 2001, §A.2.4)
//!
//! and one application of the preconditioner is a V-cycle (ibid. §2.4): on each
//! level a Chebyshev smoother on the nodal block-Jacobi preconditioned operator
//! D_l⁻¹ A_l, the residual restricted by P_lᵀ, the coarse correction prolongated
//! by P_l, the same smoother again; on the coarsest level the sparse direct solver
//! (LLᵀ, else LBLᵀ, else LU). A singular coarsest operator is factorized with its
//! diagonal raised by [`COARSE_SHIFT`] of its mean: on a ragged active set two
//! coarse basis functions can coincide on the fine unknowns they reach, P z = 0,
//! so that A_c z = 0; the restricted residual Pᵀ r has no component along z and
//! the prolongated correction none either, so the shift leaves the V-cycle as it
//! would be with a pseudo-inverse. (The 2D Griffiths–Lane slope's 1,187-unknown
//! coarse level had two zero singular values already in the elastic first
//! iteration, where A is positive definite and Pᵀ A P z = 0 only if P z = 0.)
//! Pre- and post-smoother are the same polynomial in
//! D⁻¹A, so for symmetric A the V-cycle is a symmetric operator and CG stays
//! valid (ibid. §A.2.3).
//!
//! Chebyshev smoother (Adams, Brezina, Hu & Tuminaro 2003, J. Comput. Phys.
//! 188:593–610; the three-term recurrence of Saad 2003, Algorithm 12.1): degree
//! [`SMOOTHING_STEPS`] on the interval [λ/[`EIGEN_RATIO`], 1.1 λ] of D⁻¹A, λ its
//! largest eigenvalue estimated by [`ESTIMATE_STEPS`] Lanczos steps from a fixed
//! vector. It needs only products and block solves, so it is parallel without a
//! colouring and does not depend on the ordering of the unknowns.
//!
//! Why not a crate: the Rust crates with multigrid found on docs.rs
//! (scirs2-sparse: Ruge–Stüben, smoothed aggregation and AIR AMG on its own CSR
//! type in a large scientific stack; nalgebra-sparse-linalg 0.1: a small AMG
//! behind a feature) are algebraic: they choose their own coarse spaces, cannot
//! take the grid's exact two-scale prolongations with ties and Dirichlet
//! components, and do not keep a hierarchy while refreshing only values.
//!
//! A symmetric fine tangent is used where the assembly left it, as the lower
//! triangle of the step's pattern ([`LowerSymmetric`]): no copy of both
//! triangles (at 32³ cells in 3D that copy was 400 MiB beside a 134 MiB
//! triangle), and without its row indices: the rows of every column, and the
//! columns of every row ([`LowerRows`]), follow from the node graph the
//! pattern was built from (`node_pattern`). The coarse levels are formed in compressed rows; once
//! the Galerkin products are done, symmetric ones keep their lower triangle
//! ([`Csr::into_lower_symmetric`]).
//!
//! Every product is a row-parallel CSR product, or over the lower triangle by
//! fixed column chunks, and every sum runs in a fixed order, so the result is
//! the same bits on any number of threads.

use super::direct::{DirectSolver, Ordering, Structure};
use super::iterative::Preconditioner;
use super::node_pattern::NodeLists;
use super::preconditioner::BlockJacobi;
use super::Index;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use rayon::prelude::*;
use std::sync::Arc;

/// The diagonal shift of a singular coarsest operator, relative to its mean
/// diagonal entry (module doc).
pub const COARSE_SHIFT: f64 = 1e-8;

/// Degree of the Chebyshev polynomial of each pre- and post-smoothing.
pub const SMOOTHING_STEPS: usize = 2;
/// The smoother damps the eigenvalues of D⁻¹A in [λ_max / EIGEN_RATIO, λ_max].
pub const EIGEN_RATIO: f64 = 10.0;
/// Lanczos (CG) steps for λ_max(D⁻¹A).
pub const ESTIMATE_STEPS: usize = 10;
/// Rows per parallel task.
const ROWS_PER_TASK: usize = 256;

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

    fn row(&self, i: usize) -> (&[u32], &[f64]) {
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
    fn block_values(&self, block: &[usize]) -> Vec<f64> {
        let mut out = Vec::with_capacity(block.len() * block.len());
        for &i in block {
            let (c, v) = self.row(i);
            for &j in block {
                out.push(c.binary_search(&(j as u32)).map_or(0.0, |k| v[k]));
            }
        }
        out
    }

    /// The symmetric matrix of this one's upper triangle, kept as its lower
    /// triangle in compressed columns ([`LowerSymmetric`]): the entries j ≥ i
    /// of row i are the rows ≥ i of column i. Compacted in place and shrunk:
    /// half the entries. (The two triangles of a Galerkin operator of a
    /// symmetric matrix differ by round-off; the upper one is kept, as `to_csc`
    /// keeps it for the coarse factorization.)
    fn into_lower_symmetric(mut self) -> LowerSymmetric {
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

    /// The lower triangle (or the whole matrix) in compressed columns, for the
    /// direct solver. For a symmetric matrix the lower triangle's columns are
    /// the upper triangle's rows.
    fn to_csc(&self, symmetric: bool) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
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

/// A square matrix read row by row, each row's columns ascending: what the
/// Galerkin triple product needs of an operator.
pub trait Rows: Sync {
    fn rows(&self) -> usize;
    /// f(j, a_ij) for the stored entries of row i, j ascending.
    fn for_each_in_row(&self, i: usize, f: impl FnMut(u32, f64));
}

impl Rows for Csr {
    fn rows(&self) -> usize {
        self.rows
    }

    fn for_each_in_row(&self, i: usize, mut f: impl FnMut(u32, f64)) {
        let (c, v) = self.row(i);
        c.iter().zip(v).for_each(|(&j, &a)| f(j, a));
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
    values: Vec<f64>,
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
const COLUMNS_PER_TASK: usize = 2048;

impl LowerSymmetric {
    fn rows(&self) -> usize {
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
    fn for_each_in_column_of(&self, j: usize, from: &[u32], mut f: impl FnMut(usize, usize)) {
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
    fn nnz(&self) -> usize {
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
    fn apply(&self, x: &[f64], y: &mut [f64]) {
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
    fn block_values(&self, block: &[usize]) -> Vec<f64> {
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
    fn to_csc(&self) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
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
    fn rows(&self) -> usize {
        self.a.rows()
    }

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

    fn block_values(&self, block: &[usize]) -> Vec<f64> {
        match self {
            Operator::Rows(a) => a.block_values(block),
            Operator::Lower(a) => a.block_values(block),
        }
    }

    /// Pᵀ A P (R = Pᵀ); a lower triangle is read by rows through its node
    /// graph ([`LowerRows`]).
    fn galerkin(&self, r: &Csr, p: &Csr) -> Result<Csr, String> {
        match self {
            Operator::Rows(a) => Ok(galerkin(r, a, p)),
            Operator::Lower(a) => Ok(galerkin(r, &LowerRows::new(a)?, p)),
        }
    }

    /// A symmetric operator in compressed rows kept as its lower triangle
    /// ([`Csr::into_lower_symmetric`]).
    fn keep_lower_triangle(&mut self) {
        if let Operator::Rows(a) = self {
            *self = Operator::Lower(std::mem::take(a).into_lower_symmetric());
        }
    }

    /// The lower triangle (or the whole matrix) in compressed columns.
    fn to_csc(&self, symmetric: bool) -> (SymbolicSparseColMat<Index>, Vec<f64>) {
        match self {
            Operator::Rows(a) => a.to_csc(symmetric),
            Operator::Lower(a) => a.to_csc(),
        }
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

/// The transfer from one level to the next coarser one, fixed while the active
/// nodes are.
#[derive(Clone, Debug)]
pub struct Transfer {
    /// P: rows are the unknowns of the finer level, columns those of the coarser.
    pub prolongation: Csr,
    /// The unknowns of each node of the finer level (the smoother's blocks).
    pub fine_blocks: Vec<Vec<usize>>,
}

/// The smoother of one level above the coarsest: nodal block Jacobi D and the
/// estimated largest eigenvalue of D⁻¹A, times 1.1.
struct Smoother {
    blocks: BlockJacobi,
    lambda: f64,
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

    /// The fine operator of `a`; a lower triangle only if the node graph
    /// describes it (checked by the number of entries: the pattern is built
    /// from the graph, `Pattern::col_ptr`, so a mismatch is a wrong graph).
    fn fine(a: Fine) -> Result<Operator, String> {
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
        Ok(Operator::Lower(LowerSymmetric {
            col_ptr,
            rows: RowIndex::Nodes(graph),
            values,
        }))
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
        let mut operators = vec![Self::fine(a.into())?];
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
            .map(|(a, t)| {
                let values: Vec<Vec<f64>> =
                    t.fine_blocks.iter().map(|b| a.block_values(b)).collect();
                let blocks = BlockJacobi::new(
                    t.fine_blocks
                        .iter()
                        .zip(&values)
                        .map(|(u, v)| (u.as_slice(), v.as_slice())),
                );
                let lambda = 1.1 * largest_eigenvalue(a, &blocks);
                Smoother { blocks, lambda }
            })
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

/// λ_max(D⁻¹A) from ESTIMATE_STEPS steps of conjugate gradients preconditioned
/// by D on A x = b with a fixed b: the largest eigenvalue of the Lanczos
/// tridiagonal matrix that CG's coefficients define (Saad 2003, §6.7.3), a lower
/// bound that converges fast to the top of the spectrum.
fn largest_eigenvalue(a: &Operator, d: &BlockJacobi) -> f64 {
    let n = a.rows();
    if n == 0 {
        return 1.0;
    }
    let mut r: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * (i as f64).sin()).collect();
    let (mut z, mut q) = (vec![0.0; n], vec![0.0; n]);
    d.apply(&r, &mut z);
    let mut p = z.clone();
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let (mut diagonal, mut off) = (Vec::new(), Vec::new());
    let (mut alpha_prev, mut beta_prev) = (0.0, 0.0);
    for k in 0..ESTIMATE_STEPS {
        a.apply(&p, &mut q);
        let pq: f64 = p.iter().zip(&q).map(|(a, b)| a * b).sum();
        if !(pq > 0.0 && rz > 0.0) {
            break;
        }
        let alpha = rz / pq;
        // T_kk = 1/α_k + β_{k−1}/α_{k−1}, T_{k−1,k} = √β_{k−1}/α_{k−1}.
        diagonal.push(1.0 / alpha + if k > 0 { beta_prev / alpha_prev } else { 0.0 });
        if k > 0 {
            off.push(beta_prev.sqrt() / alpha_prev);
        }
        r.iter_mut().zip(&q).for_each(|(ri, qi)| *ri -= alpha * qi);
        d.apply(&r, &mut z);
        let rz_next: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_next / rz;
        p.iter_mut()
            .zip(&z)
            .for_each(|(pi, zi)| *pi = zi + beta * *pi);
        (alpha_prev, beta_prev, rz) = (alpha, beta, rz_next);
    }
    let m = diagonal.len();
    if m == 0 {
        return 1.0;
    }
    let t = nalgebra::DMatrix::<f64>::from_fn(m, m, |i, j| {
        if i == j {
            diagonal[i]
        } else if i + 1 == j {
            off[i]
        } else if j + 1 == i {
            off[j]
        } else {
            0.0
        }
    });
    t.symmetric_eigenvalues().max()
}

/// SMOOTHING_STEPS Chebyshev iterations for A x = b preconditioned by the
/// level's block Jacobi D, on [λ/EIGEN_RATIO, λ] (Saad 2003, Algorithm 12.1).
fn chebyshev(a: &Operator, smoother: &Smoother, b: &[f64], x: &mut [f64]) {
    let n = b.len();
    let upper = smoother.lambda;
    let lower = upper / EIGEN_RATIO;
    let theta = 0.5 * (upper + lower);
    let delta = 0.5 * (upper - lower);
    let sigma = theta / delta;
    let mut rho = 1.0 / sigma;
    let (mut r, mut z, mut d) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    a.apply(x, &mut r);
    r.iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
    smoother.blocks.apply(&r, &mut z);
    d.iter_mut().zip(&z).for_each(|(di, zi)| *di = zi / theta);
    for k in 0..SMOOTHING_STEPS {
        x.iter_mut().zip(&d).for_each(|(xi, di)| *xi += di);
        if k + 1 == SMOOTHING_STEPS {
            break;
        }
        a.apply(&d, &mut z);
        r.iter_mut().zip(&z).for_each(|(ri, adi)| *ri -= adi);
        smoother.blocks.apply(&r, &mut z);
        let rho_next = 1.0 / (2.0 * sigma - rho);
        d.iter_mut()
            .zip(&z)
            .for_each(|(di, zi)| *di = rho_next * rho * *di + 2.0 * rho_next / delta * zi);
        rho = rho_next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1D Laplacian tridiag(−1, 2, −1) of order n as CSR.
    fn laplacian(n: usize) -> Csr {
        let mut m = Csr {
            rows: n,
            cols: n,
            row_ptr: vec![0],
            ..Default::default()
        };
        for i in 0..n {
            if i > 0 {
                m.col.push(i as u32 - 1);
                m.val.push(-1.0);
            }
            m.col.push(i as u32);
            m.val.push(2.0);
            if i + 1 < n {
                m.col.push(i as u32 + 1);
                m.val.push(-1.0);
            }
            m.row_ptr.push(m.col.len());
        }
        m
    }

    #[test]
    fn galerkin_of_the_identity_prolongation_is_the_operator() {
        let a = laplacian(7);
        let p = Csr {
            rows: 7,
            cols: 7,
            row_ptr: (0..=7).collect(),
            col: (0..7).collect(),
            val: vec![1.0; 7],
        };
        let c = galerkin(&p.transpose(), &a, &p);
        assert_eq!(c.row_ptr, a.row_ptr);
        assert_eq!(c.col, a.col);
        assert_eq!(c.val, a.val);
    }

    #[test]
    fn transpose_twice_is_the_matrix() {
        let mut a = laplacian(5);
        a.val[1] = 3.0;
        let t = a.transpose();
        assert_eq!(t.val[2], 3.0);
        let tt = t.transpose();
        assert_eq!((tt.row_ptr, tt.col, tt.val), (a.row_ptr, a.col, a.val));
    }

    #[test]
    fn compressed_columns_read_as_rows_are_the_matrix() {
        // P's arrays read as compressed columns are Pᵀ; entry by entry
        // against P itself.
        let p = interpolation(23, false);
        let col_ptr: Vec<Index> = p.row_ptr.iter().map(|&k| k as Index).collect();
        let pattern =
            SymbolicSparseColMat::new_checked(p.cols, p.rows, col_ptr, None, p.col.clone());
        let t = Csr::from_csc(SparseColMatRef::new(pattern.as_ref(), &p.val));
        assert_eq!((t.rows, t.cols), (p.cols, p.rows));
        for i in 0..p.rows {
            let (c, v) = p.row(i);
            for (&j, &a) in c.iter().zip(v) {
                let (tc, tv) = t.row(j as usize);
                assert_eq!(
                    tc.binary_search(&(i as u32)).map(|k| tv[k]),
                    Ok(a),
                    "({i}, {j})"
                );
            }
        }
        assert_eq!(t.nnz(), p.nnz());
    }

    /// Linear interpolation from coarse node i (at fine node 2i + 1) to the
    /// fine nodes of a 1D grid of `n` = 2 n_c + 1 unknowns, with column
    /// `n_c − 1` given twice when `duplicate` (columns n_c − 1 and n_c equal).
    fn interpolation(n: usize, duplicate: bool) -> Csr {
        let nc = (n - 1) / 2;
        let mut p = Csr {
            rows: n,
            cols: nc + usize::from(duplicate),
            row_ptr: vec![0],
            ..Default::default()
        };
        for i in 0..n {
            let mut entries: Vec<(usize, f64)> = match i % 2 {
                1 => vec![(i / 2, 1.0)],
                _ => vec![(i / 2, 0.5), ((i / 2).wrapping_sub(1), 0.5)],
            };
            // An even n leaves the last unknown without a coarse parent.
            entries.retain(|&(c, _)| c < nc);
            if duplicate {
                if let Some(&(_, w)) = entries.iter().find(|e| e.0 == nc - 1) {
                    entries.push((nc, w));
                }
            }
            entries.sort_by_key(|e| e.0);
            for (c, w) in entries {
                p.col.push(c as u32);
                p.val.push(w);
            }
            p.row_ptr.push(p.col.len());
        }
        p
    }

    /// A symmetric matrix whose unknowns come in nodes (node a owns
    /// `first[a]..first[a + 1]`, and nodes a, b couple all their unknowns when
    /// `coupled(max(a, b), min(a, b))`): its lower triangle in compressed
    /// columns with the node graph, and the whole matrix in compressed rows
    /// built directly from the same rule (the reference).
    struct Nodal {
        col_ptr: Arc<[Index]>,
        /// The triangle's rows, written out by the rule (the reference).
        rows: Vec<Index>,
        vals: Vec<f64>,
        whole: Csr,
        lists: Arc<NodeLists>,
    }

    impl Nodal {
        fn new(first: Vec<usize>, coupled: impl Fn(usize, usize) -> bool) -> Nodal {
            let nodes = first.len() - 1;
            let n = first[nodes];
            let node_of = |i: usize| first.partition_point(|&u| u <= i) - 1;
            let entry = |i: usize, j: usize| {
                let (a, b) = (node_of(i), node_of(j));
                coupled(a.max(b), a.min(b)).then(|| match i == j {
                    true => 4.0 + j as f64,
                    false => -1.0 / (1 + i + j) as f64,
                })
            };
            let (mut col_ptr, mut rows, mut vals) = (vec![0 as Index], Vec::new(), Vec::new());
            for j in 0..n {
                for (i, v) in (j..n).filter_map(|i| entry(i, j).map(|v| (i, v))) {
                    rows.push(i as Index);
                    vals.push(v);
                }
                col_ptr.push(rows.len() as Index);
            }
            let mut whole = Csr {
                rows: n,
                cols: n,
                row_ptr: vec![0],
                ..Default::default()
            };
            for i in 0..n {
                for (j, v) in (0..n).filter_map(|j| entry(i, j).map(|v| (j, v))) {
                    whole.col.push(j as u32);
                    whole.val.push(v);
                }
                whole.row_ptr.push(whole.col.len());
            }
            let (mut start, mut adjacency) = (vec![0], Vec::new());
            for a in 0..nodes {
                adjacency.extend(
                    (0..nodes)
                        .filter(|&b| coupled(a.max(b), a.min(b)))
                        .map(|b| b as u32),
                );
                start.push(adjacency.len());
            }
            Nodal {
                col_ptr: col_ptr.into(),
                rows,
                vals,
                whole,
                lists: Arc::new(NodeLists {
                    start,
                    adjacency,
                    first,
                }),
            }
        }

        fn fine(&self) -> Fine {
            Fine::Lower(
                Arc::clone(&self.col_ptr),
                self.vals.clone(),
                Arc::clone(&self.lists),
            )
        }
    }

    /// A ragged pattern of order n, one unknown per node (some columns hold
    /// only their diagonal, some rows reach far).
    fn ragged(n: usize) -> Nodal {
        Nodal::new((0..=n).collect(), |i, j| {
            let coupled = i == j || (i - j < 10 && (i - j) % 3 == 1) || (j % 5 == 0 && i == n - 1);
            coupled && !(j % 7 == 3 && i > j)
        })
    }

    /// Nodes of 2 unknowns, some of 1 or none (eliminated components), each
    /// coupled to the nodes two either side of it and the first to the last.
    fn nodal(nodes: usize) -> Nodal {
        let mut first = vec![0];
        for a in 0..nodes {
            let own = match (a % 5, a % 7) {
                (_, 4) => 0,
                (2, _) => 1,
                _ => 2,
            };
            first.push(first[a] + own);
        }
        Nodal::new(first, |a, b| a - b <= 2 || (b == 0 && a == nodes - 1))
    }

    #[test]
    fn the_lower_triangle_read_by_rows_is_the_whole_matrix() {
        // Row for row, the same columns, values and order as the copy into
        // compressed rows, so the Galerkin operators are the same bits: on a
        // ragged pattern of single unknowns, and on nodes of 2, 1 and 0
        // unknowns.
        for (case, m) in [("ragged", ragged(23)), ("nodal", nodal(20))] {
            let lower = Multigrid::fine(m.fine()).unwrap();
            let (rows, n) = (&m.whole, m.whole.rows);
            assert_eq!(lower.nnz(), rows.nnz(), "{case}");
            let Operator::Lower(a) = &lower else {
                panic!("a symmetric tangent is read in place")
            };
            // The rows that the node graph gives are those of the rule.
            let (pattern, values) = a.to_csc();
            assert_eq!(
                (pattern.row_idx(), &values),
                (&m.rows[..], &m.vals),
                "{case}"
            );
            let by_rows = LowerRows::new(a).unwrap();
            for i in 0..n {
                let mut entries = Vec::new();
                by_rows.for_each_in_row(i, |j, v| entries.push((j, v)));
                let (c, v) = rows.row(i);
                let expected: Vec<(u32, f64)> = c.iter().copied().zip(v.iter().copied()).collect();
                assert_eq!(entries, expected, "{case}: row {i}");
            }
            for block in [vec![0, 1], vec![3, 4, 5], vec![n - 1, 9, 1], vec![7]] {
                assert_eq!(
                    lower.block_values(&block),
                    rows.block_values(&block),
                    "{case}"
                );
            }
            let p = interpolation(n, false);
            let (a, b) = (
                lower.galerkin(&p.transpose(), &p).unwrap(),
                galerkin(&p.transpose(), rows, &p),
            );
            assert_eq!(
                (a.row_ptr, a.col, a.val),
                (b.row_ptr, b.col, b.val),
                "{case}"
            );
            // A V-cycle differs from the one on the copy only by the order of
            // the products' sums.
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
            let blocks: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
            let cycle = |fine: Fine| {
                let transfer = Transfer {
                    prolongation: p.clone(),
                    fine_blocks: blocks.clone(),
                };
                let mut mg = Multigrid::new(vec![transfer]);
                mg.refresh(fine, true).unwrap();
                let mut z = vec![0.0; n];
                mg.apply(&x, &mut z);
                z
            };
            let (z, z_rows) = (cycle(m.fine()), cycle(Fine::Rows(rows.clone())));
            let scale = z_rows.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in z.iter().zip(&z_rows) {
                assert!(
                    (a - b).abs() <= 1e-13 * scale,
                    "{case}: V-cycle {a} against {b}"
                );
            }
        }
    }

    #[test]
    fn a_symmetric_coarse_level_keeps_its_lower_triangle() {
        // A Galerkin operator of the ragged symmetric matrix (a coarse level),
        // kept as its lower triangle: half the stored entries, the same
        // products (to the order of the sums), blocks and coarse
        // factorization input.
        let m = ragged(2 * COLUMNS_PER_TASK + 77);
        let p = interpolation(m.whole.rows, false);
        let coarse = galerkin(&p.transpose(), &m.whole, &p);
        let n = coarse.rows;
        let mut lower = Operator::Rows(coarse.clone());
        lower.keep_lower_triangle();
        let Operator::Lower(l) = &lower else {
            panic!("kept as a lower triangle")
        };
        let diagonal = (0..n)
            .filter(|&i| coarse.row(i).0.contains(&(i as u32)))
            .count();
        assert_eq!(l.values.len(), (coarse.nnz() + diagonal) / 2);
        assert_eq!(lower.nnz(), coarse.nnz());
        let x: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
        let (mut y, mut expected) = (vec![0.0; n], vec![0.0; n]);
        lower.apply(&x, &mut y);
        coarse.apply(&x, &mut expected);
        let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in y.iter().zip(&expected) {
            assert!((a - b).abs() <= 1e-13 * scale, "{a} against {b}");
        }
        for block in [vec![0, 1], vec![3, 4, 5], vec![n - 1, 9, 1]] {
            let (a, b) = (lower.block_values(&block), coarse.block_values(&block));
            // The lower triangle's block is exactly symmetric, from the upper entries.
            for (i, row) in block.iter().enumerate() {
                for (j, col) in block.iter().enumerate() {
                    let upper = &b[block.len() * i.min(j) + j.max(i)];
                    assert_eq!(a[block.len() * i + j], *upper, "({row}, {col})");
                }
            }
        }
        let ((pa, va), (pb, vb)) = (lower.to_csc(true), Operator::Rows(coarse).to_csc(true));
        assert_eq!(
            (pa.col_ptr(), pa.row_idx(), va),
            (pb.col_ptr(), pb.row_idx(), vb)
        );
    }

    #[test]
    fn a_node_graph_that_misses_entries_of_the_triangle_is_refused() {
        // The graph of another pattern (node 0 no longer coupled to the last):
        // its rows would silently lack entries.
        let m = nodal(20);
        let other = Nodal::new(m.lists.first.clone(), |a, b| a - b <= 2);
        let wrong = || {
            Fine::Lower(
                Arc::clone(&m.col_ptr),
                m.vals.clone(),
                Arc::clone(&other.lists),
            )
        };
        let error = Multigrid::fine(wrong()).unwrap_err();
        assert!(
            error.contains("does not describe the tangent's pattern"),
            "{error}"
        );
        let p = interpolation(m.whole.rows, false);
        let mut mg = Multigrid::new(vec![Transfer {
            prolongation: p,
            fine_blocks: (0..m.whole.rows).map(|i| vec![i]).collect(),
        }]);
        assert!(mg.refresh(wrong(), true).is_err());
    }

    #[test]
    fn products_over_the_lower_triangle_are_the_whole_matrix_on_any_thread_count() {
        // Several column chunks, columns that reach the last row from far
        // above, and columns holding only their diagonal.
        for n in [1, 7, COLUMNS_PER_TASK + 1, 2 * COLUMNS_PER_TASK + 77] {
            let m = ragged(n);
            let lower = Multigrid::fine(m.fine()).unwrap();
            let x: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
            let mut expected = vec![0.0; n];
            m.whole.apply(&x, &mut expected);
            let product = |threads: usize| {
                let mut y = vec![f64::NAN; n];
                crate::parallel::on_threads(threads, || lower.apply(&x, &mut y));
                y
            };
            let (one, two) = (product(1), product(2));
            assert_eq!(one, two, "n = {n}: the bits depend on the threads");
            for (i, (a, b)) in one.iter().zip(&expected).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-14 * b.abs().max(1.0),
                    "n = {n}, row {i}: {a} against {b}"
                );
            }
        }
    }

    #[test]
    fn a_singular_coarse_operator_is_shifted_not_replaced_by_the_fine_one() {
        // Two coinciding coarse basis functions (P z = 0) make A_c = Pᵀ A P
        // singular. The hierarchy keeps its coarse level, factorized with the
        // shift, and the V-cycle is the one without the duplicate (the
        // restricted residual has no component along z, P x_c none either).
        let n = 31;
        let a = laplacian(n);
        let blocks: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
        let cycle = |duplicate: bool| {
            let transfer = Transfer {
                prolongation: interpolation(n, duplicate),
                fine_blocks: blocks.clone(),
            };
            let mut mg = Multigrid::new(vec![transfer]);
            let shape = mg.refresh(a.clone(), true).unwrap();
            let r: Vec<f64> = (0..n).map(|i| ((i * 7 % 11) as f64 - 5.0) / 3.0).collect();
            let mut z = vec![0.0; n];
            mg.apply(&r, &mut z);
            (shape, mg.depth(), z)
        };
        let (plain, depth, z) = cycle(false);
        assert_eq!(
            (plain.coarse_shift, depth, plain.unknowns.clone()),
            (0.0, 2, vec![31, 15])
        );
        let (shifted, depth, z_dup) = cycle(true);
        assert_eq!(
            (shifted.coarse_shift, depth, shifted.unknowns),
            (COARSE_SHIFT, 2, vec![31, 16])
        );
        let scale = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = z
            .iter()
            .zip(&z_dup)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff < 1e-6 * scale,
            "V-cycles differ by {diff:.2e} of {scale:.2e}"
        );
    }
}
