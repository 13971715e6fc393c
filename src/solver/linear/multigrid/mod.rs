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
//!
//! Nothing here knows the unknowns' layout: the transfers give the
//! prolongations and, per node of each finer level, its unknowns, all its
//! components together (`Transfer::fine_blocks`), which are the block-Jacobi
//! blocks.
//!
//! The files, by concept: `csr` (compressed rows), `lower` (a symmetric
//! matrix as its lower triangle, read by rows through the node graph),
//! `galerkin` (the triple products), `operator` (the operator of a level),
//! `smoother` (Chebyshev on block Jacobi, the eigenvalue estimate) and
//! `vcycle` (the hierarchy's refresh, the coarse factorization and the
//! cycle).

mod csr;
mod galerkin;
mod lower;
mod operator;
mod smoother;
mod vcycle;

pub use csr::Csr;
pub use operator::Fine;
pub use vcycle::{Multigrid, Transfer};
#[cfg(test)]
use {
    galerkin::{galerkin, Rows},
    lower::LowerRows,
    operator::Operator,
    vcycle::COARSE_SHIFT,
};

#[cfg(test)]
mod tests;
