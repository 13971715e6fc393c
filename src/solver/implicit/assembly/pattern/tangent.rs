//! The assembled tangent: values in the step's pattern.

use super::super::Dofs;
use super::layout::{slot, Storage};
use super::scatter::{Components, Coupling};
use super::Pattern;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::linear::direct::spmv;
use crate::solver::linear::Index;
use faer::sparse::SparseColMatRef;
use std::sync::Arc;

/// The assembled tangent of one Newton iterate: values in the step's pattern.
pub struct Tangent<'a> {
    /// The step's pattern.
    pub pattern: &'a Pattern,
    /// Its column pointers for `storage` ([`Pattern::col_ptr`]).
    pub col_ptr: &'a Arc<[Index]>,
    pub values: Vec<f64>,
    /// `Lower` when the tangent is symmetric (only rows ≥ column stored).
    pub storage: Storage,
}

impl Tangent<'_> {
    /// The tangent as a compressed-column matrix (its row indices built at
    /// the first call of the step, [`Pattern::csc`]).
    pub fn matrix(&self) -> SparseColMatRef<'_, Index, f64> {
        let csc = (self.pattern.csc(self.storage)).expect("counted by the column pointers");
        SparseColMatRef::new((**csc).as_ref(), &self.values)
    }

    pub fn symmetric(&self) -> bool {
        self.storage == Storage::Lower
    }

    /// y = K x (both triangles when only the lower one is stored).
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        spmv(self.matrix(), self.symmetric(), x, false)
    }

    /// The position of entry (r, c) among the values, if the pattern holds
    /// it: a symmetric tangent finds it through the node graph (the multigrid
    /// never builds its row indices), an unsymmetric one, whose rows every
    /// solver builds, by a search in column c (F-bar asks for many entries).
    pub fn slot(&self, r: usize, c: usize) -> Option<usize> {
        if self.storage == Storage::Full {
            return slot(self.matrix().symbolic(), r, c);
        }
        let lists = &self.pattern.lists;
        let (a, b) = (lists.node_of(r), lists.node_of(c));
        lists.position(self.col_ptr, (a, r), (b, c), self.storage.lowest(c))
    }

    /// Adds the particles' stencil-pair terms of one `coupling` to the values
    /// (`Pattern::add_terms`, the one scatter into the step's pattern).
    pub fn add_terms<const D: usize, const R: usize, const C: usize>(
        &mut self,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        coupling: Coupling<R, C>,
        column: impl Fn(usize, usize, &[bool], &mut [f64]) -> bool + Sync,
    ) {
        let (pattern, col_ptr, storage) = (self.pattern, self.col_ptr, self.storage);
        pattern.add_terms(
            &mut self.values,
            col_ptr,
            storage,
            map,
            st,
            dofs,
            coupling,
            column,
        );
    }

    /// Adds a term between two active nodes beyond the stencils (a pair the
    /// term listed in its couplings, `Pattern::new`'s `coupled`): K_ab +=
    /// `block(i, k)` at (a, component `coupling.rows + i`) × (b, component
    /// `coupling.cols + k`), spread onto the unknowns through the ties; rows
    /// above the diagonal dropped with `Lower`.
    pub fn add_node_block<const R: usize, const C: usize>(
        &mut self,
        dofs: &Dofs,
        (a, b): (usize, usize),
        coupling: Coupling<R, C>,
        block: impl Fn(usize, usize) -> f64,
    ) {
        for i in 0..R {
            let rows = dofs.terms(a, coupling.rows + i);
            let coupled = match coupling.components {
                Components::All => 0..C,
                Components::Diagonal => i..i + 1,
            };
            for k in coupled {
                for &(r, cr) in rows.as_slice() {
                    for &(c, cc) in dofs.terms(b, coupling.cols + k).as_slice() {
                        if self.storage == Storage::Full || r >= c {
                            let s = self.slot(r, c).expect("node pair in the pattern");
                            self.values[s] += block(i, k) * cr * cc;
                        }
                    }
                }
            }
        }
    }
}
