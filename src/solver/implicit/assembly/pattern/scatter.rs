//! The scatter of the tangent's terms into the values of the step's pattern.
//!
//! A term couples some components of a row node to some of a column node
//! ([`Coupling`]): the stiffness the D×D block of the displacements, a
//! diffusion term the diagonal of a scalar field, a coupling term the blocks
//! between the two. Its values are spread onto the unknowns through the ties
//! and added where the pattern keeps them.

use super::super::Dofs;
use super::graph::sources;
use super::layout::{slot, Storage};
use super::Pattern;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::linear::Index;
use rayon::prelude::*;

/// Which component pairs (i, k) of two nodes' blocks a term couples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Components {
    /// Every pair: a full block (stiffness).
    All,
    /// i = k only: a diagonal block (mass, dashpots, springs).
    Diagonal,
}

/// The block of components a term couples: the R components `rows..rows + R`
/// of the row node with the C components `cols..cols + C` of the column node
/// (`Dofs`: components 0..D are the displacements), every pair or only the
/// diagonal ones (R = C). Its values for one pair of stencil entries are
/// `block[i·C + k]` for component `rows + i` × component `cols + k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Coupling<const R: usize, const C: usize> {
    /// The first row component.
    pub rows: usize,
    /// The first column component.
    pub cols: usize,
    pub components: Components,
}

impl<const D: usize> Coupling<D, D> {
    /// The D×D block of the displacements (components 0..D of both nodes).
    pub const fn displacements(components: Components) -> Self {
        Coupling {
            rows: 0,
            cols: 0,
            components,
        }
    }
}

impl Pattern {
    /// Adds the term of every particle q with `column(q, e2, needed, block)` true
    /// to the values of the pattern with `storage` (its column pointers
    /// `col_ptr`, [`Pattern::col_ptr`]): for each stencil entry e2 of q,
    /// `column` fills `block[(e1 − first entry of q)·R·C + i·C + k]` with the
    /// term at (node of e1, component `coupling.rows + i`) × (node of e2,
    /// component `coupling.cols + k`) for every entry e1 of q with
    /// `needed[e1 − first entry of q]` (the others are not read: with `Lower`,
    /// the entries all of whose owners, the node or the masters of its tie,
    /// come before the column's node, so that their rows lie above the
    /// diagonal); `coupling.components` says which (i, k) it sets. Spread onto
    /// the unknowns through the ties; rows below the diagonal only with `Lower`.
    #[allow(clippy::too_many_arguments)]
    pub fn add_terms<const D: usize, const R: usize, const C: usize>(
        &self,
        values: &mut [f64],
        col_ptr: &[Index],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        coupling: Coupling<R, C>,
        column: impl Fn(usize, usize, &[bool], &mut [f64]) -> bool + Sync,
    ) {
        let n = dofs.per_node();
        assert!(
            coupling.rows + R <= n && coupling.cols + C <= n,
            "a block of {R}×{C} components from ({}, {}) of nodes of {n}",
            coupling.rows,
            coupling.cols
        );
        assert!(
            coupling.components == Components::All || R == C,
            "a diagonal block is square"
        );
        self.split_by_node(col_ptr, values)
            .into_par_iter()
            .enumerate()
            .with_min_len(16)
            .for_each_init(
                || {
                    (
                        Vec::new(),
                        vec![false; st.stride],
                        vec![0.0; st.stride * R * C],
                    )
                },
                |(offsets, needed, block), (b, vals)| {
                    self.add_column_terms(
                        b, vals, col_ptr, storage, map, st, dofs, coupling, &column, offsets,
                        needed, block,
                    )
                },
            );
    }

    /// Adds terms of the displacements' block that couple a particle's stencil
    /// to nodes beyond it: for each stencil entry e2 of particle q (node J),
    /// `rows(q, e2, out)` lists (node I, block) with block[i·D + k] the term at
    /// (I, component i) × (J, component k), i, k < D, for any active nodes I
    /// that the pattern couples to J. Spread onto the unknowns through the
    /// ties; the whole matrix only (`Storage::Full`). In parallel over the
    /// columns' nodes, each visiting its sources in order: the same sums for
    /// any number of threads.
    #[allow(clippy::too_many_arguments)]
    pub fn add_listed_terms<const D: usize>(
        &self,
        values: &mut [f64],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        rows: impl Fn(usize, usize, &mut Vec<(usize, [f64; 9])>) + Sync,
    ) {
        assert_eq!(storage, Storage::Full, "listed terms need the whole matrix");
        assert!(
            D <= dofs.per_node(),
            "displacements in nodes of {}",
            dofs.per_node()
        );
        let csc = &**self
            .csc(storage)
            .expect("counted by the tangent's column pointers");
        let col_ptr = csc.col_ptr();
        self.split_by_node(col_ptr, values)
            .into_par_iter()
            .enumerate()
            .with_min_len(16)
            .for_each_init(Vec::new, |out, (b, vals)| {
                let cols = self.columns(b);
                if cols.is_empty() {
                    return;
                }
                let base = col_ptr[cols.start] as usize;
                let col_of: [Option<usize>; D] = std::array::from_fn(|k| dofs.of(b, k));
                for (e2, cc) in sources(self.tied_sources.as_ref(), map, b) {
                    out.clear();
                    rows(e2 as usize / st.stride, e2 as usize, out);
                    for (n1, block) in out.iter() {
                        for (a, cr) in dofs.owners(*n1) {
                            for i in 0..D {
                                let Some(r) = dofs.of(a, i) else { continue };
                                for (k, c) in col_of.iter().enumerate() {
                                    let Some(c) = *c else { continue };
                                    let at = slot(csc.as_ref(), r, c)
                                        .expect("listed entry in the pattern");
                                    vals[at - base] += block[i * D + k] * cr * cc;
                                }
                            }
                        }
                    }
                }
            });
    }

    /// The terms of node b's columns (`vals`, from `col_ptr[first column]` on).
    /// Row r of node a (a neighbour of b) sits in column c at
    /// `offsets[k·m + j] + r − max(first[a], c)`, k the place of c's component
    /// in the coupling's columns, j the position of a among b's m neighbours
    /// and `offsets[k·m + j]` the rows of the neighbours before it.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn add_column_terms<const D: usize, const R: usize, const C: usize>(
        &self,
        b: usize,
        vals: &mut [f64],
        col_ptr: &[Index],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        coupling: Coupling<R, C>,
        column: &impl Fn(usize, usize, &[bool], &mut [f64]) -> bool,
        offsets: &mut Vec<usize>,
        needed: &mut [bool],
        block: &mut [f64],
    ) {
        let cols = self.columns(b);
        if cols.is_empty() {
            return;
        }
        let base = col_ptr[cols.start] as usize;
        let neighbours = self.neighbours(b);
        let m = neighbours.len();
        // Rows of column c: the unknowns first[a]..first[a + 1] of each
        // neighbour a in order, those < c dropped when only the lower
        // triangle is stored (`NodeLists::rows_of`).
        let lowest = |c: usize| storage.lowest(c);
        offsets.clear();
        offsets.resize(C * m, usize::MAX);
        let mut col_of = [usize::MAX; C];
        for k in 0..C {
            let Some(c) = dofs.of(b, coupling.cols + k) else {
                continue;
            };
            col_of[k] = c;
            let mut at = col_ptr[c] as usize - base;
            for (j, &a) in neighbours.iter().enumerate() {
                offsets[k * m + j] = at;
                at += self.lists.rows_of(a as usize, lowest(c)).len();
            }
            debug_assert_eq!(at, col_ptr[c + 1] as usize - base);
        }
        for (e2, cc) in sources(self.tied_sources.as_ref(), map, b) {
            let e2 = e2 as usize;
            let q = e2 / st.stride;
            // With `Lower`, an entry whose owners all come before b (their
            // unknowns all above b's columns) takes no term in b's columns.
            let needed = &mut needed[..st.range(q).len()];
            if storage == Storage::Full {
                needed.fill(true);
            } else {
                for (flag, e1) in needed.iter_mut().zip(st.range(q)) {
                    let n1 = map.local_of(st, e1);
                    *flag = dofs.owners(n1).any(|(a, _)| a >= b);
                }
            }
            if !column(q, e2, needed, block) {
                continue;
            }
            // The stencil's nodes ascend, so each is found by a short scan on
            // from the previous one (ties may point back: then a search).
            let mut hint = 0;
            for (local, e1) in st.range(q).enumerate() {
                if !needed[local] {
                    continue;
                }
                let n1 = map.local_of(st, e1);
                for (a, cr) in dofs.owners(n1) {
                    let Some(j) = position(neighbours, a as u32, hint) else {
                        continue;
                    };
                    hint = j;
                    let lo = self.lists.first[a];
                    for (i, r) in dofs.block::<R>(a, coupling.rows).into_iter().enumerate() {
                        let Some(r) = r else { continue };
                        let coupled = match coupling.components {
                            Components::All => 0..C,
                            Components::Diagonal => i..i + 1,
                        };
                        for k in coupled {
                            let c = col_of[k];
                            if c == usize::MAX || r < lowest(c) {
                                continue;
                            }
                            let slot = offsets[k * m + j] + r - lo.max(lowest(c));
                            vals[slot] += block[local * R * C + i * C + k] * cr * cc;
                        }
                    }
                }
            }
        }
    }
}

/// Position of `a` in the ascending `sorted`, scanning on from `from` first.
fn position(sorted: &[u32], a: u32, from: usize) -> Option<usize> {
    let mut j = from;
    while j < sorted.len() && sorted[j] < a {
        j += 1;
    }
    if j < sorted.len() && sorted[j] == a {
        Some(j)
    } else {
        sorted.binary_search(&a).ok()
    }
}
