//! Contact with rigid bodies in the implicit solver (quasi-static and Newmark).
//!
//! A rigid body with a prescribed motion is not part of the grid problem: its
//! particles touch no node (their stencils are emptied) and move at their
//! velocity when a step is committed. Its `[[body]]` geometry, carried by that
//! motion to the end of the step, is the master surface of a penalty contact
//! (`physics::rigid_penalty`) with every deformable particle of a body declared
//! in contact with it: a particle at x_p(u) = x_p + Σ_I S_Ip u_I inside the body
//! feels f_p, which enters the residual like an external force and the tangent
//! through its derivative:
//!
//!   r_I −= S_Ip f_p,   K_IJ −= S_Ip S_Jp ∂f_p/∂x_p.
//!
//! The penalty of particle p is ε_n = ε_t = α M_p A_p / h (α the contact's
//! `penalty_factor`, M_p its material's P-wave modulus, A_p = V⁰_p^{(D−1)/D} its
//! face, h the smallest cell size): a particle pressed by a traction t sinks
//! g ≈ t h / (α M) into the body, which the run reports (summary.json's
//! `contact_penetration`, the deepest of the converged steps).
//! The tangential force at the step start of each particle in contact is kept
//! for the next step (stick carries over steps).

use super::assembly::{Components, Dofs, Pattern, Tangent};
use crate::dim::Vector;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::contact::{pair_position, pair_totals, PairTotal};
use crate::physics::rigid_body::to3;
use crate::physics::rigid_penalty::{penalty_force, ParticleContact, Penalty};
use crate::physics::rigid_surface::{on_grid_boundary, rigid_surfaces, Placement, Surface};
use crate::physics::shape::Stencils;
use crate::physics::transfer::{interpolate, NodeMap};
use crate::scene::contact::ContactPlan;
use rayon::prelude::*;

/// A particle in contact at the last evaluation of the residual.
#[derive(Clone, Copy, Debug)]
pub struct Touch<const D: usize> {
    pub particle: usize,
    /// Index of the rigid body in `RigidContact::surfaces`.
    pub surface: usize,
    pub contact: ParticleContact<D>,
}

/// The implicit solver's contact with rigid bodies.
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
    /// Contacts at the last residual, in particle order.
    pub touches: Vec<Touch<D>>,
    totals: Vec<PairTotal<D>>,
    /// The deepest penalty depth of a converged step so far.
    pub deepest: f64,
}

impl<const D: usize> RigidContact<D> {
    /// The contact of model m with rigid bodies, or None without any.
    pub fn new(m: &Model<D>) -> Option<Self> {
        let plan = m.contact.clone()?;
        let p = &m.particles;
        let field: Vec<u32> = (p.body.iter())
            .map(|&b| plan.field_of_body[b as usize])
            .collect();
        let paired = |k: usize| (0..plan.fields).any(|j| plan.law(k as u32, j as u32).is_some());
        let surfaces = rigid_surfaces(&plan, m, &field, &paired);
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
            true => vec![Vector::<D>::zeros(); p.len()],
            false => Vec::new(),
        };
        let totals = pair_totals(&plan);
        Some(RigidContact {
            plan,
            field,
            surfaces,
            slave,
            tangential,
            end: Vec::new(),
            motion: Vec::new(),
            touches: Vec::new(),
            totals,
            deepest: 0.0,
        })
    }

    /// Whether particle q belongs to a rigid body (it stays off the grid).
    pub fn is_rigid(&self, q: usize) -> bool {
        self.plan.rigid[self.field[q] as usize]
    }

    /// Empty the stencils of the rigid bodies' particles.
    pub fn leave_out_rigid(&self, st: &mut Stencils<D>) {
        for q in (0..self.field.len()).filter(|&q| self.is_rigid(q)) {
            st.count[q] = 0;
        }
    }

    /// The rigid bodies' motion over the step t → t + dt (their particles'
    /// velocity) and their placements at its end.
    pub fn start_step(&mut self, p: &Particles<D>, dt: f64) {
        self.motion = (self.surfaces.iter())
            .map(|s| p.v[s.particle()] * dt)
            .collect();
        self.end = (self.surfaces.iter().zip(&self.motion))
            .map(|(s, u)| s.placement(p).shifted(&to3(u)))
            .collect();
        self.touches.clear();
    }

    /// The contacts at the nodal displacement increments u (`touches`).
    pub fn evaluate(&mut self, m: &Model<D>, st: &Stencils<D>, map: &NodeMap, u: &[Vector<D>]) {
        let p = &m.particles;
        let on_boundary = on_grid_boundary(&m.grid);
        let h = m.grid.h_min();
        let this = &*self;
        let touches = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|&q| this.slave[this.field[q] as usize] && st.count[q] > 0)
            .filter_map(|q| {
                let dx = interpolate(map, st, q, u);
                let x = p.x[q] + dx;
                let (f, ell) = (this.field[q], &p.half_length0[q]);
                (this.surfaces.iter().enumerate()).find_map(|(k, s)| {
                    let law = this.plan.law(f, s.field)?;
                    let inside = s.reached(&this.end[k], &x, ell, &on_boundary)?;
                    // ε = α M A / h.
                    let modulus = m.materials[p.material[q] as usize].p_wave_modulus();
                    let face = p.volume0[q].powf((D as f64 - 1.0) / D as f64);
                    let epsilon = law.penalty_factor * modulus * face / h;
                    let penalty = Penalty {
                        normal: epsilon,
                        tangential: epsilon,
                        friction: law.friction,
                    };
                    let f_t0 = this
                        .tangential
                        .get(q)
                        .copied()
                        .unwrap_or(Vector::<D>::zeros());
                    let relative = dx - this.motion[k];
                    Some(Touch {
                        particle: q,
                        surface: k,
                        contact: penalty_force(&penalty, &inside, &relative, &f_t0),
                    })
                })
            })
            .collect();
        self.touches = touches;
    }

    /// r_I −= S_Ip f_p over the particles in contact.
    pub fn add_residual(&self, map: &NodeMap, st: &Stencils<D>, r: &mut [Vector<D>]) {
        for t in &self.touches {
            for e in st.range(t.particle) {
                r[map.local_of(st, e)] -= t.contact.force * st.weight[e];
            }
        }
    }

    /// Whether every contact's derivative is symmetric (plane faces, no slip).
    pub fn symmetric(&self) -> bool {
        self.touches.iter().all(|t| {
            let d = &t.contact.derivative;
            (d - d.transpose()).amax() <= 1e-10 * d.amax()
        })
    }

    /// K_IJ −= S_Ip S_Jp ∂f_p/∂x_p over the particles in contact.
    pub fn add_tangent(
        &self,
        k: &mut Tangent,
        pattern: &Pattern,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
    ) {
        if self.touches.is_empty() {
            return;
        }
        let (csc, storage) = (k.pattern, k.storage);
        let touches = &self.touches;
        pattern.add_stencil_terms(
            &mut k.values,
            csc,
            storage,
            map,
            st,
            dofs,
            Components::All,
            |q, e2, needed, block| {
                let Ok(i) = touches.binary_search_by_key(&q, |t| t.particle) else {
                    return false;
                };
                let d = &touches[i].contact.derivative;
                for (local, e1) in st.range(q).enumerate() {
                    if !needed[local] {
                        continue;
                    }
                    let w = -st.weight[e1] * st.weight[e2];
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

    /// The converged step: the tangential forces carried to the next step, the
    /// contact forces into the pair totals (force × dt), and the rigid bodies'
    /// particles moved by their motion.
    pub fn commit(&mut self, p: &mut Particles<D>, dt: f64) {
        self.deepest = self.deepest.max(self.max_penetration());
        if !self.tangential.is_empty() {
            self.tangential
                .iter_mut()
                .for_each(|f| *f = Vector::<D>::zeros());
            for t in &self.touches {
                self.tangential[t.particle] = t.contact.tangential;
            }
        }
        for total in &mut self.totals {
            total.nodes = 0;
        }
        for t in &self.touches {
            let (r, s) = (self.field[t.particle], self.surfaces[t.surface].field);
            let (lo, hi) = (r.min(s) as usize, r.max(s) as usize);
            let i = pair_position(self.plan.fields, lo, hi);
            let sign = if r < s { 1.0 } else { -1.0 };
            let total = &mut self.totals[i];
            total.impulse += t.contact.force * (sign * dt);
            total.nodes += 1;
            total.dissipation += t.contact.dissipation;
        }
        for q in 0..p.len() {
            if self.is_rigid(q) {
                p.x[q] += p.v[q] * dt;
            }
        }
    }

    /// The tangential forces carried to the next step, D values per particle
    /// (empty without friction), for a checkpoint.
    pub fn tangential_state(&self) -> Vec<f64> {
        (self.tangential.iter())
            .flat_map(|f| f.iter().copied())
            .collect()
    }

    /// Continue with the tangential forces of a checkpoint (`tangential_state`;
    /// nothing happens with an empty one).
    pub fn restore_tangential(&mut self, state: &[f64]) {
        if state.len() == self.tangential.len() * D {
            self.tangential = (state.chunks_exact(D))
                .map(Vector::<D>::from_column_slice)
                .collect();
        }
    }

    /// The contact force on each of `n` particles at the last residual (zero
    /// for particles out of contact and for the rigid bodies' own).
    pub fn particle_forces(&self, n: usize) -> Vec<Vector<D>> {
        let mut f = vec![Vector::<D>::zeros(); n];
        for t in &self.touches {
            f[t.particle] += t.contact.force;
        }
        f
    }

    /// The deepest penetration at the last residual.
    pub fn max_penetration(&self) -> f64 {
        (self.touches.iter()).fold(0.0, |g, t| g.max(t.contact.depth))
    }

    /// The totals since the last call, reset.
    pub fn take_totals(&mut self) -> Vec<PairTotal<D>> {
        let out = self.totals.clone();
        for t in &mut self.totals {
            t.impulse = Vector::<D>::zeros();
            t.dissipation = 0.0;
        }
        out
    }
}
