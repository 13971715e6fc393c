//! The interface the stage loop of a run drives: one time stepper per stage,
//! explicit or implicit.

use crate::dim::Vector;
use crate::model::Model;
use crate::physics::contact::totals::PairTotal;
use crate::scene::LinearSystems;
use crate::solver::divergence::Divergence;
use crate::solver::linear::direct::Statistics;
use crate::solver::report::{MultigridCounts, NewtonRow, SolverReport};
use serde::{Deserialize, Serialize};

/// What a stepper carries from one step to the next that a restart needs
/// (`run::checkpoint`): the Newmark particle accelerations, the implicit
/// contact's tangential forces and contact points, and the counts that
/// summary.json reports. Buffers rebuilt every step are not part of it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolverState {
    /// Newmark particle accelerations a_p, D values per particle (empty when the
    /// stepper keeps none, or before its first step).
    pub acceleration: Vec<f64>,
    pub newton_iterations: usize,
    pub cutbacks: usize,
    pub krylov_iterations: usize,
    pub lagged_factorizations: usize,
    /// The direct solver's counts (zero in checkpoints written before they were kept).
    #[serde(default)]
    pub direct: Statistics,
    /// The implicit contact's tangential force of every particle at the end of
    /// the last step, D values per particle (empty without friction).
    #[serde(default)]
    pub contact_tangential: Vec<f64>,
    /// The implicit contact's contact points carried to the next step, 2 + D
    /// values per particle that has one (empty in checkpoints written before
    /// they were carried: the points are then set on the particles' domains).
    #[serde(default)]
    pub contact_points: Vec<f64>,
    /// The multigrid's counts (zero in checkpoints written before they were kept).
    #[serde(default)]
    pub multigrid: MultigridCounts,
}

pub trait Stepper<const D: usize> {
    /// The step to take now (at most what is left of the stage is taken).
    fn dt(&self, m: &Model<D>) -> f64;

    /// Advance the model from t to t + dt, the run's step number `step`; returns
    /// the work of gravity and applied loads over the step.
    fn step(&mut self, m: &mut Model<D>, t: f64, dt: f64, step: usize) -> Result<f64, Divergence>;

    /// Active grid nodes of the last step.
    fn active_nodes(&self) -> usize;

    /// A warning about the steps the stage will take, from the state `m` at
    /// its start: an explicit fixed Δt above the critical step (it runs as
    /// asked, for stability studies).
    fn step_warning(&self, _m: &Model<D>) -> Option<String> {
        None
    }

    /// Reactions of the last converged step: (grid node, force the prescribed
    /// components exert on the body); `None` when the stepper computes none.
    fn reaction(&self) -> Option<&[(u32, Vector<D>)]> {
        None
    }

    /// The Newton iterations since the last call (for newton.csv).
    fn take_newton_rows(&mut self) -> Vec<NewtonRow> {
        Vec::new()
    }

    /// Write the linear systems of the Newton iterations `which` to `dir`
    /// (`[output] linear_systems`; only steppers that assemble them do).
    fn export_linear_systems(&mut self, _dir: &std::path::Path, _which: LinearSystems) {}

    /// The solver fields of summary.json, counts so far.
    fn report(&self) -> SolverReport;

    /// What contact between bodies did since the last call, per pair of velocity
    /// fields (explicit runs with `[[contact]]`; empty otherwise).
    fn take_contact(&mut self) -> Vec<PairTotal<D>> {
        Vec::new()
    }

    /// The contact force on every particle of `m` in the last (converged)
    /// step (`particles_final.csv`'s `contact_f*` columns): implicit contact
    /// with rigid bodies, explicit contact between bodies; `None` for a
    /// solver or a scene without per-particle contact forces.
    fn contact_forces(&self, _m: &Model<D>) -> Option<Vec<Vector<D>>> {
        None
    }

    /// The state carried across steps, for a checkpoint.
    fn state(&self) -> SolverState {
        SolverState::default()
    }

    /// Continue from a checkpoint's state (`state` of the same kind of stepper).
    fn restore(&mut self, _state: &SolverState) {}
}
