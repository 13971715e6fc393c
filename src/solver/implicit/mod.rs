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

pub mod krylov;
pub mod newmark;
pub mod support;
pub mod tangent;

use crate::dim::Vector;
use crate::material::driver::numerical_stress_derivative;
use crate::material::Increment;
use crate::model::conditions::Constraint;
use crate::model::{load_factor, Model};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::absorbing::{self, AbsorbingStep};
use crate::physics::boundary::implicit_node_constraint;
use crate::physics::deformation::Trial;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::{
    applied_force, external_force, interpolate, mass_momentum, nodal_force, NodeMap,
};
use crate::scene::{Integrator, LinearSolver, MassMatrix, SolverConfig, SolverKind};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::linear::direct::{DirectSolver, Structure};
use crate::solver::report::{NewtonRow, SolverReport};
use crate::solver::stepper::Stepper;
use newmark::Newmark;
use rayon::prelude::*;
use std::time::Instant;
use support::{nodal_support, ties};
use tangent::{
    internal_force, pk1_derivative, push_terms, relative_pk1, stiffness_triplets, Dofs,
    Pk1Derivative,
};

/// Why one attempt at a step failed.
#[derive(Clone, Debug)]
struct Failure {
    particle: Option<usize>,
    message: String,
}

/// The parts of one step's nonlinear system that do not depend on the iterate.
struct StepSystem<const D: usize> {
    constraint: Vec<Constraint<D>>,
    dofs: Dofs,
    /// Lumped nodal mass.
    mass: Vec<f64>,
    /// External force at the end of the step.
    f_ext: Vec<Vector<D>>,
    /// Nodal acceleration at the step start (Newmark; zero otherwise).
    a_n: Vec<Vector<D>>,
    /// Newmark predictor ũ (zero when quasi-static).
    u_tilde: Vec<Vector<D>>,
    /// 1/(βΔt²), or 0 when quasi-static.
    inertia: f64,
    /// Load factors at the end of the step: gravity, and each load ramp.
    g_new: f64,
    scales_new: Vec<f64>,
}

pub struct Implicit<const D: usize> {
    shape: ShapeFunction,
    /// The step size (Newmark `dt`, or end_time / load_steps).
    dt: f64,
    integrator: Integrator,
    newmark: Newmark,
    mass_matrix: MassMatrix,
    /// Start and duration of the run or stage (quasi-static load factor).
    t_start: f64,
    end_time: f64,
    /// Quasi-static: gravity ramps with the load factor (else it is in full).
    gravity_ramp: bool,
    residual_tolerance: f64,
    displacement_tolerance: f64,
    max_iterations: usize,
    line_search: bool,
    max_cutbacks: usize,
    /// Nodes with less particle support (cells) are tied to their neighbours.
    min_node_support: f64,
    /// F-bar against volumetric locking (`crate::physics::fbar`).
    fbar: bool,
    stencils: Stencils<D>,
    map: NodeMap,
    trial: Trial,
    solver: DirectSolver,
    /// Matrix-free Krylov solver (None: direct solves).
    krylov: Option<krylov::KrylovState>,
    /// Particle accelerations (Newmark only; empty otherwise).
    accel: Vec<Vector<D>>,
    /// Absorbing faces within the current step (empty when the scene has none).
    absorbing: AbsorbingStep<D>,
    /// Newton iterations since the last `take_log`.
    log: Vec<NewtonRow>,
    /// Reactions of the last converged step: (grid node, force the prescribed
    /// components exert on the body), nodes with a non-zero reaction only.
    pub reaction: Vec<(u32, Vector<D>)>,
    pub newton_iterations: usize,
    pub cutbacks: usize,
    /// Krylov iterations over all Newton corrections (0 with the direct solver).
    pub krylov_iterations: usize,
}

impl<const D: usize> Implicit<D> {
    /// A solver for a run or stage that starts at time `t_start`.
    pub fn new(shape: ShapeFunction, s: &SolverConfig, t_start: f64) -> Self {
        Implicit {
            t_start,
            shape,
            dt: s.implicit_dt(),
            integrator: s.integrator(),
            newmark: Newmark {
                beta: s.beta(),
                gamma: s.gamma(),
            },
            mass_matrix: s.mass(),
            end_time: s.end_time,
            gravity_ramp: s.gravity_ramp(),
            residual_tolerance: s.residual_tolerance(),
            displacement_tolerance: s.displacement_tolerance(),
            max_iterations: s.max_iterations(),
            line_search: s.line_search(),
            max_cutbacks: s.max_cutbacks(),
            min_node_support: s.min_node_support(),
            fbar: s.fbar(),
            stencils: Stencils::default(),
            map: NodeMap::default(),
            trial: Trial::default(),
            solver: DirectSolver::new(),
            krylov: krylov::KrylovConfig::of(s).map(krylov::KrylovState::new),
            accel: Vec::new(),
            absorbing: AbsorbingStep::default(),
            log: Vec::new(),
            reaction: Vec::new(),
            newton_iterations: 0,
            cutbacks: 0,
            krylov_iterations: 0,
        }
    }

    /// Newton rows logged since the last call.
    pub fn take_log(&mut self) -> Vec<NewtonRow> {
        std::mem::take(&mut self.log)
    }

    pub fn active_nodes(&self) -> usize {
        self.map.len()
    }

    /// Factorizations of the lagged_direct preconditioner so far (0 otherwise).
    pub fn lagged_factorizations(&self) -> usize {
        self.krylov.as_ref().map_or(0, |k| k.factorizations)
    }

    /// Advance from t to t + dt, halving the step on Newton failure. Returns the
    /// work of gravity and applied loads.
    pub fn advance(
        &mut self,
        m: &mut Model<D>,
        t: f64,
        dt: f64,
        step: usize,
    ) -> Result<f64, Divergence> {
        self.advance_level(m, t, dt, step, 0)
    }

    fn advance_level(
        &mut self,
        m: &mut Model<D>,
        t: f64,
        dt: f64,
        step: usize,
        level: usize,
    ) -> Result<f64, Divergence> {
        match self.attempt(m, t, dt, step, level) {
            Ok(work) => Ok(work),
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

    /// Load factor of gravity and loads at time t: (t − t_start) / duration when
    /// quasi-static, otherwise 1 for gravity and the ramp of each load.
    fn load_factors(&self, m: &Model<D>, t: f64) -> (f64, Vec<f64>) {
        match self.integrator {
            Integrator::QuasiStatic => {
                let lambda = ((t - self.t_start) / self.end_time).clamp(0.0, 1.0);
                let g = if self.gravity_ramp { lambda } else { 1.0 };
                (g, vec![lambda; m.load_ramps.len()])
            }
            Integrator::Newmark => (1.0, m.load_scales(t)),
        }
    }

    /// Particle accelerations at t = 0 from M a = f_ext − f_int (lumped).
    fn initial_acceleration(&mut self, m: &Model<D>) {
        let p = &m.particles;
        let (g, scales) = self.load_factors(m, self.t_start);
        let load = |q: usize| load_factor(&m.load_ramp_of, q, &scales);
        let mut force = nodal_force(&self.map, &self.stencils, p, &(m.gravity * g), &load);
        let (mass, momentum) = mass_momentum(&self.map, &self.stencils, p);
        let v = crate::physics::transfer::mass_average(&mass, &momentum);
        absorbing::add_force(
            &m.absorbing,
            &m.grid,
            p,
            &self.map,
            &self.stencils,
            &v,
            &mut force,
        );
        let a: Vec<Vector<D>> = force
            .iter()
            .zip(&mass)
            .map(|(f, m)| if *m > 0.0 { f / *m } else { f * 0.0 })
            .collect();
        self.accel = (0..p.len())
            .map(|q| interpolate(&self.map, &self.stencils, q, &a))
            .collect();
    }

    /// One attempt at the step t → t + dt. Leaves the model untouched on failure.
    fn attempt(
        &mut self,
        m: &mut Model<D>,
        t: f64,
        dt: f64,
        step: usize,
        level: usize,
    ) -> Result<f64, Failure> {
        let started = Instant::now();
        let dynamic = self.integrator == Integrator::Newmark;
        let sys = self.prepare(m, t, dt);
        self.prepare_absorbing(m, &sys, dt);
        let StepSystem {
            constraint,
            dofs,
            mass,
            f_ext,
            a_n,
            u_tilde,
            inertia,
            g_new,
            scales_new,
        } = &sys;
        let (mass, f_ext, u_tilde, inertia, g_new) = (
            mass.as_slice(),
            f_ext.as_slice(),
            u_tilde.as_slice(),
            *inertia,
            *g_new,
        );
        let (st, map) = (&self.stencils, &self.map);
        let p = &m.particles;
        let n = map.len();
        let load_new = |q: usize| load_factor(&m.load_ramp_of, q, scales_new);

        // Initial iterate: the predictor, with the prescribed components imposed.
        let mut u = u_tilde.to_vec();
        for a in 0..n {
            for d in (0..D).filter(|&d| constraint[a].fixed[d]) {
                u[a][d] = constraint[a].value[d] * dt;
            }
        }
        dofs.follow_ties(&mut u);
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let applied = norm(&dofs.reduce(f_ext)).max(norm(
            &dofs.reduce(&self.inertial_force(map, st, p, mass, u_tilde, inertia)),
        ));
        let mut method = "none";
        let mut converged = false;
        let mut last_increment = f64::NAN;
        let mut previous_residual = f64::INFINITY;
        for iteration in 0..=self.max_iterations {
            // Residual at the current iterate, from the step-start state.
            let r = self.residual(m, &u, u_tilde, mass, f_ext, inertia, dt)?;
            let r_free = dofs.reduce(&r);
            let r_norm = norm(&r_free);
            // The residual is measured against the largest of the applied force,
            // the inertial force and the reactions at the prescribed components
            // (as FE codes do): a run driven only by prescribed displacements
            // (weightless soil under a rigid footing) has no applied force.
            let reaction = reactions(constraint, &r);
            let reaction_norm = reaction
                .iter()
                .map(|f| f.norm_squared())
                .sum::<f64>()
                .sqrt();
            let reference = applied.max(reaction_norm);
            let scale = reference.max(f64::MIN_POSITIVE);
            let residual_ok = r_norm <= self.residual_tolerance * scale || r_norm == 0.0;
            let u_norm = norm(&dofs.values(&u));
            // Near rest (e.g. settled on absorbing faces) ‖u‖ → 0 and ‖δu‖/‖u‖ stalls
            // at round-off: a converged residual that a correction no longer halves
            // is at the round-off floor and accepted.
            let stalled = iteration >= 2 && r_norm >= 0.5 * previous_residual;
            previous_residual = r_norm;
            let increment_ok =
                iteration == 0 || last_increment <= self.displacement_tolerance || stalled;
            if !r_norm.is_finite() {
                return Err(Failure {
                    particle: None,
                    message: format!("non-finite residual in Newton iteration {iteration}"),
                });
            }
            let mut row = NewtonRow {
                step: step + 1,
                time: t + dt,
                dt,
                cutback: level,
                iteration,
                residual: r_norm / scale,
                increment: f64::NAN,
                wall_seconds: started.elapsed().as_secs_f64(),
                linear_solver: method,
                krylov_iterations: 0,
                forcing: f64::NAN,
            };
            if residual_ok && increment_ok {
                self.log.push(row);
                self.reaction = self
                    .map
                    .active
                    .iter()
                    .copied()
                    .zip(reaction)
                    .filter(|(_, f)| *f != Vector::<D>::zeros())
                    .collect();
                converged = true;
                break;
            }
            if iteration == self.max_iterations {
                self.log.push(row);
                break;
            }
            // Correction: direct, or matrix-free Krylov to the forcing term.
            let krylov_before = self.krylov_iterations;
            let correction = if self.krylov.is_some() {
                let stop = self.residual_tolerance * scale;
                self.krylov_correction(
                    m, dofs, &u, &r_free, stop, iteration, u_tilde, mass, f_ext, inertia, dt,
                )
            } else {
                self.direct_correction(m, dofs, &r_free, mass, inertia)
            };
            let correction = match correction {
                Ok(c) => c,
                Err(f) => {
                    // Keep the failing iteration in newton.csv.
                    row.wall_seconds = started.elapsed().as_secs_f64();
                    row.krylov_iterations = self.krylov_iterations - krylov_before;
                    self.log.push(row);
                    return Err(f);
                }
            };
            let du = correction.du;
            method = correction.method;
            row.krylov_iterations = correction.krylov_iterations;
            row.forcing = correction.forcing;
            let mut step_length = 1.0;
            if self.line_search {
                step_length =
                    self.line_search(m, &u, &du, dofs, u_tilde, mass, f_ext, inertia, dt, r_norm)?;
            }
            dofs.apply_correction(&mut u, &du, step_length);
            last_increment =
                step_length * norm(&du) / norm(&dofs.values(&u)).max(u_norm).max(f64::MIN_POSITIVE);
            row.increment = last_increment;
            row.linear_solver = method;
            row.wall_seconds = started.elapsed().as_secs_f64();
            self.log.push(row);
            self.newton_iterations += 1;
        }
        if !converged {
            return Err(Failure {
                particle: None,
                message: format!(
                    "Newton did not converge in {} iterations",
                    self.max_iterations
                ),
            });
        }

        // Commit: stresses of the converged iterate (the last residual evaluation),
        // positions, and the Newmark update of velocities and accelerations.
        let (g_old, scales_old) = self.load_factors(m, t);
        let load_old = |q: usize| load_factor(&m.load_ramp_of, q, &scales_old);
        let (map, st) = (&self.map, &self.stencils);
        let p = &mut m.particles;
        self.trial.commit(p);
        let dx: Vec<Vector<D>> = (0..p.len()).map(|q| interpolate(map, st, q, &u)).collect();
        let work: f64 = (0..p.len())
            .map(|q| {
                let f_old = applied_force(p, q, &(m.gravity * g_old), &load_old);
                let f_new = applied_force(p, q, &(m.gravity * g_new), &load_new);
                (f_old + f_new).dot(&dx[q]) * 0.5
            })
            .sum();
        for (x, d) in p.x.iter_mut().zip(&dx) {
            *x += d;
        }
        if dynamic {
            let a_new: Vec<Vector<D>> = (0..n)
                .map(|a| self.newmark.acceleration(dt, &u[a], &u_tilde[a]))
                .collect();
            let dv: Vec<Vector<D>> = (0..n)
                .map(|a| self.newmark.velocity_increment(dt, &a_n[a], &a_new[a]))
                .collect();
            // FLIP-style increments for both: the particles keep what the grid
            // cannot represent, and the grid's Newmark update is not re-projected.
            let da: Vec<Vector<D>> = (0..n).map(|a| a_new[a] - a_n[a]).collect();
            for q in 0..p.len() {
                p.v[q] += interpolate(map, st, q, &dv);
                self.accel[q] += interpolate(map, st, q, &da);
            }
        }
        check_state(m, step + 1, t + dt).map_err(|d| Failure {
            particle: d.particle,
            message: d.message,
        })?;
        Ok(work)
    }

    /// Everything of the step t → t + dt that does not depend on the iterate:
    /// shape functions at the step-start positions, conditions, unknowns, masses,
    /// external force at t + dt and the Newmark predictor.
    fn prepare(&mut self, m: &Model<D>, t: f64, dt: f64) -> StepSystem<D> {
        let dynamic = self.integrator == Integrator::Newmark;
        let p = &m.particles;
        crate::physics::transfer::stencils_and_nodes(
            m,
            self.shape,
            &mut self.stencils,
            &mut self.map,
        );
        if self.fbar {
            self.trial.use_fbar(&m.grid, &p.x);
        }
        if dynamic && self.accel.len() != p.len() {
            self.initial_acceleration(m);
        }
        let p = &m.particles;
        let (st, map) = (&self.stencils, &self.map);
        let constraint: Vec<Constraint<D>> = map
            .active
            .par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|&g| implicit_node_constraint(&m.grid, &m.faces, &m.friction, g as usize))
            .collect();
        let support = nodal_support(map, st, &p.volume, m.grid.cell_volume());
        let ties = ties(&m.grid, map, &support, &constraint, self.min_node_support);
        let dofs = Dofs::with_ties(constraint.iter().map(|c| c.fixed), ties);
        let n = map.len();

        // External force at the end of the step; inertia terms (Newmark).
        let (g_new, scales_new) = self.load_factors(m, t + dt);
        let load_new = |q: usize| load_factor(&m.load_ramp_of, q, &scales_new);
        let f_ext = external_force(map, st, p, &(m.gravity * g_new), &load_new);
        let (mass, momentum) = mass_momentum(map, st, p);
        let nodal = |w: &[f64], a: usize| if w[a] > 0.0 { 1.0 / w[a] } else { 0.0 };
        let (a_n, u_tilde) = if dynamic {
            let am = map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
                self.accel[q] * (p.mass[q] * st.weight[e])
            });
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
        let inertia = if dynamic {
            self.newmark.inertia(dt)
        } else {
            0.0
        };

        StepSystem {
            constraint,
            dofs,
            mass,
            f_ext,
            a_n,
            u_tilde,
            inertia,
            g_new,
            scales_new,
        }
    }

    /// The absorbing faces of this step: layer particles at the step start, and
    /// their velocity as a function of u through Newmark (none when quasi-static).
    fn prepare_absorbing(&mut self, m: &Model<D>, sys: &StepSystem<D>, dt: f64) {
        let newmark = (self.integrator == Integrator::Newmark).then_some((&self.newmark, dt));
        let layer = absorbing::layer(&m.absorbing, &m.grid, &m.particles);
        if layer.is_empty() {
            self.absorbing = AbsorbingStep::default();
            return;
        }
        let n = sys.a_n.len();
        let (velocity_offset, rate) = match newmark {
            Some((nm, dt)) => (
                (0..n)
                    .map(|a| {
                        nm.end_velocity(dt, &Vector::<D>::zeros(), &sys.u_tilde[a], &sys.a_n[a])
                    })
                    .collect(),
                nm.velocity_rate(dt),
            ),
            None => (vec![Vector::<D>::zeros(); n], 0.0),
        };
        self.absorbing = AbsorbingStep {
            layer,
            velocity_offset,
            rate,
        };
    }

    /// M (u − ũ) / (βΔt²) at the active nodes (lumped or consistent M).
    fn inertial_force(
        &self,
        map: &NodeMap,
        st: &Stencils<D>,
        p: &crate::model::particles::Particles<D>,
        mass: &[f64],
        w: &[Vector<D>],
        inertia: f64,
    ) -> Vec<Vector<D>> {
        if inertia == 0.0 {
            return vec![Vector::<D>::zeros(); mass.len()];
        }
        match self.mass_matrix {
            MassMatrix::Lumped => w.iter().zip(mass).map(|(w, m)| w * (m * inertia)).collect(),
            MassMatrix::Consistent => {
                let at_particles: Vec<Vector<D>> =
                    (0..p.len()).map(|q| interpolate(map, st, q, w)).collect();
                map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
                    at_particles[q] * (p.mass[q] * st.weight[e] * inertia)
                })
            }
        }
    }

    /// r(u) at the active nodes; evaluates the trial state of the particles.
    #[allow(clippy::too_many_arguments)]
    fn residual(
        &mut self,
        m: &Model<D>,
        u: &[Vector<D>],
        u_tilde: &[Vector<D>],
        mass: &[f64],
        f_ext: &[Vector<D>],
        inertia: f64,
        dt: f64,
    ) -> Result<Vec<Vector<D>>, Failure> {
        let p = &m.particles;
        if let Some(q) = self
            .trial
            .evaluate(p, &m.materials, &self.stencils, &self.map, u, dt)
        {
            return Err(Failure {
                particle: Some(q),
                message: "inverted (det F ≤ 0) in a Newton iterate".into(),
            });
        }
        let pk1: Vec<_> = (0..p.len())
            .map(|q| relative_pk1(&self.trial.df[q], &self.trial.stress[q]))
            .collect();
        let f_int = internal_force(&self.map, &self.stencils, &p.volume, &pk1);
        let w: Vec<Vector<D>> = u.iter().zip(u_tilde).map(|(a, b)| a - b).collect();
        let f_inertia = self.inertial_force(&self.map, &self.stencils, p, mass, &w, inertia);
        let mut r: Vec<Vector<D>> = (0..u.len())
            .map(|a| f_inertia[a] + f_int[a] - f_ext[a])
            .collect();
        // Absorbing faces: − f_boundary(u), dashpots through v_{n+1}(u) (2-63).
        self.absorbing
            .add_residual(&self.map, &self.stencils, p, u, &mut r);
        Ok(r)
    }

    /// δu = −K⁻¹ r with the assembled tangent, factorized by the direct solver.
    fn direct_correction(
        &mut self,
        m: &Model<D>,
        dofs: &Dofs,
        r_free: &[f64],
        mass: &[f64],
        inertia: f64,
    ) -> Result<krylov::Correction, Failure> {
        let (triplets, symmetric) = self.tangent(m, dofs, mass, inertia)?;
        let structure = if symmetric {
            Structure::Symmetric
        } else {
            Structure::General
        };
        let used = self
            .solver
            .factorize(dofs.free, &triplets, structure)
            .map_err(|e| Failure {
                particle: None,
                message: format!("linear solve failed: {e}"),
            })?;
        let rhs: Vec<f64> = r_free.iter().map(|x| -x).collect();
        let du = self.solver.solve(&rhs).map_err(|e| Failure {
            particle: None,
            message: format!("linear solve failed: {e}"),
        })?;
        Ok(krylov::Correction {
            du,
            method: used.name(),
            krylov_iterations: 0,
            forcing: f64::NAN,
        })
    }

    /// A_p = ∂P/∂ΔF of every particle at the trial state: from the material's
    /// exact stress derivative, or, when `numerical` (Krylov preconditioners
    /// only), from central differences of its stress update if it has none.
    fn particle_tangents(
        &self,
        m: &Model<D>,
        numerical: bool,
    ) -> Result<Vec<Pk1Derivative>, Failure> {
        let p = &m.particles;
        let history_old = p.history.slots(&p.history.data);
        let a: Vec<Option<Pk1Derivative>> = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| {
                let inc = Increment {
                    f_old: p.f[q],
                    df: self.trial.df[q],
                    dt: 0.0,
                    stress_old: p.stress[q],
                    history_old: history_old[q],
                };
                let mat = m.materials[p.material[q] as usize].as_ref();
                mat.stress_derivative(&inc)
                    .or_else(|| {
                        numerical.then(|| numerical_stress_derivative(mat, &inc, NUMERICAL_STEP))
                    })
                    .map(|ds| pk1_derivative(&self.trial.df[q], &self.trial.stress[q], &ds))
            })
            .collect();
        if let Some(q) = a.iter().position(|x| x.is_none()) {
            let model = m.materials[p.material[q] as usize].model();
            return Err(Failure {
                particle: Some(q),
                message: format!(
                    "material model `{model}` has no analytic tangent, which the direct solver \
                     needs; choose a matrix-free solver: linear_solver = \"gmres\" (or \"cg\" \
                     for symmetric problems) in [solver] or the [[stage]]"
                ),
            });
        }
        Ok(a.into_iter().map(|x| x.unwrap()).collect())
    }

    /// Consistent tangent triplets over the free unknowns, and whether it is symmetric.
    fn tangent(
        &self,
        m: &Model<D>,
        dofs: &Dofs,
        mass: &[f64],
        inertia: f64,
    ) -> Result<(tangent::Triplets, bool), Failure> {
        let p = &m.particles;
        // The Krylov path's lagged preconditioner accepts a numerical tangent.
        let a = self.particle_tangents(m, self.krylov.is_some())?;
        let (mut triplets, symmetric) = match &self.trial.fbar {
            None => stiffness_triplets(&self.map, &self.stencils, dofs, &p.volume, &a),
            Some(state) => (
                tangent::fbar_triplets(&self.map, &self.stencils, dofs, &p.volume, state, &a),
                false,
            ),
        };
        // Absorbing faces: Σ S_I S_J (γ/(βΔt) C + K), symmetric.
        tangent::absorbing_triplets(
            &self.absorbing,
            &self.map,
            &self.stencils,
            dofs,
            &mut triplets,
        );
        if inertia > 0.0 {
            match self.mass_matrix {
                MassMatrix::Lumped => {
                    for (node, m_i) in mass.iter().enumerate() {
                        for d in 0..D {
                            let t = dofs.terms(node, d, D);
                            push_terms(&mut triplets, &t, &t, m_i * inertia);
                        }
                    }
                }
                MassMatrix::Consistent => {
                    let st = &self.stencils;
                    for q in 0..p.len() {
                        for e1 in st.range(q) {
                            for e2 in st.range(q) {
                                let (n1, n2) = (
                                    self.map.local[st.node[e1] as usize] as usize,
                                    self.map.local[st.node[e2] as usize] as usize,
                                );
                                let v = p.mass[q] * st.weight[e1] * st.weight[e2] * inertia;
                                for d in 0..D {
                                    let (rows, cols) = (dofs.terms(n1, d, D), dofs.terms(n2, d, D));
                                    push_terms(&mut triplets, &rows, &cols, v);
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok((triplets, symmetric))
    }

    /// Backtracking on ‖r‖: halve the step length until the residual decreases
    /// (at most 6 halvings; the last length is taken anyway).
    #[allow(clippy::too_many_arguments)]
    fn line_search(
        &mut self,
        m: &Model<D>,
        u: &[Vector<D>],
        du: &[f64],
        dofs: &Dofs,
        u_tilde: &[Vector<D>],
        mass: &[f64],
        f_ext: &[Vector<D>],
        inertia: f64,
        dt: f64,
        r_norm: f64,
    ) -> Result<f64, Failure> {
        let mut length = 1.0;
        for _ in 0..6 {
            let mut trial_u = u.to_vec();
            dofs.apply_correction(&mut trial_u, du, length);
            let r = self.residual(m, &trial_u, u_tilde, mass, f_ext, inertia, dt);
            if let Ok(r) = r {
                let n: f64 = dofs.reduce(&r).iter().map(|x| x * x).sum::<f64>().sqrt();
                if n < r_norm {
                    return Ok(length);
                }
            }
            length *= 0.5;
        }
        Ok(length)
    }
}

impl<const D: usize> Stepper<D> for Implicit<D> {
    fn dt(&self, _m: &Model<D>) -> f64 {
        self.dt
    }

    fn step(&mut self, m: &mut Model<D>, t: f64, dt: f64, step: usize) -> Result<f64, Divergence> {
        self.advance(m, t, dt, step)
    }

    fn active_nodes(&self) -> usize {
        Implicit::active_nodes(self)
    }

    fn reaction(&self) -> Option<&[(u32, Vector<D>)]> {
        Some(&self.reaction)
    }

    fn take_newton_rows(&mut self) -> Vec<NewtonRow> {
        self.take_log()
    }

    fn report(&self) -> SolverReport {
        let krylov = self.krylov.as_ref().map(|k| k.config);
        let newmark = self.integrator == Integrator::Newmark;
        SolverReport {
            solver: SolverKind::Implicit,
            scheme: None,
            integrator: Some(self.integrator),
            newton_iterations: Some(self.newton_iterations),
            cutbacks: Some(self.cutbacks),
            linear_solver: Some(krylov.map_or(LinearSolver::Direct, |k| k.method)),
            krylov_iterations: Some(self.krylov_iterations),
            preconditioner: krylov.map(|k| k.preconditioner),
            lagged_factorizations: krylov.map(|_| self.lagged_factorizations()),
            beta: newmark.then_some(self.newmark.beta),
            gamma: newmark.then_some(self.newmark.gamma),
        }
    }
}

/// Central-difference step of the numerical stress derivative (preconditioners
/// of materials without an analytic tangent).
const NUMERICAL_STEP: f64 = 1e-6;
/// The residual at the prescribed components, r = f_int + inertia − f_ext: the
/// reactions, node by node (zero at free components).
fn reactions<const D: usize>(constraint: &[Constraint<D>], r: &[Vector<D>]) -> Vec<Vector<D>> {
    constraint
        .iter()
        .zip(r)
        .map(|(c, ra)| Vector::<D>::from_fn(|d, _| if c.fixed[d] { ra[d] } else { 0.0 }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    const BLOCK: &str = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [4.0, 4.0]
cells = [4, 4]
shape_function = "linear"
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "rectangle"
min = [0.5, 0.0]
max = [3.0, 2.5]
[[boundary]]
face = "ymin"
condition = "fixed"
[[load]]
kind = "point"
region_min = [2.5, 2.0]
region_max = [3.0, 2.5]
force = [3.0e3, -1.0e3]
[solver]
kind = "implicit"
integrator = "newmark"
end_time = 1.0
dt = 0.01
"#;

    /// Absorbing faces for the tangent check: dashpots and springs (thesis 2-63).
    const ABSORBING: &str = "[[boundary]]\nface = \"xmin\"\ncondition = \"absorbing\"\nspring_distance = 2.0\n[[boundary]]\nface = \"ymin\"\ncondition = \"absorbing\"\nspring_stiffness = [4.0e4, 1.0e4]\n";

    /// max |K − K_fd| / max |K| of the assembled tangent against central
    /// differences of the residual (2-37), column by column, at a smooth
    /// finite-strain iterate of the block with these overrides; also the number of
    /// unknowns, of tied nodes and of particles with plastic strain at the iterate.
    fn tangent_error(overrides: &[String], absorbing: bool) -> (f64, usize, usize, usize) {
        let text = if absorbing {
            BLOCK.replace("[solver]", &format!("{ABSORBING}[solver]"))
        } else {
            BLOCK.to_string()
        };
        tangent_error_of::<2>(&text, overrides, absorbing)
    }

    /// `tangent_error` of any scene, in D dimensions.
    fn tangent_error_of<const D: usize>(
        text: &str,
        overrides: &[String],
        absorbing: bool,
    ) -> (f64, usize, usize, usize) {
        let scene = Scene::parse("block.toml", text, overrides).unwrap();
        let m = Model::<D>::build(&scene).unwrap();
        let mut solver = Implicit::<D>::new(
            scene.config.grid.shape_function,
            scene.config.stages()[0],
            0.0,
        );
        let sys = solver.prepare(&m, 0.0, 0.01);
        solver.prepare_absorbing(&m, &sys, 0.01);
        assert_eq!(solver.absorbing.is_empty(), !absorbing);
        // A smooth, finite-strain iterate (strains of a few per cent).
        let nodes: Vec<usize> = solver.map.active.iter().map(|&g| g as usize).collect();
        let mut u: Vec<Vector<D>> = nodes
            .iter()
            .zip(&sys.constraint)
            .map(|(&g, c)| {
                let x = m.grid.node_position(m.grid.node_ijk(g));
                Vector::<D>::from_fn(|d, _| match d {
                    _ if c.fixed[d] => 0.0,
                    0 => 0.03 * (0.7 * x[1]).sin() + 0.01 * x[0],
                    1 => -0.02 * x[0] * x[1] / 4.0,
                    _ => 0.02 * (0.9 * x[0]).cos() * x[2] - 0.01 * x[1],
                })
            })
            .collect();
        sys.dofs.follow_ties(&mut u);
        let tied = sys.dofs.ties.iter().filter(|t| t.is_some()).count();
        let dt = 0.01;
        let res = |solver: &mut Implicit<D>, u: &[Vector<D>]| {
            let r = solver
                .residual(&m, u, &sys.u_tilde, &sys.mass, &sys.f_ext, sys.inertia, dt)
                .unwrap();
            sys.dofs.reduce(&r)
        };
        res(&mut solver, &u);
        // History of the materials used here: equivalent plastic strain or none.
        let plastic = solver.trial.history.iter().filter(|&&k| k > 0.0).count();
        let (triplets, _) = solver
            .tangent(&m, &sys.dofs, &sys.mass, sys.inertia)
            .unwrap();
        let n = sys.dofs.free;
        let mut k = vec![0.0; n * n];
        for (r, c, v) in triplets {
            k[r * n + c] += v;
        }
        let kmax = k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for col in 0..n {
            let (mut up, mut um) = (u.clone(), u.clone());
            let mut e = vec![0.0; n];
            e[col] = 1.0;
            sys.dofs.apply_correction(&mut up, &e, h);
            sys.dofs.apply_correction(&mut um, &e, -h);
            let (rp, rm) = (res(&mut solver, &up), res(&mut solver, &um));
            for row in 0..n {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                worst = worst.max((fd - k[row * n + col]).abs());
            }
        }
        (worst / kmax, n, tied, plastic)
    }

    /// The assembled tangent (material + geometric + inertia, 2-40…2-42, and the
    /// dashpots and springs of absorbing faces) against central differences of the
    /// residual (2-37), column by column, at a non-trivial iterate, for every
    /// material, several shape functions and both mass matrices. Two cases tie many
    /// weakly supported nodes (a large `min_node_support`), so the tangent is
    /// checked through the ties too; three have absorbing faces.
    #[test]
    fn global_tangent_matches_finite_differences_of_the_residual() {
        for (model, shape, mass, support, absorbing) in [
            ("hencky", "linear", "lumped", 0.0, false),
            ("hencky", "cpdi", "consistent", 0.01, false),
            ("neo_hookean", "bspline2", "lumped", 0.01, false),
            ("linear_elastic", "ugimp", "lumped", 0.01, false),
            ("neo_hookean", "cpgimp", "consistent", 0.01, false),
            ("hencky", "bspline2", "consistent", 0.3, false),
            ("hencky", "ugimp", "lumped", 0.3, false),
            ("hencky", "linear", "lumped", 0.0, true),
            ("linear_elastic", "bspline2", "consistent", 0.01, true),
            ("hencky", "ugimp", "lumped", 0.3, true),
        ] {
            let overrides = vec![
                format!("material.0.model={model}"),
                format!("grid.shape_function={shape}"),
                format!("solver.mass={mass}"),
                format!("solver.min_node_support={support}"),
            ];
            let (error, n, tied, _) = tangent_error(&overrides, absorbing);
            println!(
                "{model} {shape} {mass} absorbing={absorbing}: {n} unknowns, {tied} tied nodes, \
                 max |K − K_fd| / max|K| = {error:.2e}"
            );
            assert!(
                error < 1e-6,
                "{model} {shape} {mass}: tangent off by {error:.2e} of its largest entry"
            );
        }
    }

    /// The F-bar tangent (`tangent::fbar_triplets`: each particle couples to the
    /// nodes of every particle in its cell) against central differences of the
    /// F-bar residual, with linear and smooth shape functions, through ties, and
    /// with Mohr-Coulomb in a plastic state (c small against the stresses of the
    /// iterate, ψ = 0 and ψ > 0). 2 × 2 particles per cell (as in the slope).
    #[test]
    fn global_tangent_with_fbar_matches_finite_differences_of_the_residual() {
        let mohr_coulomb = |psi: f64| {
            vec![
                "material.0.model=mohr_coulomb".to_string(),
                "material.0.cohesion=200.0".to_string(),
                "material.0.friction_angle=20.0".to_string(),
                format!("material.0.dilation_angle={psi}"),
            ]
        };
        let hencky = vec!["material.0.model=hencky".to_string()];
        for (name, material, shape, support) in [
            ("hencky", hencky.clone(), "linear", 0.0),
            ("hencky", hencky.clone(), "bspline2", 0.01),
            ("hencky", hencky.clone(), "ugimp", 0.3),
            ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "linear", 0.0),
            ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "bspline2", 0.01),
            ("mohr_coulomb ψ=10", mohr_coulomb(10.0), "ugimp", 0.3),
        ] {
            let mut overrides = material;
            overrides.extend([
                format!("grid.shape_function={shape}"),
                format!("solver.min_node_support={support}"),
                "solver.fbar=true".to_string(),
                "body.0.particles_per_cell=2".to_string(),
            ]);
            let (error, n, tied, plastic) = tangent_error(&overrides, false);
            println!(
                "F-bar {name} {shape}: {n} unknowns, {tied} tied nodes, {plastic} plastic \
                 particles, max |K − K_fd| / max|K| = {error:.2e}"
            );
            if name.starts_with("mohr") {
                assert!(plastic > 0, "F-bar {name} {shape}: no plastic particle");
            }
            assert!(
                error < 1e-6,
                "F-bar {name} {shape}: tangent off by {error:.2e} of its largest entry"
            );
        }
        // 3D: ΔF scaled as a whole (n = 3).
        for (name, material, shape) in [
            ("hencky", hencky.clone(), "linear"),
            ("mohr_coulomb ψ=0", mohr_coulomb(0.0), "bspline2"),
        ] {
            let mut overrides = material;
            overrides.extend([
                format!("grid.shape_function={shape}"),
                "solver.fbar=true".to_string(),
            ]);
            let (error, n, tied, plastic) = tangent_error_of::<3>(BLOCK_3D, &overrides, false);
            println!(
                "F-bar 3D {name} {shape}: {n} unknowns, {tied} tied nodes, {plastic} plastic \
                 particles, max |K − K_fd| / max|K| = {error:.2e}"
            );
            assert!(error < 1e-6, "F-bar 3D {name} {shape}: {error:.2e}");
            if name.starts_with("mohr") {
                assert!(plastic > 0, "F-bar 3D {name} {shape}: no plastic particle");
            }
        }
    }

    /// A small 3D block for the F-bar tangent check, 2 × 2 × 2 particles per cell.
    const BLOCK_3D: &str = r#"dimension = 3
[grid]
min = [0.0, 0.0, 0.0]
max = [3.0, 3.0, 3.0]
cells = [3, 3, 3]
[[material]]
name = "m"
model = "hencky"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "box"
min = [0.5, 0.0, 0.0]
max = [2.5, 2.0, 1.5]
particles_per_cell = 2
[[boundary]]
face = "ymin"
condition = "fixed"
[solver]
kind = "implicit"
integrator = "newmark"
end_time = 1.0
dt = 0.01
"#;

    /// Tied nodes follow a linear field exactly, so every particle's gradient of
    /// a linear nodal field is exact (linear consistency survives the ties), and
    /// masters are never tied themselves.
    #[test]
    fn ties_keep_linear_fields_exact() {
        for shape in ["linear", "ugimp", "cpdi", "bspline2", "bspline3"] {
            // The block's edges cut the cells anywhere: many weakly supported nodes.
            let overrides = vec![
                format!("grid.shape_function={shape}"),
                "grid.cells=[8,8]".to_string(),
                "body.0.min=[0.61,0.77]".to_string(),
                "body.0.max=[3.93,2.38]".to_string(),
                "body.0.particles_per_cell=2".to_string(),
                "load.0.region_min=[3.5,2.0]".to_string(),
                "load.0.region_max=[3.93,2.38]".to_string(),
                "solver.min_node_support=0.2".to_string(),
            ];
            let scene = Scene::parse("block.toml", BLOCK, &overrides).unwrap();
            let m = Model::<2>::build(&scene).unwrap();
            let mut solver = Implicit::<2>::new(
                scene.config.grid.shape_function,
                scene.config.stages()[0],
                0.0,
            );
            let sys = solver.prepare(&m, 0.0, 1.0);
            let ties = &sys.dofs.ties;
            let tied = ties.iter().filter(|t| t.is_some()).count();
            assert!(tied > 0, "{shape}: no tied node at min_node_support 0.2");
            for t in ties.iter().flatten() {
                assert!(ties[t.master[0]].is_none() && ties[t.master[1]].is_none());
            }
            let a = crate::dim::Tensor::<2>::new(0.013, -0.021, 0.008, 0.017);
            let b = Vector::<2>::new(0.3, -0.1);
            let linear = |g: u32| {
                let x = m.grid.node_position(m.grid.node_ijk(g as usize));
                a * x + b
            };
            let mut u: Vec<Vector<2>> = solver.map.active.iter().map(|&g| linear(g)).collect();
            let exact = u.clone();
            for (ua, t) in u.iter_mut().zip(ties) {
                if t.is_some() {
                    *ua = Vector::<2>::new(9.0, 9.0); // overwritten by the tie
                }
            }
            sys.dofs.follow_ties(&mut u);
            let node_error = u
                .iter()
                .zip(&exact)
                .map(|(x, y)| (x - y).norm())
                .fold(0.0, f64::max);
            let grad_error = (0..m.particles.len())
                .map(|q| {
                    (crate::physics::transfer::gradient(&solver.map, &solver.stencils, q, &u) - a)
                        .amax()
                })
                .fold(0.0, f64::max);
            println!(
                "{shape}: {tied} of {} nodes tied; node error {node_error:.1e}, gradient error {grad_error:.1e}",
                u.len()
            );
            assert!(node_error < 1e-14 && grad_error < 1e-12, "{shape}");
        }
    }
}
