//! Linear solvers of the implicit Newton step: sparse direct (faer) and Krylov
//! (GMRES, CG) with their preconditioners.

/// The index type of the sparse matrices (tangent patterns, factors, coarse
/// operators): 32 bits, half the memory of `usize` row indices. A pattern or
/// factor beyond 2³² entries (32 GiB of values alone) is refused with an
/// error.
pub type Index = u32;

pub(crate) mod cg;
pub mod direct;
pub(crate) mod gmres;
pub(crate) mod iterative;
pub(crate) mod multigrid;
pub(crate) mod node_pattern;
pub mod ordering;
pub(crate) mod preconditioner;
