//! One implicit step around its Newton iteration (thesis §2.2.2).
//!
//! [`StepSettings::prepare`] sets up everything of the step t → t + Δt that does
//! not depend on the iterate: the step's grid at the step-start positions
//! (updated Lagrangian; `super::grid`), the conditions and unknowns of the active
//! nodes (weakly supported nodes tied to their neighbours and the natural end
//! condition of cubic B-splines at faces with prescribed velocities,
//! `super::ties`), the lumped mass, the external force at t + Δt, the Newmark
//! predictor ũ (2-36), and then every optional term of the step
//! (`super::terms`). Quasi-static steps scale gravity and loads with the load
//! factor λ = (t − t_start) / duration and have no inertia. Newmark starts from
//! the particle accelerations of M a = f_ext − f_int at the first step.
//! [`StepSettings::commit`] makes the converged increment the particles' state.

use super::assembly::{Dofs, Pattern};
use super::grid::StepGrid;
use super::newmark::Newmark;
use super::terms::list::step_terms;
use super::terms::{Couplings, Restore, StepStart, StepTerm, StepView, TermReport};
use super::ties::{merge, natural_end_ties, nodal_support, ties, NodeFields};
use crate::dim::Vector;
use crate::model::conditions::{Constraint, FaceCondition, FrictionFace};
use crate::model::loads::LoadTime;
use crate::model::{load_factor, Model};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::boundary::conditions::implicit_node_constraint;
use crate::physics::contact::totals::PairTotal;
use crate::physics::kinematics::deformation::Trial;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::{
    applied_force, external_force, interpolate, mass_average, mass_momentum, mass_weighted,
    nodal_force, NodeMap,
};
use crate::scene::{DirectOrdering, Integrator, MassMatrix, SolverConfig};
use crate::solver::stepper::SolverState;
use rayon::prelude::*;
use std::sync::OnceLock;

/// How the steps of a stage are set up (scene [solver]).
#[derive(Clone, Debug)]
pub struct StepSettings {
    pub shape: ShapeFunction,
    pub integrator: Integrator,
    pub newmark: Newmark,
    /// Start and duration of the run or stage (quasi-static load factor).
    pub t_start: f64,
    pub end_time: f64,
    /// Quasi-static: gravity ramps with the load factor (else it is in full).
    pub gravity_ramp: bool,
    /// Quasi-static: the loads without a time history ramp with the load
    /// factor (else they are in full: a stage that changes the model,
    /// `SolverConfig::changes_model`, finds them applied already).
    pub ramp_loads: bool,
    /// Newmark: gravity rises linearly from zero over this time on the run's
    /// clock (`gravity_ramp_time`; 0: in full from the start).
    pub gravity_ramp_time: LoadTime,
    /// Nodes with less particle support (cells) are tied to their neighbours.
    pub min_node_support: f64,
    /// F-bar against volumetric locking (`crate::physics::kinematics::fbar`).
    pub fbar: bool,
    /// The direct solver's fill-reducing ordering.
    pub direct_ordering: DirectOrdering,
}

/// One step's nonlinear system r(u) = 0 (2-37): the parts that do not depend on
/// the iterate u, and the evaluation at the iterate, the u of the last
/// `residual` call (`StepSystem::iterate`): the particles' trial state there
/// and every term's state (`super::terms`, the rule). The solver keeps it
/// between steps so that the stencils, the node map, the trial state and the
/// terms reuse their buffers and carry their state; the rest is set anew by
/// `prepare`.
#[derive(Clone, Debug)]
pub struct StepSystem<const D: usize> {
    /// The step t → t + dt.
    pub t: f64,
    pub dt: f64,
    /// Shape functions at the step-start positions and the active nodes.
    pub stencils: Stencils<D>,
    pub map: NodeMap,
    pub constraint: Vec<Constraint<D>>,
    pub dofs: Dofs,
    /// Lumped nodal mass.
    pub mass: Vec<f64>,
    /// The mass matrix of the inertial force (lumped or consistent).
    pub mass_matrix: MassMatrix,
    /// External force at the end of the step.
    pub f_ext: Vec<Vector<D>>,
    /// Nodal acceleration at the step start (Newmark; zero otherwise).
    pub a_n: Vec<Vector<D>>,
    /// Newmark predictor ũ (zero when quasi-static).
    pub u_tilde: Vec<Vector<D>>,
    /// 1/(βΔt²), or 0 when quasi-static.
    pub inertia: f64,
    /// Load factors at the end of the step: gravity, and each load ramp.
    pub g_new: f64,
    pub scales_new: Vec<f64>,
    /// The particles' state at the iterate.
    pub trial: Trial<D>,
    /// The fill-reducing ordering of the direct factorizations.
    pub direct_ordering: DirectOrdering,
    /// The tangent's sparsity pattern (built at the step's first assembly, kept
    /// for the next step if it fits).
    pub pattern: OnceLock<Pattern>,
    /// Which particles the step's grid carries and which nodes the bodies
    /// share (set up with the terms).
    pub grid: StepGrid,
    /// The optional terms of r and K, in the order they add in (set up at the
    /// first `prepare`, `terms::list`).
    pub terms: Vec<Box<dyn StepTerm<D>>>,
    /// Whether the grid and the terms are set up.
    set_up: bool,
}

impl<const D: usize> StepSystem<D> {
    /// An empty system, filled by [`StepSettings::prepare`].
    pub fn new(mass_matrix: MassMatrix) -> Self {
        StepSystem {
            t: 0.0,
            dt: 0.0,
            stencils: Stencils::default(),
            map: NodeMap::default(),
            constraint: Vec::new(),
            dofs: Dofs::default(),
            mass: Vec::new(),
            mass_matrix,
            f_ext: Vec::new(),
            a_n: Vec::new(),
            u_tilde: Vec::new(),
            inertia: 0.0,
            g_new: 0.0,
            scales_new: Vec::new(),
            trial: Trial::default(),
            direct_ordering: DirectOrdering::Auto,
            pattern: OnceLock::new(),
            grid: StepGrid::default(),
            terms: Vec::new(),
            set_up: false,
        }
    }

    /// Set up the step's grid and terms for model m, once.
    pub fn set_up(&mut self, m: &Model<D>) {
        if !self.set_up {
            (self.grid, self.terms) = step_terms(m);
            self.set_up = true;
        }
    }

    /// The step as the terms see it.
    pub fn view<'a>(&'a self, m: &'a Model<D>) -> StepView<'a, D> {
        StepView {
            m,
            stencils: &self.stencils,
            map: &self.map,
            dofs: &self.dofs,
            grid: &self.grid,
            t: self.t,
            dt: self.dt,
        }
    }

    /// `f` on every term, in order, with the step's view (the terms taken out
    /// of the system while the view borrows it).
    pub fn for_each_term(
        &mut self,
        m: &Model<D>,
        mut f: impl FnMut(&StepView<'_, D>, &mut dyn StepTerm<D>),
    ) {
        let mut terms = std::mem::take(&mut self.terms);
        let step = self.view(m);
        for t in terms.iter_mut() {
            f(&step, t.as_mut());
        }
        self.terms = terms;
    }

    /// The iterate: the nodal displacement increments u of the last
    /// `residual` call, at which the trial state and the terms' states are.
    pub fn iterate(&self) -> &[Vector<D>] {
        self.trial.displacements()
    }

    /// What the terms couple beyond the stencils, together.
    pub fn couplings(&self) -> Couplings<'_, D> {
        let mut all = Couplings::default();
        for c in self.terms.iter().map(|t| t.couplings()) {
            all.node_pairs.extend(c.node_pairs);
            if let Some(n) = c.neighbours {
                assert!(all.neighbours.is_none(), "two terms with neighbour lists");
                all.neighbours = Some(n);
            }
        }
        all
    }

    /// The round-off floor of ‖r‖ at the iterate: the terms' in quadrature.
    pub fn residual_floor(&self) -> f64 {
        (self.terms.iter()).fold(0.0, |floor, t| floor.hypot(t.residual_floor()))
    }

    /// What the terms report.
    pub fn report(&self) -> TermReport {
        let mut report = TermReport::default();
        self.terms.iter().for_each(|t| t.report(&mut report));
        report
    }

    /// The terms' pair totals since the last call (contact.csv; empty
    /// without contact).
    pub fn take_pair_totals(&mut self) -> Vec<PairTotal<D>> {
        let mut totals = Vec::new();
        (self.terms.iter_mut()).for_each(|t| t.take_pair_totals(&mut totals));
        totals
    }

    /// The terms' contact force on each of `n` particles at the iterate, if
    /// any term has such forces.
    pub fn particle_forces(&self, n: usize) -> Option<Vec<Vector<D>>> {
        let mut forces = vec![Vector::<D>::zeros(); n];
        let any =
            (self.terms.iter()).fold(false, |any, t| t.add_particle_forces(&mut forces) | any);
        any.then_some(forces)
    }

    /// What the terms carry across steps, into a checkpoint's `state`.
    pub fn save_terms(&self, state: &mut SolverState) {
        self.terms.iter().for_each(|t| t.save(state));
    }

    /// Continue the terms from a checkpoint's `state` (after `set_up`).
    pub fn restore_terms(&mut self, state: &SolverState) {
        let mut from = Restore::new(state);
        self.terms.iter_mut().for_each(|t| t.restore(&mut from));
    }
}

impl StepSettings {
    /// The settings of a run or stage that starts at time `t_start`.
    pub fn new(shape: ShapeFunction, s: &SolverConfig, t_start: f64) -> Self {
        StepSettings {
            shape,
            integrator: s.integrator(),
            newmark: Newmark {
                beta: s.beta(),
                gamma: s.gamma(),
            },
            t_start,
            end_time: s.end_time,
            gravity_ramp: s.gravity_ramp(),
            ramp_loads: !s.changes_model(),
            gravity_ramp_time: LoadTime::Ramp(s.gravity_ramp_time()),
            min_node_support: s.min_node_support(),
            fbar: s.fbar(),
            direct_ordering: s.direct_ordering(),
        }
    }

    fn dynamic(&self) -> bool {
        self.integrator == Integrator::Newmark
    }

    /// Load factor of gravity and loads at time t: (t − t_start) / duration when
    /// quasi-static, otherwise the gravity ramp's factor (1 without one) and
    /// the ramp of each load. A time history (`gravity_history`, a load's
    /// `time_history`) gives its own factor at t in both.
    pub fn load_factors<const D: usize>(&self, m: &Model<D>, t: f64) -> (f64, Vec<f64>) {
        match self.integrator {
            Integrator::QuasiStatic => {
                let lambda = ((t - self.t_start) / self.end_time).clamp(0.0, 1.0);
                let g = match (&m.gravity_history, self.gravity_ramp) {
                    (Some(h), _) => h.factor(t),
                    (None, true) => lambda,
                    (None, false) => 1.0,
                };
                let scales = (m.load_ramps.iter())
                    .map(|r| match (r.is_curve(), self.ramp_loads) {
                        (true, _) => r.factor(t),
                        (false, true) => lambda,
                        (false, false) => 1.0,
                    })
                    .collect();
                (g, scales)
            }
            Integrator::Newmark => (
                m.gravity_factor(t, &self.gravity_ramp_time),
                m.load_scales(t),
            ),
        }
    }

    /// Fill `sys` for the step t → t + dt. `accel` holds the particle
    /// accelerations (Newmark), computed here at the first step.
    pub fn prepare<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &mut StepSystem<D>,
        accel: &mut Vec<Vector<D>>,
        t: f64,
        dt: f64,
    ) {
        let p = &m.particles;
        sys.set_up(m);
        sys.grid
            .build(m, self.shape, &mut sys.stencils, &mut sys.map);
        if self.fbar {
            sys.trial.use_fbar(&m.grid, &p.x);
        }
        if self.dynamic() && accel.len() != p.len() {
            *accel = self.initial_acceleration(m, sys);
        }
        let (st, map) = (&sys.stencils, &sys.map);
        let fields = sys.grid.node_fields();
        let (faces, walls) = (m.faces_during(t, dt), m.walls_during(t, dt));
        let (constraint, dofs) =
            number_unknowns(m, &faces, &walls, st, map, fields, self.min_node_support);
        let n = map.len();

        // External force at the end of the step; inertia terms: the Newmark
        // predictor ũ (2-36) from the projected velocities and accelerations.
        let (g_new, scales_new) = self.load_factors(m, t + dt);
        let load_new = |q: usize| load_factor(&m.load_ramp_of, q, &scales_new);
        let f_ext = external_force(map, st, p, &(m.gravity * g_new), &load_new);
        let (mass, momentum) = mass_momentum(map, st, p, None);
        let nodal = |w: &[f64], a: usize| if w[a] > 0.0 { 1.0 / w[a] } else { 0.0 };
        let (a_n, u_tilde) = if self.dynamic() {
            let am = mass_weighted(map, st, p, accel.as_slice());
            // Prescribed components move at their value with no acceleration; the
            // projection from nearby particles must not leak into them (with
            // β < 1/4 such a leak grows by (½ − β)/β every step).
            let mut v: Vec<Vector<D>> = (0..n).map(|a| momentum[a] * nodal(&mass, a)).collect();
            let mut acc: Vec<Vector<D>> = (0..n).map(|a| am[a] * nodal(&mass, a)).collect();
            for a in 0..n {
                constraint[a].apply_velocity(&mut v[a]);
                constraint[a].apply_rate(&mut acc[a]);
            }
            let ut = (0..n)
                .map(|a| self.newmark.predictor(dt, &v[a], &acc[a]))
                .collect();
            (acc, ut)
        } else {
            (vec![Vector::<D>::zeros(); n], vec![Vector::<D>::zeros(); n])
        };
        sys.inertia = if self.dynamic() {
            self.newmark.inertia(dt)
        } else {
            0.0
        };
        sys.t = t;
        sys.dt = dt;
        sys.constraint = constraint;
        sys.dofs = dofs;
        sys.direct_ordering = self.direct_ordering;
        sys.mass = mass;
        sys.f_ext = f_ext;
        sys.a_n = a_n;
        sys.u_tilde = u_tilde;
        sys.g_new = g_new;
        sys.scales_new = scales_new;
        self.begin_terms(m, sys);
        // The previous step's pattern, ordering and (in the direct solver) symbolic
        // factorization serve again when no stencil, constraint, tie or coupling
        // changed.
        let last = std::mem::take(&mut sys.pattern).into_inner();
        let cells = sys.trial.fbar.as_ref().map(|f| &f.cells);
        let couplings = sys.couplings();
        let (st, dofs, neighbours) = (&sys.stencils, &sys.dofs, couplings.neighbours);
        let kept =
            last.filter(|pattern| pattern.fits(st, dofs, cells, neighbours, &couplings.node_pairs));
        if let Some(pattern) = kept {
            let _ = sys.pattern.set(pattern);
        }
    }

    /// Begin every term of the step (its stencils, unknowns and predictor are
    /// set).
    fn begin_terms<const D: usize>(&self, m: &Model<D>, sys: &mut StepSystem<D>) {
        let mut terms = std::mem::take(&mut sys.terms);
        let step = sys.view(m);
        let start = StepStart {
            shape: self.shape,
            newmark: self.dynamic().then_some(&self.newmark),
            u_tilde: &sys.u_tilde,
            a_n: &sys.a_n,
        };
        terms.iter_mut().for_each(|t| t.begin_step(&step, &start));
        sys.terms = terms;
    }

    /// The particles' displacements over the step: Σ_I S_Ip u_I, or as a term
    /// moves them (a linear domain stress).
    fn particle_displacements<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &StepSystem<D>,
        u: &[Vector<D>],
    ) -> Vec<Vector<D>> {
        let step = sys.view(m);
        if let Some(dx) = (sys.terms.iter()).find_map(|t| t.particle_displacements(&step, u)) {
            return dx;
        }
        let (map, st) = (&sys.map, &sys.stencils);
        (0..m.particles.len())
            .into_par_iter()
            .with_min_len(crate::parallel::MIN_PARALLEL_LEN)
            .map(|q| interpolate(map, st, q, u))
            .collect()
    }

    /// Particle accelerations at t = 0 from M a = f_ext − f_int (lumped).
    fn initial_acceleration<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &StepSystem<D>,
    ) -> Vec<Vector<D>> {
        let (p, st, map) = (&m.particles, &sys.stencils, &sys.map);
        let (g, scales) = self.load_factors(m, self.t_start);
        let load = |q: usize| load_factor(&m.load_ramp_of, q, &scales);
        let mut force = nodal_force(map, st, p, &(m.gravity * g), &load);
        let (mass, momentum) = mass_momentum(map, st, p, None);
        let v = mass_average(&mass, &momentum);
        for t in &sys.terms {
            t.add_initial_force(m, st, map, &v, self.t_start, &mut force);
        }
        let a: Vec<Vector<D>> = force
            .iter()
            .zip(&mass)
            .map(|(f, m)| if *m > 0.0 { f / *m } else { f * 0.0 })
            .collect();
        (0..p.len()).map(|q| interpolate(map, st, q, &a)).collect()
    }

    /// Make the converged increment u the particles' state: the stresses of the
    /// converged iterate (`StepSystem::iterate`, which is u), positions, the
    /// terms' carried state, and the Newmark update of velocities and
    /// accelerations. Returns the work of gravity and applied loads over the
    /// step.
    pub fn commit<const D: usize>(
        &self,
        m: &mut Model<D>,
        sys: &mut StepSystem<D>,
        u: &[Vector<D>],
        accel: &mut [Vector<D>],
    ) -> f64 {
        debug_assert!(sys.iterate() == u, "the converged u is the iterate");
        let dt = sys.dt;
        let dx = self.particle_displacements(m, sys, u);
        // The terms keep what they carry, seeing the step-start model.
        sys.for_each_term(m, |step, t| t.commit(step, u));
        let (g_old, scales_old) = self.load_factors(m, sys.t);
        let load_old = |q: usize| load_factor(&m.load_ramp_of, q, &scales_old);
        let load_new = |q: usize| load_factor(&m.load_ramp_of, q, &sys.scales_new);
        let p = &mut m.particles;
        sys.trial.commit(p, &sys.stencils, &sys.map);
        let (map, st) = (&sys.map, &sys.stencils);
        let work: f64 = (0..p.len())
            .map(|q| {
                let f_old = applied_force(p, q, &(m.gravity * g_old), &load_old);
                let f_new = applied_force(p, q, &(m.gravity * sys.g_new), &load_new);
                (f_old + f_new).dot(&dx[q]) * 0.5
            })
            .sum();
        for (x, d) in p.x.iter_mut().zip(&dx) {
            *x += d;
        }
        if self.dynamic() {
            let n = map.len();
            let (u_tilde, a_n) = (&sys.u_tilde, &sys.a_n);
            let a_new: Vec<Vector<D>> = (0..n)
                .map(|a| self.newmark.acceleration(dt, &u[a], &u_tilde[a]))
                .collect();
            let dv: Vec<Vector<D>> = (0..n)
                .map(|a| self.newmark.velocity_increment(dt, &a_n[a], &a_new[a]))
                .collect();
            // FLIP-style increments for both: the particles keep what the grid
            // cannot represent, and the grid's Newmark update is not re-projected.
            let da: Vec<Vector<D>> = (0..n).map(|a| a_new[a] - a_n[a]).collect();
            for (q, a_q) in accel.iter_mut().enumerate() {
                p.v[q] += interpolate(map, st, q, &dv);
                *a_q += interpolate(map, st, q, &da);
            }
        }
        sys.grid.advance_off_grid(m, dt);
        work
    }
}

/// The conditions at the active nodes and the numbering of the unknowns: the
/// free components, weakly supported nodes tied to their neighbours.
pub fn number_unknowns<const D: usize>(
    m: &Model<D>,
    faces: &[FaceCondition<D>],
    walls: &[FrictionFace<D>],
    st: &Stencils<D>,
    map: &NodeMap,
    fields: Option<&NodeFields>,
    min_node_support: f64,
) -> (Vec<Constraint<D>>, Dofs) {
    let constraint: Vec<Constraint<D>> = map
        .active
        .par_iter()
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|(a, _)| implicit_node_constraint(&m.grid, faces, walls, map.grid_node(a)))
        .collect();
    let support = nodal_support(map, st, &m.particles.volume, m.grid.cell_volume());
    let fixed: Vec<[bool; D]> = constraint.iter().map(|c| c.fixed).collect();
    let weak = ties(&m.grid, map, fields, &support, &fixed, min_node_support);
    let natural = natural_end_ties(&m.grid, &m.faces, map, fields);
    let ties = merge(weak, natural, map.len());
    let dofs = Dofs::with_ties(fixed.into_iter(), ties);
    (constraint, dofs)
}
