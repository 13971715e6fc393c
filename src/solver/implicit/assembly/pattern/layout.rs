//! The compressed-column layout of the tangent's unknowns: which part is
//! stored ([`Storage`]), the column pointers and row indices that the node
//! graph gives (`node_pattern`), and where an entry sits ([`slot`]).

use super::Pattern;
use crate::solver::linear::Index;
use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
use rayon::prelude::*;
use std::sync::Arc;

/// Which part of the tangent is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// Rows ≥ column only (a symmetric tangent).
    Lower,
    /// Every entry.
    Full,
}

impl Storage {
    /// The lowest row of column c that is stored: c itself in the lower
    /// triangle, 0 in the whole matrix.
    pub(super) fn lowest(self, c: usize) -> usize {
        match self {
            Storage::Lower => c,
            Storage::Full => 0,
        }
    }
}

impl Pattern {
    /// The column pointers of the compressed-column pattern of the unknowns
    /// (counted at the first call, in parallel over the nodes): column c of
    /// node b holds the unknowns of b's neighbours, those ≥ c with `Lower`
    /// ([`NodeLists`]). An error if the pattern has more entries than
    /// [`Index`] numbers.
    pub fn col_ptr(&self, storage: Storage) -> Result<&Arc<[Index]>, String> {
        let cell = match storage {
            Storage::Lower => &self.lower_cols,
            Storage::Full => &self.full_cols,
        };
        if let Some(ptr) = cell.get() {
            return Ok(ptr);
        }
        let lengths: Vec<usize> = (0..self.nodes())
            .into_par_iter()
            .with_min_len(256)
            .flat_map_iter(|b| {
                self.columns(b)
                    .map(move |c| self.lists.column_len(b, storage.lowest(c)))
            })
            .collect();
        let total: usize = lengths.iter().sum();
        if total > Index::MAX as usize {
            return Err(format!(
                "the tangent's pattern has {total} entries, more than the 2³² that 32-bit \
                 indices number"
            ));
        }
        let mut col_ptr: Vec<Index> = Vec::with_capacity(lengths.len() + 1);
        col_ptr.push(0);
        for len in lengths {
            col_ptr.push(col_ptr.last().unwrap() + len as Index);
        }
        Ok(cell.get_or_init(|| col_ptr.into()))
    }

    /// The compressed-column pattern with its row indices (built at the first
    /// call), shared: the direct solver keeps a handle to the pattern it
    /// analysed instead of a copy. An error as [`Pattern::col_ptr`].
    pub fn csc(&self, storage: Storage) -> Result<&Arc<SymbolicSparseColMat<Index>>, String> {
        let cell = match storage {
            Storage::Lower => &self.lower,
            Storage::Full => &self.full,
        };
        if let Some(csc) = cell.get() {
            return Ok(csc);
        }
        let csc = self.build_csc(storage)?;
        Ok(cell.get_or_init(|| Arc::new(csc)))
    }

    /// The rows of every column ([`NodeLists::for_each_in_column`]), filled in
    /// parallel over the nodes (each node writes its own columns: the same
    /// result on any number of threads). Rows ascend within each column:
    /// neighbours ascend and unknowns are numbered node by node.
    fn build_csc(&self, storage: Storage) -> Result<SymbolicSparseColMat<Index>, String> {
        let col_ptr = self.col_ptr(storage)?;
        let mut rows: Vec<Index> = vec![0; col_ptr[col_ptr.len() - 1] as usize];
        self.split_by_node(col_ptr, &mut rows)
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .for_each(|(b, out)| {
                let base = col_ptr[self.columns(b).start] as usize;
                for c in self.columns(b) {
                    let lowest = storage.lowest(c);
                    let from = self.lists.neighbours_from(b, lowest);
                    (self.lists).for_each_in_column(col_ptr, from, c, lowest, |k, i| {
                        out[k - base] = i as Index
                    });
                }
            });
        let n = col_ptr.len() - 1;
        Ok(SymbolicSparseColMat::new_checked(
            n,
            n,
            col_ptr.to_vec(),
            None,
            rows,
        ))
    }

    /// `entries` (a compressed-column array with `col_ptr`) split into the
    /// columns of each node: disjoint slices, in node order.
    pub(super) fn split_by_node<'v, T>(
        &self,
        col_ptr: &[Index],
        mut entries: &'v mut [T],
    ) -> Vec<&'v mut [T]> {
        let mut out = Vec::with_capacity(self.nodes());
        for b in 0..self.nodes() {
            let cols = self.columns(b);
            let len = col_ptr[cols.end] - col_ptr[cols.start];
            let (head, tail) = entries.split_at_mut(len as usize);
            out.push(head);
            entries = tail;
        }
        out
    }
}

/// Position of row r in column c of `csc`, if the pattern has it.
pub fn slot(csc: SymbolicSparseColMatRef<Index>, r: usize, c: usize) -> Option<usize> {
    let (start, end) = (csc.col_ptr()[c] as usize, csc.col_ptr()[c + 1] as usize);
    csc.row_idx()[start..end]
        .binary_search(&(r as Index))
        .ok()
        .map(|s| start + s)
}
