//! Plane-strain limit analysis with second-order cone programming (clarabel):
//! rigorous lower and upper bounds on the collapse load of a footing and on the
//! strength-reduction factor of safety of a slope, as an independent check of
//! the MPM strength-reduction results.
//!
//! - `mesh`: structured triangulations from mapped blocks.
//! - `cone`: Mohr–Coulomb as a second-order cone; the clarabel program builder.
//! - `model`: the boundary value problems (footing, slope).
//! - `lower_bound`: linear stress triangles with stress discontinuities.
//! - `upper_bound`: quadratic velocity triangles, solved in dual form.
//! - `reduction`: the factor of safety from the collapse multiplier on gravity.
//! - `config`, `run`: the `mpm limit` scene file and driver.
//!
//! Sign convention: tension positive, compression negative.

pub(crate) mod cone;
pub mod config;
pub mod lower_bound;
pub(crate) mod mesh;
pub(crate) mod model;
pub mod reduction;
pub mod run;
pub mod upper_bound;

/// A solved bound: the collapse multiplier (physical units) and the size and
/// cost of the conic program.
#[derive(Clone, Debug)]
pub struct Bound {
    pub multiplier: f64,
    pub elements: usize,
    pub variables: usize,
    pub equalities: usize,
    pub cones: usize,
    pub iterations: u32,
    pub seconds: f64,
    /// Lower bound: (σx, σy, τxy) at every triangle node (three per triangle, in
    /// the units of the model). Upper bound: the normalised collapse velocity
    /// (vx, vy, 0) at every vertex and mid-side node.
    pub field: Vec<[f64; 3]>,
}
