//! Linear solvers of the implicit Newton step: sparse direct (faer) and Krylov
//! (GMRES, CG) with their preconditioners.

pub mod cg;
pub mod direct;
pub mod gmres;
pub mod iterative;
pub mod multigrid;
pub mod ordering;
pub mod preconditioner;
