//! One implicit step around its Newton iteration (thesis §2.2.2).
//!
//! [`StepSettings::prepare`] sets up everything of the step t → t + Δt that does
//! not depend on the iterate: the shape functions at the step-start positions
//! (updated Lagrangian), the conditions and unknowns of the active nodes (weakly
//! supported nodes tied to their neighbours and the natural end condition of cubic
//! B-splines at faces with prescribed velocities, `super::ties`), the lumped mass, the
//! external force at t + Δt, the Newmark predictor ũ (2-36) and the absorbing
//! faces of the step. Quasi-static steps scale gravity and loads with the load
//! factor λ = (t − t_start) / duration and have no inertia. Newmark starts from
//! the particle accelerations of M a = f_ext − f_int at the first step.
//! [`StepSettings::commit`] makes the converged increment the particles' state.

use super::assembly::{Dofs, Pattern};
use super::contact::PenaltyContact;
use super::newmark::Newmark;
use super::ties::{merge, natural_end_ties, nodal_support, ties};
use crate::dim::Vector;
use crate::model::conditions::Constraint;
use crate::model::loads::LoadTime;
use crate::model::{load_factor, Model};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::boundary::absorbing::{self, AbsorbingStep};
use crate::physics::boundary::conditions::implicit_node_constraint;
use crate::physics::kinematics::deformation::Trial;
use crate::physics::shape::{domain_corner_mean, ShapeFunction, Stencils};
use crate::physics::transfer::{
    applied_force, external_force, interpolate, mass_average, mass_momentum, mass_weighted,
    nodal_force, stencils, NodeMap,
};
use crate::scene::{DirectOrdering, Integrator, MassMatrix, SolverConfig};
use crate::solver::implicit::stress_gradient::LinearStress;
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
/// the iterate u, and the particles' trial state at the latest iterate (which
/// the residual evaluates). The solver keeps it between steps so that the
/// stencils, the node map and the trial state reuse their buffers; the rest is
/// set anew by `prepare`.
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
    /// Absorbing faces within the step (empty when the scene has none).
    pub absorbing: AbsorbingStep<D>,
    /// Load factors at the end of the step: gravity, and each load ramp.
    pub g_new: f64,
    pub scales_new: Vec<f64>,
    /// The particles' state at the latest iterate.
    pub trial: Trial<D>,
    /// The fill-reducing ordering of the direct factorizations.
    pub direct_ordering: DirectOrdering,
    /// The tangent's sparsity pattern (built at the step's first assembly, kept
    /// for the next step if it fits).
    pub pattern: OnceLock<Pattern>,
    /// Contact with rigid bodies (None in a scene without).
    pub contact: Option<PenaltyContact<D>>,
    /// The linear domain stress of the step-start configuration (None unless
    /// `[grid] domain_stress = "linear"`).
    pub linear_stress: Option<LinearStress<D>>,
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
            absorbing: AbsorbingStep::default(),
            g_new: 0.0,
            scales_new: Vec::new(),
            trial: Trial::default(),
            direct_ordering: DirectOrdering::Auto,
            pattern: OnceLock::new(),
            contact: None,
            linear_stress: None,
        }
    }

    /// The contact of model m, set up on first use (None in a scene without).
    pub fn contact_of(&mut self, m: &Model<D>) -> Option<&mut PenaltyContact<D>> {
        if self.contact.is_none() && m.contact.is_some() {
            self.contact = PenaltyContact::new(m);
        }
        self.contact.as_mut()
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
    /// the ramp of each load.
    pub fn load_factors<const D: usize>(&self, m: &Model<D>, t: f64) -> (f64, Vec<f64>) {
        match self.integrator {
            Integrator::QuasiStatic => {
                let lambda = ((t - self.t_start) / self.end_time).clamp(0.0, 1.0);
                let g = if self.gravity_ramp { lambda } else { 1.0 };
                (g, vec![lambda; m.load_ramps.len()])
            }
            Integrator::Newmark => (self.gravity_ramp_time.factor(t), m.load_scales(t)),
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
        sys.contact_of(m);
        let contact = sys.contact.as_mut();
        step_stencils(m, self.shape, contact, &mut sys.stencils, &mut sys.map);
        if let Some(contact) = sys.contact.as_mut() {
            contact.start_step(m, self.shape, &sys.stencils, &sys.map, dt);
        }
        if self.fbar {
            sys.trial.use_fbar(&m.grid, &p.x);
        }
        if self.dynamic() && accel.len() != p.len() {
            *accel = self.initial_acceleration(m, &sys.stencils, &sys.map);
        }
        sys.linear_stress = m
            .linear_domain_stress
            .then(|| LinearStress::new(self.shape, &m.grid, p, &sys.stencils));
        let (st, map) = (&sys.stencils, &sys.map);
        let contact = sys.contact.as_ref();
        let (constraint, dofs) = number_unknowns(m, st, map, contact, self.min_node_support);
        if let Some(contact) = sys.contact.as_mut() {
            contact.drop_tied_meetings(&dofs);
        }
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
        sys.absorbing = self.absorbing_step(m, &u_tilde, &a_n, dt);
        sys.inertia = if self.dynamic() {
            self.newmark.inertia(dt)
        } else {
            0.0
        };
        sys.t = t;
        sys.dt = dt;
        sys.constraint = constraint;
        // The previous step's pattern, ordering and (in the direct solver) symbolic
        // factorization serve again when no stencil, constraint or tie changed.
        let cells = sys.trial.fbar.as_ref().map(|f| &f.cells);
        let fit = sys.linear_stress.as_ref().map(|l| &l.fit);
        let coupled = (sys.contact.as_ref()).map_or_else(Vec::new, |c| c.coupled_nodes());
        let kept = std::mem::take(&mut sys.pattern)
            .into_inner()
            .filter(|pattern| pattern.fits(st, &dofs, cells, fit, &coupled));
        sys.pattern = OnceLock::new();
        if let Some(pattern) = kept {
            let _ = sys.pattern.set(pattern);
        }
        sys.dofs = dofs;
        sys.direct_ordering = self.direct_ordering;
        sys.mass = mass;
        sys.f_ext = f_ext;
        sys.a_n = a_n;
        sys.u_tilde = u_tilde;
        sys.g_new = g_new;
        sys.scales_new = scales_new;
    }

    /// The particles' displacements over the step: Σ_I S_Ip u_I; with a linear
    /// domain stress, the mean of u at the corners of the step-start domain,
    /// as CPDI moves its particles, so that the domains keep tiling the body
    /// (the domain average moves a domain's centre by δ²u''/24 off its
    /// corners' mean, which opens gaps and overlaps of O(h²) at the faces;
    /// docs/accuracy.md).
    fn particle_displacements<const D: usize>(
        &self,
        m: &Model<D>,
        sys: &StepSystem<D>,
        u: &[Vector<D>],
    ) -> Vec<Vector<D>> {
        let (p, map, st) = (&m.particles, &sys.map, &sys.stencils);
        (0..p.len())
            .into_par_iter()
            .with_min_len(crate::parallel::MIN_PARALLEL_LEN)
            .map(|q| match sys.linear_stress.is_some() && st.count[q] > 0 {
                false => interpolate(map, st, q, u),
                true => {
                    let value = |n: u32| u[map.local[n as usize] as usize];
                    let shape = self.shape;
                    domain_corner_mean(
                        shape,
                        &m.grid,
                        &p.x[q],
                        &p.half_length0[q],
                        &p.f.get(q),
                        value,
                    )
                    .expect("a linear domain stress on a box domain")
                }
            })
            .collect()
    }

    /// Particle accelerations at t = 0 from M a = f_ext − f_int (lumped).
    fn initial_acceleration<const D: usize>(
        &self,
        m: &Model<D>,
        st: &Stencils<D>,
        map: &NodeMap,
    ) -> Vec<Vector<D>> {
        let p = &m.particles;
        let (g, scales) = self.load_factors(m, self.t_start);
        let load = |q: usize| load_factor(&m.load_ramp_of, q, &scales);
        let mut force = nodal_force(map, st, p, &(m.gravity * g), &load);
        let (mass, momentum) = mass_momentum(map, st, p, None);
        let v = mass_average(&mass, &momentum);
        absorbing::add_force(&m.absorbing, &m.grid, p, map, st, &v, &mut force);
        let a: Vec<Vector<D>> = force
            .iter()
            .zip(&mass)
            .map(|(f, m)| if *m > 0.0 { f / *m } else { f * 0.0 })
            .collect();
        (0..p.len()).map(|q| interpolate(map, st, q, &a)).collect()
    }

    /// The absorbing faces of this step: layer particles at the step start, and
    /// their velocity as a function of u through Newmark (none when quasi-static).
    fn absorbing_step<const D: usize>(
        &self,
        m: &Model<D>,
        u_tilde: &[Vector<D>],
        a_n: &[Vector<D>],
        dt: f64,
    ) -> AbsorbingStep<D> {
        let layer = absorbing::layer(&m.absorbing, &m.grid, &m.particles);
        if layer.is_empty() {
            return AbsorbingStep::default();
        }
        let n = a_n.len();
        let nm = &self.newmark;
        let (velocity_offset, rate) = if self.dynamic() {
            (
                (0..n)
                    .map(|a| nm.end_velocity(dt, &Vector::<D>::zeros(), &u_tilde[a], &a_n[a]))
                    .collect(),
                nm.velocity_rate(dt),
            )
        } else {
            (vec![Vector::<D>::zeros(); n], 0.0)
        };
        AbsorbingStep {
            layer,
            velocity_offset,
            rate,
        }
    }

    /// Make the converged increment u the particles' state: the stresses of the
    /// converged iterate (the last residual evaluation), positions, and the Newmark
    /// update of velocities and accelerations. Returns the work of gravity and
    /// applied loads over the step.
    pub fn commit<const D: usize>(
        &self,
        m: &mut Model<D>,
        sys: &mut StepSystem<D>,
        u: &[Vector<D>],
        accel: &mut [Vector<D>],
    ) -> f64 {
        let dt = sys.dt;
        let (g_old, scales_old) = self.load_factors(m, sys.t);
        let load_old = |q: usize| load_factor(&m.load_ramp_of, q, &scales_old);
        let load_new = |q: usize| load_factor(&m.load_ramp_of, q, &sys.scales_new);
        let dx = self.particle_displacements(m, sys, u);
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
        if let Some(contact) = sys.contact.as_mut() {
            contact.commit(p, dt);
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
        work
    }
}

/// The particles' stencils at the step start and the active nodes they touch;
/// with contact, rigid bodies' particles stay off the grid and deformable
/// bodies in contact get nodes of their own (`PenaltyContact::stencils`).
pub fn step_stencils<const D: usize>(
    m: &Model<D>,
    shape: ShapeFunction,
    contact: Option<&mut PenaltyContact<D>>,
    st: &mut Stencils<D>,
    map: &mut NodeMap,
) {
    match contact {
        Some(contact) => contact.stencils(m, shape, st, map),
        None => {
            stencils(m, shape, st);
            map.build(st, m.grid.node_count());
        }
    }
}

/// The conditions at the active nodes and the numbering of the unknowns: the
/// free components, weakly supported nodes tied to their neighbours.
pub fn number_unknowns<const D: usize>(
    m: &Model<D>,
    st: &Stencils<D>,
    map: &NodeMap,
    contact: Option<&PenaltyContact<D>>,
    min_node_support: f64,
) -> (Vec<Constraint<D>>, Dofs) {
    let constraint: Vec<Constraint<D>> = map
        .active
        .par_iter()
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|(a, _)| implicit_node_constraint(&m.grid, &m.faces, &m.friction, map.grid_node(a)))
        .collect();
    let support = nodal_support(map, st, &m.particles.volume, m.grid.cell_volume());
    let fields = contact.and_then(|c| c.node_fields());
    let fixed: Vec<[bool; D]> = constraint.iter().map(|c| c.fixed).collect();
    let weak = ties(&m.grid, map, fields, &support, &fixed, min_node_support);
    let natural = natural_end_ties(&m.grid, &m.faces, map, fields);
    let ties = merge(weak, natural, map.len());
    let dofs = Dofs::with_ties(fixed.into_iter(), ties);
    (constraint, dofs)
}
