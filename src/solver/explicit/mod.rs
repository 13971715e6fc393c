//! Explicit MPM: central difference in time (thesis 2-29, 2-30) with the USF, USL
//! and MUSL orderings of the stress update (§2.2.1), a PIC/FLIP blend, and local
//! damping for dynamic relaxation. B-spline grids take the mirror extension at
//! faces with prescribed velocities (`crate::solver::explicit::mirror`).

pub mod apic;
pub mod bulk_viscosity;
pub mod contact;
pub mod grid_update;
pub mod mirror;
pub mod node_box;
pub mod scatter;

use crate::dim::Vector;
use crate::model::conditions::{Constraint, FrictionFace};
use crate::model::loads::LoadTime;
use crate::model::{load_factor, Model};
use crate::parallel::{deterministic_sum, MIN_PARALLEL_LEN};
use crate::physics::boundary::absorbing;
use crate::physics::boundary::conditions::{friction_contact, node_constraint, node_friction};
use crate::physics::contact::totals::PairTotal;
use crate::physics::kinematics::deformation::Trial;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::{
    applied_force, interpolate_two, mass_average, mass_momentum, nodal_force, NodeMap,
};
use crate::scene::{Scheme, SolverConfig, Transfer};
use crate::solver::divergence::{check_state, inverted, Divergence};
use crate::solver::explicit::bulk_viscosity::BulkViscosity;
use crate::solver::explicit::grid_update::{acceleration, local_damping, TINY_MASS_FRACTION};
use crate::solver::explicit::mirror::Mirror;
use crate::solver::explicit::node_box::NodeBox;
use crate::solver::explicit::scatter::{ScatterStep, Settings};
use crate::solver::report::{SolverReport, TransferPath};
use crate::solver::stepper::Stepper;
use apic::AffineMomentum;
use contact::Contact;
use rayon::prelude::*;

pub struct Explicit<const D: usize> {
    pub shape: ShapeFunction,
    pub scheme: Scheme,
    pub cfl: f64,
    pub fixed_dt: Option<f64>,
    pub flip: f64,
    /// APIC (`solver::explicit::apic`) instead of the PIC/FLIP blend (`flip` is then 0).
    pub apic: bool,
    pub damping: f64,
    /// Gravity rises linearly from zero over `gravity_ramp_time` on the run's
    /// clock, as a load's `ramp_time` (0: in full from the start).
    pub gravity_ramp: LoadTime,
    /// F-bar against volumetric locking (`crate::physics::kinematics::fbar`).
    pub fbar: bool,
    stencils: Stencils<D>,
    map: NodeMap,
    trial: Trial<D>,
    /// Contact between bodies (`crate::solver::explicit::contact`), when the scene has some.
    contact: Option<Contact<D>>,
    /// Artificial bulk viscosity (`crate::solver::explicit::bulk_viscosity`), if asked for.
    pub viscosity: Option<BulkViscosity>,
    /// `solver.transfer`: `Auto` takes the scatter path where it serves.
    pub transfer: Transfer,
    /// The scatter path's buffers (`solver::explicit::scatter`), once it has run.
    scatter: Option<ScatterStep<D>>,
}

impl<const D: usize> Explicit<D> {
    pub fn new(shape: ShapeFunction, s: &SolverConfig) -> Self {
        Explicit {
            shape,
            scheme: s.scheme(),
            cfl: s.cfl(),
            fixed_dt: s.dt,
            flip: if s.apic() { 0.0 } else { s.flip() },
            apic: s.apic(),
            damping: s.damping(),
            gravity_ramp: LoadTime::Ramp(s.gravity_ramp_time()),
            fbar: s.fbar(),
            stencils: Stencils::default(),
            map: NodeMap::default(),
            trial: Trial::default(),
            contact: None,
            viscosity: s
                .bulk_viscosity()
                .map(|(quadratic, linear)| BulkViscosity { quadratic, linear }),
            transfer: s.transfer(),
            scatter: None,
        }
    }

    /// Can this step run on the scatter path (`solver::explicit::scatter`)? Not
    /// with what needs the node map or per-entry values: CPDI, contact, F-bar,
    /// bulk viscosity, absorbing faces, axisymmetry, removed particles, the
    /// mirror of cubic and domain B-splines at faces with prescribed velocity;
    /// nor USF with the families that read F (cpGIMP, domain B-splines), whose
    /// second scatter would see the updated F.
    pub fn scatter_serves(&self, m: &Model<D>) -> bool {
        let prescribed = m.faces.iter().any(|fc| fc.constraint.fixed.contains(&true));
        let mirror =
            self.shape != ShapeFunction::Bspline2 && (2..=3).contains(&m.grid.degree) && prescribed;
        self.transfer == Transfer::Auto
            && NodeBox::<D>::serves(self.shape)
            && m.contact.is_none()
            && !self.fbar
            && self.viscosity.is_none()
            && m.absorbing.faces.is_empty()
            && !m.axisymmetric
            && !m.removes_particles()
            && !mirror
            && !(self.scheme == Scheme::Usf && self.shape.reads_deformation())
    }

    /// Critical time step min_p h / (c_p + |v_p|) (2-45).
    pub fn critical_dt(m: &Model<D>) -> f64 {
        Self::critical_dt_with(m, None)
    }

    /// The critical step, and with bulk viscosity also its stable step
    /// h/(C_L c + √(C_L² c² + c²)) at every particle, in one pass. Removed
    /// particles (eroded, or outside the grid) do not count, unless all are.
    fn critical_dt_with(m: &Model<D>, viscosity: Option<&BulkViscosity>) -> f64 {
        let removes = m.removes_particles();
        let active = Self::critical_dt_over(m, viscosity, &|q| !(removes && m.removed(q)));
        match active.is_finite() {
            true => active,
            false => Self::critical_dt_over(m, viscosity, &|_| true),
        }
    }

    fn critical_dt_over(
        m: &Model<D>,
        viscosity: Option<&BulkViscosity>,
        counts: &(dyn Fn(usize) -> bool + Sync),
    ) -> f64 {
        let p = &m.particles;
        let h = m.grid.h_min();
        (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&q| counts(q))
            .map(|q| {
                let c = m.materials[p.material[q] as usize]
                    .wave_speed(p.f.get(q).determinant(), p.history.get(q));
                let dt = h / (c + p.v[q].norm());
                viscosity.map_or(dt, |v| dt.min(v.stable_dt(c, h, 0.0)))
            })
            .reduce(|| f64::INFINITY, f64::min)
    }
}

impl<const D: usize> Stepper<D> for Explicit<D> {
    /// The step to take now: the fixed one, or cfl × the critical one (with bulk
    /// viscosity, also within its stable step at every particle, its rate from
    /// the particle's F rate being unknown here: ε̇_v = 0, the linear term only).
    fn dt(&self, m: &Model<D>) -> f64 {
        self.fixed_dt
            .unwrap_or_else(|| self.cfl * Self::critical_dt_with(m, self.viscosity.as_ref()))
    }

    /// Advance the model from t to t + dt. Returns the work done by gravity and
    /// applied loads over the step.
    fn step(&mut self, m: &mut Model<D>, t: f64, dt: f64, step: usize) -> Result<f64, Divergence> {
        if self.scatter_serves(m) {
            let settings = Settings {
                shape: self.shape,
                scheme: self.scheme,
                flip: self.flip,
                apic: self.apic,
                damping: self.damping,
                gravity: m.gravity * self.gravity_ramp.factor(t),
            };
            let scatter = self.scatter.get_or_insert_with(ScatterStep::default);
            return scatter.step(&settings, m, t, dt, step);
        }
        self.scatter = None;
        if self.apic {
            apic::ensure(m, self.shape);
        }
        if let (None, Some(plan)) = (&self.contact, &m.contact) {
            self.contact = Some(Contact::new(plan.clone(), m));
        }
        let p = &m.particles;
        match &mut self.contact {
            None => crate::physics::transfer::stencils_and_nodes(
                m,
                self.shape,
                &mut self.stencils,
                &mut self.map,
            ),
            Some(c) => c.stencils_and_fields(m, self.shape, &mut self.stencils, &mut self.map),
        }
        if self.fbar {
            self.trial.use_fbar(&m.grid, &p.x);
        }
        let (st, map) = (&self.stencils, &self.map);
        let constraint: Vec<Constraint<D>> = (0..map.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| node_constraint(&m.grid, &m.faces, map.grid_node(a)))
            .collect();
        let contacts = friction_nodes(m, map);
        let tiny = TINY_MASS_FRACTION * p.mass.iter().cloned().fold(f64::INFINITY, f64::min);
        // Cubic and domain-averaged B-splines: the image problem's masses at faces
        // with prescribed velocities. Point-sampled quadratic B-splines keep the
        // clamped masses: the mirror removes their O(ε) stress error at the face
        // too, but their knot-crossing quadrature error then dominates and makes the
        // refinement sequence non-monotone (docs/accuracy.md); the suite's target
        // for them (tests/verification/column_explicit.rs) stays as it was.
        let mirror = if self.shape == ShapeFunction::Bspline2 {
            Mirror::default()
        } else {
            Mirror::build(&m.grid, &m.faces, map)
        };

        // APIC: the node positions and the affine part of the momentum.
        let positions = match self.apic {
            true => apic::node_positions(map, &m.grid),
            false => Vec::new(),
        };
        let affine =
            (self.apic).then(|| AffineMomentum::new(map, st, p, &p.x, &positions, self.shape));
        let term = affine.as_ref().map(|a| move |q, e, n| a.term(st, q, e, n));

        // Nodal velocity at the start of the step, with the conditions applied.
        let (mass, momentum) = mass_momentum(map, st, p, term.as_ref().map(|t| t as _));
        drop(affine);
        let mut raw_velocity = mass_average(&mass, &momentum);
        mirror.velocity(&mass, &momentum, &mut raw_velocity);
        // Contact after P2G: its momentum reaches the particles through the PIC part.
        if let Some(c) = &mut self.contact {
            c.correct(&mass, &mut raw_velocity, dt, 1.0 - self.flip);
        }
        let mut velocity = constrained(&raw_velocity, &constraint);
        apply_friction(&m.friction, &contacts, &constraint, &mut velocity);
        if self.scheme == Scheme::Usf {
            update_stress(m, &mut self.trial, st, map, &velocity, dt, step, t)?;
        }
        let p = &m.particles;

        // Nodal forces, damping, acceleration and updated velocity (2-23, 2-29).
        let scales = m.load_scales(t);
        let load_factor = |q: usize| load_factor(&m.load_ramp_of, q, &scales);
        let gravity = m.gravity * self.gravity_ramp.factor(t);
        let mut force = nodal_force(map, st, p, &gravity, &load_factor);
        if let Some(v) = &self.viscosity {
            let l = m.grid.h_min();
            v.add_force(map, st, p, &m.materials, &velocity, l, &mut force);
        }
        // Absorbing faces: dashpot (and spring) forces on the outer cell layer (2-63).
        absorbing::add_force(&m.absorbing, &m.grid, p, map, st, &velocity, &mut force);
        let mut accel: Vec<Vector<D>> = (0..map.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| {
                acceleration(
                    mass[a],
                    &force[a],
                    &velocity[a],
                    &raw_velocity[a],
                    &constraint[a],
                    self.damping,
                    tiny,
                    dt,
                )
            })
            .collect();
        let damped = |f: f64, v: f64| {
            local_damping(&Vector::<1>::new(f), &Vector::<1>::new(v), self.damping)[0]
        };
        mirror.acceleration(&mass, &force, &velocity, damped, &mut accel);
        let mut velocity_new: Vec<Vector<D>> = (0..map.len())
            .map(|a| raw_velocity[a] + accel[a] * dt)
            .collect();
        // Friction faces act on the updated velocity; the acceleration follows.
        apply_friction(&m.friction, &contacts, &constraint, &mut velocity_new);
        for (a, _) in &contacts {
            accel[*a] = (velocity_new[*a] - raw_velocity[*a]) / dt;
        }
        // Contact after the grid update (rigid bodies' nodes keep their velocity:
        // zero acceleration); prescribed components win.
        if let Some(c) = &mut self.contact {
            for a in c.correct(&mass, &mut velocity_new, dt, 1.0) {
                constraint[a].apply_velocity(&mut velocity_new[a]);
                accel[a] = (velocity_new[a] - raw_velocity[a]) / dt;
            }
        }

        // G2P: particle velocity (PIC/FLIP blend, 2-27) and position (2-26);
        // APIC: the affine moment where the particles are before they move.
        let flip = self.flip;
        let mp = &mut m.particles;
        let step_start_x = (self.apic && self.scheme == Scheme::Musl).then(|| mp.x.clone());
        if self.apic {
            let (x, velocity_new) = (&mp.x, &velocity_new);
            mp.affine = (0..mp.len())
                .into_par_iter()
                .with_min_len(MIN_PARALLEL_LEN)
                .map(|q| apic::moment(map, st, q, &x[q], &positions, velocity_new))
                .collect();
        }
        let old_v = mp.v.clone();
        mp.v.par_iter_mut()
            .zip(mp.x.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(q, (v, x))| {
                let (a, v_pic) = interpolate_two(map, st, q, &accel, &velocity_new);
                let v_flip = *v + a * dt;
                *v = v_flip * flip + v_pic * (1.0 - flip);
                *x += v_pic * dt;
            });
        // Free rigid bodies: Newton–Euler under the step's contact impulses and
        // the applied forces (`physics::rigid::newton_euler`).
        if let Some(free) = self.contact.as_mut().and_then(|c| c.free_bodies()) {
            let force: Vec<Vector<D>> = (free.particles())
                .map(|q| applied_force(&m.particles, q, &gravity, &load_factor))
                .collect();
            free.advance(&mut m.particles, &force, m.axisymmetric, dt);
        }
        if let Some(c) = &mut self.contact {
            c.keep_out_of_rigid_bodies(m);
        }
        let load_factor = |q: usize| crate::model::load_factor(&m.load_ramp_of, q, &scales);
        let p = &m.particles;
        let contact = &self.contact;
        let rigid = |q: usize| {
            contact
                .as_ref()
                .is_some_and(|c| c.is_prescribed_particle(q))
        };
        let work = dt
            * deterministic_sum(p.len(), |q| {
                // A rigid body's prescribed motion takes the work done on it.
                if rigid(q) {
                    return 0.0;
                }
                let f = applied_force(p, q, &gravity, &load_factor);
                f.dot(&(old_v[q] + p.v[q])) * 0.5
            });

        match self.scheme {
            Scheme::Usf => {}
            Scheme::Usl => update_stress(m, &mut self.trial, st, map, &velocity_new, dt, step, t)?,
            Scheme::Musl => {
                // Map the updated particle momentum back and use that velocity
                // (APIC: with the affine part, where the particles were).
                let p = &m.particles;
                let x = step_start_x.as_deref().unwrap_or(&p.x);
                let affine =
                    (self.apic).then(|| AffineMomentum::new(map, st, p, x, &positions, self.shape));
                let term = affine.as_ref().map(|a| move |q, e, n| a.term(st, q, e, n));
                let (_, momentum) = mass_momentum(map, st, p, term.as_ref().map(|t| t as _));
                let mut remapped = mass_average(&mass, &momentum);
                mirror.velocity(&mass, &momentum, &mut remapped);
                if let Some(c) = &mut self.contact {
                    c.correct(&mass, &mut remapped, dt, 0.0);
                }
                let mut velocity = constrained(&remapped, &constraint);
                apply_friction(&m.friction, &contacts, &constraint, &mut velocity);
                update_stress(m, &mut self.trial, st, map, &velocity, dt, step, t)?;
            }
        }
        check_state(m, step + 1, t + dt)?;
        Ok(work)
    }

    fn active_nodes(&self) -> usize {
        match &self.scatter {
            Some(s) => s.active,
            None => self.map.len(),
        }
    }

    fn report(&self) -> SolverReport {
        let transfer = match self.scatter {
            Some(_) => TransferPath::Scatter,
            None => TransferPath::Gather,
        };
        SolverReport::explicit(self.scheme, transfer)
    }

    fn take_contact(&mut self) -> Vec<PairTotal<D>> {
        self.contact
            .as_mut()
            .map_or_else(Vec::new, |c| c.take_totals())
    }
}

/// Nodal velocities with the prescribed components imposed.
fn constrained<const D: usize>(v: &[Vector<D>], c: &[Constraint<D>]) -> Vec<Vector<D>> {
    v.iter()
        .zip(c)
        .map(|(v, c)| {
            let mut v = *v;
            c.apply_velocity(&mut v);
            v
        })
        .collect()
}

/// The active nodes on friction faces, with the faces each lies on.
fn friction_nodes<const D: usize>(m: &Model<D>, map: &NodeMap) -> Vec<(usize, Vec<u8>)> {
    if m.friction.is_empty() {
        return Vec::new();
    }
    (0..map.len())
        .map(|a| (a, node_friction(&m.grid, &m.friction, map.grid_node(a))))
        .filter(|(_, on)| !on.is_empty())
        .collect()
}

/// Rigid-wall contact with Coulomb friction on the nodes of friction faces.
fn apply_friction<const D: usize>(
    faces: &[FrictionFace],
    contacts: &[(usize, Vec<u8>)],
    constraint: &[Constraint<D>],
    v: &mut [Vector<D>],
) {
    for (a, on) in contacts {
        v[*a] = friction_contact(faces, on, &constraint[*a], &v[*a]);
    }
}

/// ΔF = I + Δt L with L_p = Σ v_I ⊗ ∇S_Ip, then F, V and the stress (2-31, 2-32):
/// the shared deformation update with the nodal displacement u_I = Δt v_I.
#[allow(clippy::too_many_arguments)]
fn update_stress<const D: usize>(
    m: &mut Model<D>,
    trial: &mut Trial<D>,
    st: &Stencils<D>,
    map: &NodeMap,
    velocity: &[Vector<D>],
    dt: f64,
    step: usize,
    t: f64,
) -> Result<(), Divergence> {
    let u: Vec<Vector<D>> = velocity.iter().map(|v| v * dt).collect();
    trial
        .advance(&mut m.particles, &m.materials, st, map, &u, dt)
        .map_err(|(q, det)| inverted(q, det, step + 1, t + dt))
}
