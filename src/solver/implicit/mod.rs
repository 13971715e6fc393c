//! Implicit MPM: Newmark with Newton-Raphson, or quasi-static load stepping, on the
//! same particles, grid, shape functions, transfers, boundary conditions and
//! material updates as the explicit solver (thesis §2.2.2).
//!
//! One step: shape functions at the step-start positions; unknowns are the nodal
//! displacement increments u of the free components; residual (2-37)
//! r(u) = M (u − ũ)/(βΔt²) + f_int(u) − f_ext (no inertia when quasi-static);
//! Newton (2-38) with the assembled consistent tangent (2-40), Dirichlet
//! components eliminated, sparse direct solves, or matrix-free GMRES / CG on
//! finite-difference products (2-39, `krylov`). Every iterate's stresses are
//! recomputed from the step-start state (`deformation::Trial`). A step whose Newton
//! iteration fails is halved and retried, up to `max_cutbacks` times.
//!
//! The files follow the step: `step` prepares it (and commits it) on the
//! step's `grid`, `newton` iterates on `residual` r(u) with corrections from the
//! tangent of `assembly` or from `krylov`; `ties` slaves weakly supported nodes,
//! `newmark` integrates in time. What is optional (absorbing faces, contact, a
//! linear domain stress) enters the step as one of its `terms`.

pub mod assembly;
pub(crate) mod coarsening;
pub(crate) mod export;
pub(crate) mod failure;
pub(crate) mod grid;
pub(crate) mod krylov;
pub(crate) mod newmark;
pub mod newton;
pub mod residual;
pub mod step;
pub(crate) mod stress_gradient;
pub(crate) mod terms;
#[cfg(test)]
mod tests;
pub(crate) mod ties;

use crate::dim::Vector;
use crate::model::Model;
use crate::physics::contact::totals::PairTotal;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::NodeMap;
use crate::scene::{
    Integrator, LinearSolver, LinearSystems, PreconditionerKind, SolverConfig, SolverKind,
};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::linear::direct::DirectSolver;
use crate::solver::report::{DirectReport, NewtonRow, SolverReport};
use crate::solver::stepper::{SolverState, Stepper};
use failure::Failure;
use newton::Newton;
use std::time::Instant;
use step::{number_unknowns, StepSettings, StepSystem};

pub struct Implicit<const D: usize> {
    /// The step size (Newmark `dt`, or end_time / load_steps).
    dt: f64,
    max_cutbacks: usize,
    settings: StepSettings,
    newton: Newton,
    /// The current step (kept between steps for its buffers).
    system: StepSystem<D>,
    /// Particle accelerations (Newmark only; empty otherwise).
    accel: Vec<Vector<D>>,
    /// Reactions of the last converged step: (grid node, force the prescribed
    /// components exert on the body), nodes with a non-zero reaction only.
    pub reaction: Vec<(u32, Vector<D>)>,
    pub cutbacks: usize,
    /// The state of a checkpoint, for the step's terms (their tangential
    /// forces, contact points and meetings): restored once they are set up,
    /// before the first step begins them.
    restored: Option<SolverState>,
}

impl<const D: usize> Implicit<D> {
    /// A solver for a run or stage that starts at time `t_start`.
    pub fn new(shape: ShapeFunction, s: &SolverConfig, t_start: f64) -> Self {
        Implicit {
            dt: s.implicit_dt(),
            max_cutbacks: s.max_cutbacks(),
            settings: StepSettings::new(shape, s, t_start),
            newton: Newton::new(s),
            system: StepSystem::new(s.mass()),
            accel: Vec::new(),
            reaction: Vec::new(),
            cutbacks: 0,
            restored: None,
        }
    }

    /// The sparse direct solver: the linear solver's, or the lagged_direct
    /// preconditioner's (None for other Krylov preconditioners).
    fn direct_solver(&self) -> Option<&DirectSolver> {
        match &self.newton.linear {
            newton::Linear::Direct(d) => Some(d),
            newton::Linear::Krylov(k) => {
                (k.config.preconditioner == PreconditionerKind::LaggedDirect).then_some(&k.lagged)
            }
        }
    }

    /// Factorizations of the lagged_direct preconditioner so far (0 otherwise).
    pub fn lagged_factorizations(&self) -> usize {
        self.newton.krylov().map_or(0, |k| k.factorizations)
    }

    /// Advance from t to t + dt at cut-back `level`, halving the step on Newton
    /// failure. Returns the work of gravity and applied loads.
    fn advance_level(
        &mut self,
        m: &mut Model<D>,
        t: f64,
        dt: f64,
        step: usize,
        level: usize,
    ) -> Result<f64, Divergence> {
        match self.attempt(m, t, dt, step, level) {
            // The step is committed: a state it leaves unsound (a particle off
            // the grid, F inverted) stops the run; a cut-back would restart
            // from the committed model, not from the step's start.
            Ok(work) => check_state(m, step + 1, t + dt).map(|()| work),
            Err(_) if level < self.max_cutbacks => {
                self.cutbacks += 1;
                let first = self.advance_level(m, t, dt / 2.0, step, level + 1)?;
                Ok(first + self.advance_level(m, t + dt / 2.0, dt / 2.0, step, level + 1)?)
            }
            Err(f) => Err(Divergence {
                step: step + 1,
                time: t + dt,
                particle: f.particle,
                message: format!(
                    "{} (after {} cut-backs of the step, now Δt = {dt:.3e})",
                    f.message, level
                ),
            }),
        }
    }

    /// One attempt at the step t → t + dt: prepare, Newton, commit. Leaves the
    /// model untouched when Newton fails; the caller checks the committed state.
    fn attempt(
        &mut self,
        m: &mut Model<D>,
        t: f64,
        dt: f64,
        step: usize,
        level: usize,
    ) -> Result<f64, Failure> {
        let started = Instant::now();
        self.prepare(m, t, dt);
        let converged = self
            .newton
            .solve(m, &mut self.system, step, level, started)?;
        let map = &self.system.map;
        self.reaction = (0..map.len())
            .map(|a| map.grid_node(a) as u32)
            .zip(converged.reaction)
            .filter(|(_, f)| *f != Vector::<D>::zeros())
            .collect();
        let work = self
            .settings
            .commit(m, &mut self.system, &converged.u, &mut self.accel);
        Ok(work)
    }

    /// Set up the step t → t + dt (`step`).
    fn prepare(&mut self, m: &Model<D>, t: f64, dt: f64) {
        self.system.set_up(m);
        if let Some(state) = self.restored.take() {
            self.system.restore_terms(&state);
        }
        self.settings
            .prepare(m, &mut self.system, &mut self.accel, t, dt);
    }
}

/// The unknowns of the first Newton system of a stage with settings `s` on model
/// `m` (particles where they are now): the free components of the active nodes,
/// weakly supported nodes tied to their neighbours. `mpm bench` reports it.
pub fn unknowns<const D: usize>(m: &Model<D>, shape: ShapeFunction, s: &SolverConfig) -> usize {
    let (mut st, mut map) = (Stencils::<D>::default(), NodeMap::default());
    let (mut grid, _) = terms::list::step_terms(m);
    grid.build(m, shape, &mut st, &mut map);
    number_unknowns(
        m,
        &m.faces,
        &m.friction,
        &st,
        &map,
        grid.node_fields(),
        s.min_node_support(),
    )
    .1
    .free
}

impl<const D: usize> Stepper<D> for Implicit<D> {
    fn dt(&self, _m: &Model<D>) -> f64 {
        self.dt
    }

    /// The step, halved on Newton failure up to `max_cutbacks` times.
    fn step(&mut self, m: &mut Model<D>, t: f64, dt: f64, step: usize) -> Result<f64, Divergence> {
        self.advance_level(m, t, dt, step, 0)
    }

    fn active_nodes(&self) -> usize {
        self.system.map.len()
    }

    fn reaction(&self) -> Option<&[(u32, Vector<D>)]> {
        Some(&self.reaction)
    }

    fn take_contact(&mut self) -> Vec<PairTotal<D>> {
        self.system.take_pair_totals()
    }

    fn contact_forces(&self, m: &Model<D>) -> Option<Vec<Vector<D>>> {
        self.system.particle_forces(m.particles.len())
    }

    fn take_newton_rows(&mut self) -> Vec<NewtonRow> {
        std::mem::take(&mut self.newton.log)
    }

    fn export_linear_systems(&mut self, dir: &std::path::Path, which: LinearSystems) {
        self.newton.export = Some(export::Export {
            dir: dir.to_path_buf(),
            which,
        });
    }

    fn report(&self) -> SolverReport {
        let krylov = self.newton.krylov().map(|k| k.config);
        let newmark = self.settings.integrator == Integrator::Newmark;
        SolverReport {
            solver: SolverKind::Implicit,
            scheme: None,
            transfer: None,
            integrator: Some(self.settings.integrator),
            newton_iterations: Some(self.newton.iterations),
            cutbacks: Some(self.cutbacks),
            linear_solver: Some(krylov.map_or(LinearSolver::Direct, |k| k.method)),
            krylov_iterations: Some(self.newton.krylov_iterations()),
            preconditioner: krylov.map(|k| k.preconditioner),
            lagged_factorizations: krylov.map(|_| self.lagged_factorizations()),
            direct: self.direct_solver().map(|d| {
                let ordering = self.settings.direct_ordering.resolved(D);
                DirectReport::new(ordering, d.statistics())
            }),
            beta: newmark.then_some(self.settings.newmark.beta),
            gamma: newmark.then_some(self.settings.newmark.gamma),
            contact_penetration: self.system.report().contact_penetration,
            multigrid: self.newton.krylov().and_then(|k| {
                use PreconditionerKind::{LaggedMultigrid, Multigrid};
                matches!(k.config.preconditioner, Multigrid | LaggedMultigrid)
                    .then_some(k.multigrid_counts)
            }),
        }
    }

    /// The Newmark accelerations, the counts and what the step's terms carry.
    /// The lagged_direct preconditioner's factorization is not saved: a
    /// restarted solver factorizes afresh at its first Krylov solve
    /// (docs/robustness.md).
    fn state(&self) -> SolverState {
        let krylov = self.newton.krylov();
        let mut state = SolverState {
            acceleration: self.accel.iter().flat_map(|a| a.iter().copied()).collect(),
            newton_iterations: self.newton.iterations,
            cutbacks: self.cutbacks,
            krylov_iterations: self.newton.krylov_iterations(),
            lagged_factorizations: krylov.map_or(0, |k| k.factorizations),
            direct: self
                .direct_solver()
                .map_or_else(Default::default, |d| d.statistics()),
            contact_tangential: Vec::new(),
            contact_points: Vec::new(),
            multigrid: krylov.map_or_else(Default::default, |k| k.multigrid_counts),
        };
        self.system.save_terms(&mut state);
        state
    }

    fn restore(&mut self, s: &SolverState) {
        self.accel = (s.acceleration.chunks_exact(D))
            .map(Vector::<D>::from_column_slice)
            .collect();
        self.newton.iterations = s.newton_iterations;
        self.cutbacks = s.cutbacks;
        self.restored = Some(s.clone());
        match &mut self.newton.linear {
            newton::Linear::Krylov(k) => {
                k.iterations = s.krylov_iterations;
                k.factorizations = s.lagged_factorizations;
                k.multigrid_counts = s.multigrid;
                k.lagged.restore_statistics(s.direct);
            }
            newton::Linear::Direct(d) => d.restore_statistics(s.direct),
        }
    }
}
