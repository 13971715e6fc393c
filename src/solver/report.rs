//! What the solvers report: one row per Newton iteration (newton.csv) and the
//! solver fields of a stage in summary.json.

use crate::scene::{
    DirectOrdering, Integrator, LinearSolver, PreconditionerKind, Scheme, SolverKind,
};
use crate::solver::linear::direct::Statistics;
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
/// summary.json: the kind, the scheme of an explicit stage, the integrator,
/// linear solver and iteration counts of an implicit one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverReport {
    pub solver: SolverKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scheme: Option<Scheme>,
    /// How the last explicit step moved values between particles and nodes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<TransferPath>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<Integrator>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub newton_iterations: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutbacks: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<LinearSolver>,
    /// Krylov iterations over all Newton corrections (0 with the direct solver).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub krylov_iterations: Option<usize>,
    /// Krylov solvers only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preconditioner: Option<PreconditionerKind>,
    /// Factorizations of the lagged_direct preconditioner (Krylov solvers only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lagged_factorizations: Option<usize>,
    /// The sparse direct solver of the stage (the direct linear solver, or the
    /// lagged_direct preconditioner).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direct: Option<DirectReport>,
    /// Newmark only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma: Option<f64>,
    /// Implicit contact with rigid bodies: the deepest penalty penetration of a
    /// converged step (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_penetration: Option<f64>,
    /// The multigrid preconditioner's refreshes (multigrid only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multigrid: Option<MultigridCounts>,
}

/// What the multigrid preconditioner did over a stage: how often its operators
/// were refreshed, how often the coarsest one was singular and factorized with
/// a diagonal shift, how often a refresh had to end its hierarchy on a finer
/// level (its coarsest operator could not be factorized even shifted), and the
/// largest coarsest level factorized.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MultigridCounts {
    pub refreshes: usize,
    pub shifted: usize,
    pub truncated: usize,
    pub largest_coarse_unknowns: usize,
}

/// The transfers an explicit step took (`solver.transfer`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransferPath {
    /// Particle-side scatter on a box of nodes (`solver::explicit::scatter`).
    Scatter,
    /// Node-side gathers through the node map.
    Gather,
}

impl SolverReport {
    /// An explicit stage.
    pub fn explicit(scheme: Scheme, transfer: TransferPath) -> SolverReport {
        SolverReport {
            solver: SolverKind::Explicit,
            scheme: Some(scheme),
            transfer: Some(transfer),
            integrator: None,
            newton_iterations: None,
            cutbacks: None,
            linear_solver: None,
            krylov_iterations: None,
            preconditioner: None,
            lagged_factorizations: None,
            direct: None,
            beta: None,
            gamma: None,
            contact_penetration: None,
            multigrid: None,
        }
    }
}

/// What the sparse direct solver of a stage did: its ordering, how often it
/// factorized and analysed a new pattern, and its largest factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectReport {
    /// The fill-reducing ordering used (`auto` resolved: amd or metis).
    pub ordering: DirectOrdering,
    pub factorizations: usize,
    /// Symbolic analyses: one per new pattern (a step whose stencils,
    /// constraints or ties changed).
    pub symbolic_analyses: usize,
    /// Stored entries of the largest Cholesky factor (0 when only LU was used)
    /// and its values' memory.
    pub largest_factor_entries: usize,
    pub largest_factor_mib: f64,
}

impl DirectReport {
    pub fn new(ordering: DirectOrdering, s: Statistics) -> DirectReport {
        DirectReport {
            ordering,
            factorizations: s.factorizations,
            symbolic_analyses: s.symbolic_analyses,
            largest_factor_entries: s.largest_factor_entries,
            largest_factor_mib: (s.largest_factor_entries * 8) as f64 / (1024.0 * 1024.0),
        }
    }
}
