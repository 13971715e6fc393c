//! Penalty contact of deformable particles with rigid bodies (quasi-static and
//! Newmark steps).
//!
//! A rigid body with a prescribed motion is off the step's grid
//! (`super::super::super::grid`). Its `[[body]]` geometry, carried by that
//! motion to the end of the step, is the master surface of a penalty contact
//! (`super::penalty`) with every deformable particle of a body declared in
//! contact with it: a particle at x_p(u) = x_p + Σ_I S_Ip u_I inside the body
//! feels f_p, which enters the residual like an external force and the tangent
//! through its derivative:
//!
//!   r_I −= S_Ip f_p,   K_IJ −= S_Ip S_Jp ∂f_p/∂x_p.
//!
//! With linear hats or a particle-domain basis the point that touches is the
//! particle's contact point instead (`super::points`), and S_Ip above becomes
//! N_I(c).
//!
//! The penalty of particle p is ε_n = ε_t = α M_p A_p / h (α the contact's
//! `penalty_factor`, M_p its material's P-wave modulus, A_p = V⁰_p^{(D−1)/D} its
//! face, h the smallest cell size): a particle pressed by a traction t sinks
//! g ≈ t h / (α M) into the body, which the run reports (summary.json's
//! `contact_penetration`, the deepest of the converged steps). The tangential
//! force at the step start of each particle in contact is kept for the next
//! step (stick carries over steps).

use super::penalty::{penalty_force, ParticleContact, Penalty};
use super::points::ContactPoints;
use super::state::{hand_over, read_points, write_points};
use crate::dim::Vector;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::contact::field_split::pair_position;
use crate::physics::contact::totals::{pair_totals, PairTotal};
use crate::physics::rigid::newton_euler::to3;
use crate::physics::rigid::surface::{on_grid_boundary, Placement, Surface};
use crate::physics::transfer::interpolate;
use crate::scene::contact::ContactPlan;
use crate::solver::implicit::assembly::stiffness::ParticleTangents;
use crate::solver::implicit::assembly::{Components, Coupling, Tangent};
use crate::solver::implicit::terms::{Restore, StepStart, StepTerm, StepView, TermReport};
use crate::solver::stepper::SolverState;
use rayon::prelude::*;

/// A particle in contact with a rigid body at the iterate.
#[derive(Clone, Copy, Debug)]
pub struct Touch<const D: usize> {
    pub particle: usize,
    /// Index of the rigid body in `RigidContact::surfaces`.
    pub surface: usize,
    pub contact: ParticleContact<D>,
    /// Whether it touches at its contact point (`super::points`: its force
    /// and motion go with the point's weights) or at its centre.
    pub at_point: bool,
    /// What round-off in the particle's position leaves in its force:
    /// ε_n × 2.2e-16 × (|x|∞ + |surface point|∞).
    pub round_off: f64,
}

/// The contacts with the rigid bodies at one displacement increment u.
#[derive(Clone, Debug, Default)]
struct Contacts<const D: usize> {
    /// The particles in contact, in particle order.
    touches: Vec<Touch<D>>,
    /// How far each contact point has moved, Σ N_I(c) u_I.
    point_motion: Vec<Option<Vector<D>>>,
}

/// The penalty contact of the deformable particles with the rigid bodies.
#[derive(Clone, Debug)]
pub struct RigidContact<const D: usize> {
    plan: ContactPlan,
    /// Field of each particle.
    field: Vec<u32>,
    /// The rigid bodies some deformable body is in contact with.
    surfaces: Vec<Surface>,
    /// Whether each field is deformable and in contact with a rigid body.
    slave: Vec<bool>,
    /// Tangential force of each particle at the step start (empty when every
    /// contact is frictionless).
    tangential: Vec<Vector<D>>,
    /// The rigid bodies' placements at the end of the step and their motion
    /// over it.
    end: Vec<Placement>,
    motion: Vec<Vector<D>>,
    points: ContactPoints<D>,
    /// The contacts at the iterate.
    at: Contacts<D>,
    totals: Vec<PairTotal<D>>,
    /// The deepest penalty depth of a converged step so far.
    deepest: f64,
}

impl<const D: usize> RigidContact<D> {
    /// The contact under `plan` of model m's deformable particles (each of
    /// `field`) with the rigid bodies `surfaces`, or None without any.
    pub fn new(
        m: &Model<D>,
        plan: &ContactPlan,
        field: &[u32],
        surfaces: Vec<Surface>,
    ) -> Option<Self> {
        if surfaces.is_empty() {
            return None;
        }
        let touches_some =
            |f: usize| (surfaces.iter()).any(|s| plan.law(f as u32, s.field).is_some());
        let slave: Vec<bool> = (0..plan.fields)
            .map(|f| !plan.rigid[f] && touches_some(f))
            .collect();
        let friction = (plan.laws.iter()).any(|l| l.is_some_and(|l| l.friction > 0.0));
        let tangential = match friction {
            true => vec![Vector::<D>::zeros(); m.particles.len()],
            false => Vec::new(),
        };
        Some(RigidContact {
            plan: plan.clone(),
            field: field.to_vec(),
            surfaces,
            slave,
            tangential,
            end: Vec::new(),
            motion: Vec::new(),
            points: ContactPoints::default(),
            at: Contacts::default(),
            totals: pair_totals(plan),
            deepest: 0.0,
        })
    }

    /// Particle q: of a field in contact with a rigid body, and on the grid.
    fn slave_on_grid(&self, q: usize, step: &StepView<'_, D>) -> bool {
        self.slave[self.field[q] as usize] && step.stencils.count[q] > 0
    }

    /// The contacts at the nodal displacement increments u.
    fn contacts(&self, step: &StepView<'_, D>, u: &[Vector<D>]) -> Contacts<D> {
        let (m, st, map) = (step.m, step.stencils, step.map);
        let p = &m.particles;
        let on_boundary = on_grid_boundary(&m.grid);
        let h = m.grid.h_min();
        let point_motion = self.points.motion(st, map, u);
        let touches = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&q| self.slave_on_grid(q, step))
            .filter_map(|q| {
                let f = self.field[q];
                let point = self.points.of(q);
                let touch = |k: usize, at_point: bool| {
                    let s = &self.surfaces[k];
                    let law = self.plan.law(f, s.field)?;
                    // At its contact point (a point: a reach of 1e-9 of the
                    // particle's), or at its centre with the particle's reach.
                    let point_reach = p.half_length0[q] * 1e-9;
                    let (x, dx, ell) = match (at_point, point) {
                        (true, Some((_, c))) => {
                            let dx = point_motion[q].expect("a contact point moves");
                            (c + dx, dx, &point_reach)
                        }
                        _ => {
                            let dx = interpolate(map, st, q, u);
                            (p.x[q] + dx, dx, &p.half_length0[q])
                        }
                    };
                    let inside = s.reached(&self.end[k], &x, ell, &on_boundary)?;
                    // ε = α M A / h.
                    let modulus = m.materials[p.material[q] as usize].p_wave_modulus();
                    let face = p.volume0[q].powf((D as f64 - 1.0) / D as f64);
                    let epsilon = law.penalty_factor * modulus * face / h;
                    let penalty = Penalty {
                        normal: epsilon,
                        tangential: epsilon,
                        friction: law.friction,
                    };
                    let f_t0 = (self.tangential.get(q).copied()).unwrap_or(Vector::<D>::zeros());
                    let relative = dx - self.motion[k];
                    let magnitude = x.amax() + inside.point.amax();
                    Some(Touch {
                        particle: q,
                        surface: k,
                        contact: penalty_force(&penalty, &inside, &relative, &f_t0),
                        at_point,
                        round_off: epsilon * f64::EPSILON * magnitude,
                    })
                };
                // The body its contact point faces at that point; the others
                // (a corner of two bodies) at its centre.
                let faced = point.map(|(k, _)| k);
                faced.and_then(|k| touch(k, true)).or_else(|| {
                    (0..self.surfaces.len())
                        .filter(|&k| Some(k) != faced)
                        .find_map(|k| touch(k, false))
                })
            })
            .collect();
        Contacts {
            touches,
            point_motion,
        }
    }

    /// r_I −= S_Ip f_p over the particles in contact.
    fn add_forces(&self, contacts: &Contacts<D>, step: &StepView<'_, D>, r: &mut [Vector<D>]) {
        let (st, map) = (step.stencils, step.map);
        for t in &contacts.touches {
            for e in st.range(t.particle) {
                r[map.local_of(st, e)] -= t.contact.force * self.points.weight(t.at_point, st, e);
            }
        }
    }
}

impl<const D: usize> StepTerm<D> for RigidContact<D> {
    fn name(&self) -> &'static str {
        "contact with rigid bodies"
    }

    fn cloned(&self) -> Box<dyn StepTerm<D>> {
        Box::new(self.clone())
    }

    /// The rigid bodies' motion over the step (their particles' velocity) and
    /// their placements at its end, and the particles' contact points.
    fn begin_step(&mut self, step: &StepView<'_, D>, start: &StepStart<'_, D>) {
        let (m, dt) = (step.m, step.dt);
        let p = &m.particles;
        self.motion = (self.surfaces.iter())
            .map(|s| p.v[s.particle()] * dt)
            .collect();
        self.end = (self.surfaces.iter().zip(&self.motion))
            .map(|(s, u)| s.placement(p).shifted(&to3(u)))
            .collect();
        self.at = Contacts::default();
        let on_boundary = on_grid_boundary(&m.grid);
        let mut points = std::mem::take(&mut self.points);
        let this = &*self;
        // The nearest of the bodies particle q is in contact with.
        let nearest = |q: usize, near: &Vector<D>| {
            if !this.slave[this.field[q] as usize] {
                return None;
            }
            (this.surfaces.iter().enumerate())
                .filter_map(|(k, s)| {
                    this.plan.law(this.field[q], s.field)?;
                    Some((k, s.reached(&this.end[k], &p.x[q], near, &on_boundary)?))
                })
                .max_by(|a, b| a.1.depth.total_cmp(&b.1.depth))
                .map(|(k, inside)| (k, inside.normal))
        };
        points.place(m, start.shape, step.stencils, step.map, nearest);
        self.points = points;
    }

    fn evaluate(&mut self, step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        self.at = self.contacts(step, u);
        self.add_forces(&self.at, step, r);
    }

    fn probe(&self, step: &StepView<'_, D>, u: &[Vector<D>], r: &mut [Vector<D>]) {
        self.add_forces(&self.contacts(step, u), step, r);
    }

    /// √Σ (ε_n ε_mach |x|)² over the particles in contact at the iterate. A
    /// particle's depth is a difference of positions (r − d, d from x and the
    /// surface point), so it carries round-off ε_mach |x| whatever u is, and
    /// its force ε_n times that: with ε_n = α M A / h this can exceed the
    /// residual tolerance (a block of E = 10 MPa resting on a rigid base with
    /// h = 0.05 m: 1–2.4e-9 of its weight against an estimate of 1.9e-9).
    fn residual_floor(&self) -> f64 {
        (self.at.touches.iter())
            .map(|t| t.round_off * t.round_off)
            .sum::<f64>()
            .sqrt()
    }

    /// K_IJ −= S_Ip S_Jp ∂f_p/∂x_p over the particles in contact.
    fn add_tangent(&self, step: &StepView<'_, D>, _a: &ParticleTangents<D>, k: &mut Tangent) {
        if self.at.touches.is_empty() {
            return;
        }
        let (map, st, dofs) = (step.map, step.stencils, step.dofs);
        let touches = &self.at.touches;
        k.add_terms(
            map,
            st,
            dofs,
            Coupling::<D, D>::displacements(Components::All),
            |q, e2, needed, block| {
                let Ok(i) = touches.binary_search_by_key(&q, |t| t.particle) else {
                    return false;
                };
                let (d, at_point) = (&touches[i].contact.derivative, touches[i].at_point);
                let w2 = self.points.weight(at_point, st, e2);
                for (local, e1) in st.range(q).enumerate() {
                    if !needed[local] {
                        continue;
                    }
                    let w = -self.points.weight(at_point, st, e1) * w2;
                    for a in 0..D {
                        for b in 0..D {
                            block[local * D * D + a * D + b] = w * d[(a, b)];
                        }
                    }
                }
                true
            },
        );
    }

    /// Symmetric while every contact's derivative is (plane faces, no slip).
    fn symmetric(&self) -> bool {
        (self.at.touches.iter()).all(|t| t.contact.is_symmetric())
    }

    /// The tangential forces and the contact points carried to the next
    /// step, the contact forces into the pair totals (force × dt).
    fn commit(&mut self, step: &StepView<'_, D>, _u: &[Vector<D>]) {
        self.points.carry(&self.at.point_motion);
        let deepest = (self.at.touches.iter()).map(|t| t.contact.depth);
        self.deepest = self.deepest.max(deepest.fold(0.0, f64::max));
        if !self.tangential.is_empty() {
            self.tangential
                .iter_mut()
                .for_each(|f| *f = Vector::<D>::zeros());
            for t in &self.at.touches {
                self.tangential[t.particle] = t.contact.tangential;
            }
        }
        for total in &mut self.totals {
            total.nodes = 0;
        }
        for t in &self.at.touches {
            let (r, s) = (self.field[t.particle], self.surfaces[t.surface].field);
            let (lo, hi) = (r.min(s) as usize, r.max(s) as usize);
            let i = pair_position(self.plan.fields, lo, hi);
            let sign = if r < s { 1.0 } else { -1.0 };
            let total = &mut self.totals[i];
            total.impulse += t.contact.force * (sign * step.dt);
            total.nodes += 1;
            total.dissipation += t.contact.dissipation;
        }
    }

    /// The particles' tangential forces (D values each, none without
    /// friction) and the carried contact points (`super::state`).
    fn save(&self, state: &mut SolverState) {
        let particles = self.tangential.iter().flat_map(|f| f.iter().copied());
        state.contact_tangential.extend(particles);
        state
            .contact_points
            .extend(write_points(&self.points.carried));
    }

    fn restore(&mut self, from: &mut Restore<'_>) {
        if let Some(values) = from.take_tangential(self.tangential.len() * D) {
            self.tangential = (values.chunks_exact(D))
                .map(Vector::<D>::from_column_slice)
                .collect();
        }
        let n = self.field.len();
        self.points.carried = read_points(&from.state.contact_points, n, self.surfaces.len());
    }

    fn report(&self, report: &mut TermReport) {
        report.penetration(self.deepest);
        report.contacts(self.at.touches.iter().map(|t| t.contact.slips));
    }

    fn take_pair_totals(&mut self, totals: &mut Vec<PairTotal<D>>) {
        hand_over(&mut self.totals, totals);
    }

    /// f_p of each particle in contact (zero for the others and for the
    /// rigid bodies' own).
    fn add_particle_forces(&self, forces: &mut [Vector<D>]) -> bool {
        for t in &self.at.touches {
            forces[t.particle] += t.contact.force;
        }
        true
    }
}
