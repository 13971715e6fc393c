//! What the solvers report: one row per Newton iteration (newton.csv) and the
//! solver fields of a stage in summary.json.

use crate::scene::{Integrator, LinearSolver, PreconditionerKind, Scheme};
use serde::{Deserialize, Serialize};

/// One Newton iteration, as written to newton.csv.
#[derive(Clone, Debug)]
pub struct NewtonRow {
    pub step: usize,
    pub time: f64,
    pub dt: f64,
    /// How many times this step was halved.
    pub cutback: usize,
    pub iteration: usize,
    /// ‖r‖ / reference force.
    pub residual: f64,
    /// ‖δu‖ / ‖u‖ of the correction that follows (NaN on the converged row).
    pub increment: f64,
    pub wall_seconds: f64,
    /// The linear solver of that correction (`direct` method, or `gmres/jacobi` …).
    pub linear_solver: String,
    /// Krylov iterations of the correction that follows (0: direct solver or
    /// converged row).
    pub krylov_iterations: usize,
    /// Forcing term η of that correction (NaN: direct solver or converged row).
    pub forcing: f64,
}

/// The solver fields of a stage (and of the run, for its last stage) in
/// summary.json: `"solver": "explicit"` with the scheme, or `"solver": "implicit"`
/// with the integrator and the iteration counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "solver", rename_all = "snake_case")]
pub enum SolverReport {
    Explicit { scheme: Scheme },
    Implicit(ImplicitReport),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImplicitReport {
    pub integrator: Integrator,
    pub newton_iterations: usize,
    pub cutbacks: usize,
    pub linear_solver: LinearSolver,
    /// Krylov iterations over all Newton corrections (0 with the direct solver).
    pub krylov_iterations: usize,
    /// Krylov solvers only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preconditioner: Option<PreconditionerKind>,
    /// Factorizations of the lagged_direct preconditioner (Krylov solvers only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lagged_factorizations: Option<usize>,
    /// Newmark only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma: Option<f64>,
}
