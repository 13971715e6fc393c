//! The consistent tangent K = ∂r/∂u of the implicit step over its unknowns
//! (thesis 2-40…2-42), in the configuration at the start of the step (updated
//! Lagrangian).
//!
//! The unknowns are the free components of the active nodes ([`Dofs`]): the D
//! displacements, and further scalar fields when the problem gives a node more
//! components (`Dofs::per_node`); a tied node (`super::ties`) has none and
//! enters through its masters, u = T ũ, so every nodal entry is spread onto the
//! unknowns (`Dofs::terms`). Each term of K couples the nodes of one particle's
//! stencil, and some components of them ([`Coupling`]: the terms below couple
//! the displacements' D×D block); [`pattern`] builds the step's sparsity
//! pattern from the stencils and adds the terms into its values
//! (`Pattern::add_terms`, the one loop over stencil pairs):
//! - [`stiffness`]: Σ_p V_p ∇S_Ip A_p ∇S_Jp with A_p = ∂P/∂ΔF, material (2-41)
//!   and geometric (2-42) parts;
//! - [`fbar`]: the same with F-bar, which also couples the particles of a cell;
//! - [`linear_stress`]: the stress gradient within the particle domains, which
//!   couples each particle to the nodes of its least-squares neighbours;
//! - [`mass`]: the inertia M/(βΔt²) of 2-40, lumped or consistent;
//! - [`absorbing`]: the dashpots and springs of absorbing faces (2-63).
//!
//! A term of another block adds itself with `Pattern::add_terms` and the
//! block's `Coupling` (the tests: a scalar field with D + 1 unknowns per node).

pub(crate) mod absorbing;
pub(crate) mod fbar;
pub(crate) mod linear_stress;
pub(crate) mod mass;
pub(crate) mod pattern;
pub mod stiffness;

mod dofs;
#[cfg(test)]
mod tests;

pub use dofs::{Dofs, Terms, Tie};
pub use pattern::layout::Storage;
pub use pattern::scatter::{Components, Coupling};
pub use pattern::tangent::Tangent;
pub use pattern::Pattern;
