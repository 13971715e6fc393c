//! The optional terms of the implicit step: what adds to the residual r(u)
//! (2-37) and the tangent K = ∂r/∂u (2-40) besides the particles' stresses,
//! the inertia and the applied loads. Each enters through [`StepTerm`]:
//!
//! - [`absorbing`]: the dashpots and springs of absorbing faces (2-63);
//! - [`linear_stress`]: a stress linear within each particle domain (part of
//!   the internal force);
//! - [`contact`]: penalty contact with rigid bodies and between deformable
//!   bodies.
//!
//! [`list`] is the one place that names them all, in the order they add into r
//! and K; the Newton loop, the residual, the tangent and the step's set-up and
//! commit (`super::step`) go through the trait only. What contact does to the
//! grid itself (rigid bodies' particles left off, deformable bodies on nodes of
//! their own) is not a term: the step's grid is `super::grid::StepGrid`, which
//! the terms read.
//!
//! **The iterate.** The tangent, the commit and the reports are taken at the
//! step's iterate: the u of the last `residual` call (`super::residual`), which
//! evaluates the particles' trial state there (`StepSystem::trial`) and every
//! term's state ([`StepTerm::evaluate`]) and keeps both. A residual anywhere
//! else, the finite-difference products of the Krylov solver (2-39,
//! `residual::probe_residual`), goes through [`StepTerm::probe`] and the trial
//! state's `probe`: nothing of the step changes. A term therefore keeps the
//! state of its last `evaluate` (contacts, gaps, slip) and reads only that in
//! `add_tangent`, `commit` and the reports, as the particles' stiffness reads
//! only the trial state.
//!
//! **Blocks.** A node carries the components the problem gives it
//! (`assembly::Dofs::per_node`: the D displacements 0..D, then any scalar
//! fields), and the pattern couples all of them between two coupled nodes. A
//! term says which block of components it fills where it adds to K, with an
//! `assembly::Coupling` (first row and column component, R×C, full or
//! diagonal): `Pattern::add_terms` over the stencils, `Tangent::add_node_block`
//! for the node pairs of its [`Couplings`]. The terms here all fill the
//! displacements' D×D block (`Coupling::displacements`).
//!
//! **Unknowns of a term's own.** The step's unknowns are the displacements
//! today (`super::step::number_unknowns` numbers D components per node) and
//! the terms see the nodal displacement increments `&[Vector<D>]` and add
//! D-vectors per node to r. A term with unknowns of its own (a pore pressure
//! per node, D + 1 unknowns per node) enters once the step numbers D + 1
//! components per node (`Dofs::with_ties` with `[bool; D + 1]` fixity) and
//! its nodal vectors carry them: it reads its field beside u in `evaluate`
//! and `probe`, adds its rows to r there, and adds its blocks (K_pp, K_up,
//! K_pu) with their `Coupling` in `add_tangent`. The assembly, ties,
//! multigrid, direct solver and export already take the components per node
//! from `Dofs` (`assembly::tests`: a Biot-type system with D + 1 unknowns per
//! node, through the direct solver and multigrid-preconditioned GMRES).

pub(crate) mod absorbing;
pub(crate) mod contact;
pub(crate) mod linear_stress;
pub(crate) mod list;

use super::assembly::stiffness::ParticleTangents;
use super::assembly::{Dofs, Tangent};
use super::grid::StepGrid;
use super::newmark::Newmark;
use super::stress_gradient::LeastSquares;
use crate::dim::{Mat3, Vector};
use crate::model::Model;
use crate::physics::contact::totals::PairTotal;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::NodeMap;
use crate::solver::stepper::SolverState;
use std::fmt::Debug;

/// The step as a term sees it: the model at the step start, the shape
/// functions at the step-start positions, the active nodes and the unknowns.
#[derive(Clone, Copy)]
pub struct StepView<'a, const D: usize> {
    pub m: &'a Model<D>,
    pub stencils: &'a Stencils<D>,
    pub map: &'a NodeMap,
    pub dofs: &'a Dofs,
    pub grid: &'a StepGrid,
    /// The step t → t + dt.
    pub t: f64,
    pub dt: f64,
}

/// What a term needs besides the [`StepView`] to set up a step.
pub struct StepStart<'a, const D: usize> {
    pub shape: ShapeFunction,
    /// Newmark's coefficients (None when quasi-static).
    pub newmark: Option<&'a Newmark>,
    /// The Newmark predictor ũ (2-36) and the nodal accelerations at the step
    /// start, per active node (zero when quasi-static).
    pub u_tilde: &'a [Vector<D>],
    pub a_n: &'a [Vector<D>],
}

/// What a term couples in the tangent beyond the nodes of each particle's
/// stencil (`assembly::Pattern`): whole nodes, every component of one with
/// every component of the other (the term fills its block of them,
/// `Tangent::add_node_block`).
#[derive(Clone, Debug)]
pub struct Couplings<'a, const D: usize> {
    /// Pairs of active nodes (a < b) the term couples directly.
    pub node_pairs: Vec<(u32, u32)>,
    /// Particles whose stiffness has the nodes of other particles' stencils as
    /// rows: their least-squares neighbours (a linear domain stress,
    /// `Pattern::add_listed_terms`). The pattern holds one such relation: at
    /// most one term of a step lists neighbours.
    pub neighbours: Option<&'a LeastSquares<D>>,
}

impl<const D: usize> Default for Couplings<'_, D> {
    fn default() -> Self {
        Couplings {
            node_pairs: Vec::new(),
            neighbours: None,
        }
    }
}

/// What the terms report beside the solver's counts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TermReport {
    /// summary.json's `contact_penetration`: the deepest penalty depth of a
    /// converged step so far (None without contact).
    pub contact_penetration: Option<f64>,
    /// Contacts sticking and slipping at the iterate.
    pub sticking: usize,
    pub slipping: usize,
}

impl TermReport {
    /// Take `depth` into `contact_penetration` (the deepest of the terms).
    pub fn penetration(&mut self, depth: f64) {
        let deepest = self.contact_penetration.map_or(depth, |d| d.max(depth));
        self.contact_penetration = Some(deepest);
    }

    /// Count the contacts that slip and those that stick.
    pub fn contacts(&mut self, slips: impl Iterator<Item = bool>) {
        for slip in slips {
            match slip {
                true => self.slipping += 1,
                false => self.sticking += 1,
            }
        }
    }
}

/// A checkpoint's solver state read back by the terms, in the order of the
/// step's terms (the order they wrote it in, [`StepTerm::save`]): each takes
/// its part of `SolverState::contact_tangential` after the parts of the terms
/// before it.
pub struct Restore<'a> {
    pub state: &'a SolverState,
    /// Values of `contact_tangential` taken by the terms before.
    taken: usize,
}

impl<'a> Restore<'a> {
    pub fn new(state: &'a SolverState) -> Self {
        Restore { state, taken: 0 }
    }

    /// The next `n` values of `contact_tangential`, or None if fewer are left
    /// or the checkpoint has none at all (the terms after then get none
    /// either: the state does not belong to these terms).
    pub fn take_tangential(&mut self, n: usize) -> Option<&'a [f64]> {
        let all = &self.state.contact_tangential;
        let rest = &all[self.taken.min(all.len())..];
        if all.is_empty() || rest.len() < n {
            self.taken = all.len();
            return None;
        }
        self.taken += n;
        Some(&rest[..n])
    }

    /// The values of `contact_tangential` not taken yet, taken.
    pub fn rest_tangential(&mut self) -> &'a [f64] {
        let all = &self.state.contact_tangential;
        let rest = &all[self.taken.min(all.len())..];
        self.taken = all.len();
        rest
    }
}

/// A term of the implicit step's residual and tangent (module docs: the
/// iterate, and unknowns of a term's own). The hooks follow the step:
/// `begin_step` once the step's stencils, unknowns and predictor exist;
/// `couplings` for the tangent's pattern; `evaluate` or `probe` inside every
/// residual; `add_tangent` at the iterate; `commit` with the converged
/// increment; `save` and `restore` for checkpoints; the reports at any time.
pub trait StepTerm<const D: usize>: Debug + Send + Sync {
    /// What the term is, for messages and tests.
    fn name(&self) -> &'static str;

    /// A copy of the term (a step system is cloned whole, terms included).
    fn cloned(&self) -> Box<dyn StepTerm<D>>;

    /// Newmark's first step: the term's force at the initial state, with the
    /// nodal velocities v at time t (M a₀ = f), added into `force`. Called
    /// before the first step begins.
    fn add_initial_force(
        &self,
        _m: &Model<D>,
        _st: &Stencils<D>,
        _map: &NodeMap,
        _v: &[Vector<D>],
        _t: f64,
        _force: &mut [Vector<D>],
    ) {
    }

    /// Set up the step (what does not depend on the iterate).
    fn begin_step(&mut self, step: &StepView<'_, D>, start: &StepStart<'_, D>);

    /// What the term couples in the tangent beyond the stencils (its state of
    /// this step; `begin_step` has run).
    fn couplings(&self) -> Couplings<'_, D> {
        Couplings::default()
    }

    /// A part of the internal force (a term of the stress itself, like the
    /// linear domain stress), from the particles' stress measure `pk1` at u
    /// (`internal_force`'s), added into f_int before the inertia and the
    /// external force join it. Stateless.
    fn add_internal_force(&self, _step: &StepView<'_, D>, _pk1: &[Mat3], _f_int: &mut [Vector<D>]) {
    }

    /// At the iterate u: keep the term's state at u (what `add_tangent`,
    /// `commit` and the reports read) and add its part of r(u) to `r`. A term
    /// without state only probes.
    fn evaluate(&mut self, step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        self.probe(step, u, r);
    }

    /// Its part of r(u) at a u that is not the iterate (a difference
    /// product), added to `r`; nothing is kept.
    fn probe(&self, step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]);

    /// The round-off the term leaves in ‖r‖ at the iterate, below which Newton
    /// cannot go (the floors of several terms add in quadrature).
    fn residual_floor(&self) -> f64 {
        0.0
    }

    /// Its part of K = ∂r/∂u at the iterate, added to `k` (`a`: the particles'
    /// tangents ∂P/∂ΔF there).
    fn add_tangent(&self, step: &StepView<'_, D>, a: &ParticleTangents<D>, k: &mut Tangent);

    /// Whether its part of K at the iterate is symmetric.
    fn symmetric(&self) -> bool {
        true
    }

    /// The particles' displacements over the step with the converged
    /// increment u, where the term moves them otherwise than by Σ_I S_Ip u_I
    /// (None: it does not). At most one term of a step moves the particles.
    fn particle_displacements(
        &self,
        _step: &StepView<'_, D>,
        _u: &[Vector<D>],
    ) -> Option<Vec<Vector<D>>> {
        None
    }

    /// The converged step (at the iterate, u): keep what the term carries to
    /// the next step. The view is the step-start model, before the particles
    /// take the step's state.
    fn commit(&mut self, _step: &StepView<'_, D>, _u: &[Vector<D>]) {}

    /// What it carries to the next step, appended to the checkpoint's state.
    fn save(&self, _state: &mut SolverState) {}

    /// Continue from a checkpoint (before the first step of the restarted run).
    fn restore(&mut self, _from: &mut Restore<'_>) {}

    /// Add its part to `report`.
    fn report(&self, _report: &mut TermReport) {}

    /// contact.csv: what it did per pair of velocity fields since the last
    /// call, added into `totals` (one per pair, `totals::pair_totals`; an empty
    /// `totals` takes the term's own), then forgotten.
    fn take_pair_totals(&mut self, _totals: &mut Vec<PairTotal<D>>) {}

    /// particles_final.csv: its contact force on each particle at the iterate,
    /// added into `forces` (one per particle); whether it has such forces (the
    /// file's `contact_f*` columns).
    fn add_particle_forces(&self, _forces: &mut [Vector<D>]) -> bool {
        false
    }
}

impl<const D: usize> Clone for Box<dyn StepTerm<D>> {
    fn clone(&self) -> Self {
        self.cloned()
    }
}
