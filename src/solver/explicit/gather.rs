//! The node-map back-end of the explicit step (`solver::explicit::step`): the
//! particles' stencils stored for the step, the active nodes and, per node,
//! the entries that touch it (`physics::transfer::NodeMap`); P2G by node-side
//! gathers in increasing particle order, G2P and the stress update by
//! particle-side reads through the map. Every feature runs here, and those
//! that need a node map run only here (`solver::explicit::features`): contact
//! between bodies (split nodes, rigid bodies), CPDI, the mirror at faces with
//! prescribed velocities, USF with the families that read F.

use crate::dim::Vector;
use crate::model::body::Advance;
use crate::model::conditions::{Constraint, FrictionFace};
use crate::model::{load_factor, Model};
use crate::parallel::{deterministic_sum, MIN_PARALLEL_LEN};
use crate::physics::boundary::absorbing;
use crate::physics::boundary::conditions::{node_constraint, node_friction};
use crate::physics::contact::totals::PairTotal;
use crate::physics::kinematics::deformation::Trial;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::{
    interpolate_two, mass_average, mass_momentum, nodal_force, stencils_and_nodes, NodeMap,
};
use crate::scene::Scheme;
use crate::solver::divergence::{check_state, inverted, Divergence};
use crate::solver::explicit::apic::{self, AffineMomentum};
use crate::solver::explicit::contact::{Contact, Pass};
use crate::solver::explicit::grid_update::{
    acceleration, local_damping, updated_velocity, with_conditions,
};
use crate::solver::explicit::mirror::Mirror;
use crate::solver::explicit::motion::{blend, load_power};
use crate::solver::explicit::step::{removed_particles, Backend, P2g, Start, Step, Then, Velocity};
use rayon::prelude::*;

/// The node map's state: what a step builds, kept between steps for its buffers.
#[derive(Debug, Default)]
pub struct NodeMapStep<const D: usize> {
    stencils: Stencils<D>,
    pub map: NodeMap,
    trial: Trial<D>,
    /// Contact between bodies (`solver::explicit::contact`), when the scene has some.
    contact: Option<Contact<D>>,
    /// Per active node: its constraint, and the friction faces of the nodes on some.
    constraint: Vec<Constraint<D>>,
    friction: Vec<(usize, Vec<u8>)>,
    /// The friction faces with their walls' velocities this step
    /// (`Model::walls_during`).
    walls: Vec<FrictionFace<D>>,
    mirror: Mirror,
    /// APIC: the active nodes' positions.
    positions: Vec<Vector<D>>,
    /// Per particle: removed from the transfers this step (`Model::removed` at
    /// the step start; empty when the scene removes none).
    removed: Vec<bool>,
    /// MUSL with APIC: the particles' positions at the step start.
    step_start_x: Option<Vec<Vector<D>>>,
    mass: Vec<f64>,
    momentum: Vec<Vector<D>>,
    force: Vec<Vector<D>>,
    /// p/m at the step start (with the mirror and contact), then with the conditions.
    raw_velocity: Vec<Vector<D>>,
    velocity: Vec<Vector<D>>,
    /// The grid update's acceleration and velocity.
    accel: Vec<Vector<D>>,
    velocity_new: Vec<Vector<D>>,
}

impl<const D: usize> NodeMapStep<D> {
    /// What contact between bodies did since the last call, per pair of fields.
    pub fn take_contact(&mut self) -> Vec<PairTotal<D>> {
        self.contact
            .as_mut()
            .map_or_else(Vec::new, |c| c.take_totals())
    }

    /// The contact force on every particle in the last step
    /// (`Contact::particle_forces`); None without contact.
    pub fn contact_forces(&self, m: &Model<D>) -> Option<Vec<Vector<D>>> {
        (self.contact.as_ref())
            .map(|c| c.particle_forces(&self.stencils, &self.map, &self.mass, &m.particles))
    }

    /// After G2P, the one place of the explicit step that hands each body
    /// kind its work (`model::body::Advance`): continuum bodies moved with the
    /// grid in G2P, and so did a prescribed rigid body (its nodes move at its
    /// velocity); peridynamic bodies advance from the step start by their
    /// bond forces, gravity and loads (`physics::peridynamics::advance`),
    /// replacing what G2P gave them; free rigid bodies advance by Newton–Euler
    /// under the step's contact impulses and the applied forces
    /// (`physics::rigid::newton_euler`). Then the deformable particles that
    /// entered a rigid body are put back on its surface. Rigid bodies meet the
    /// rest through contact only, so a scene without contact has none
    /// (`scene::validate`).
    fn advance_bodies(&mut self, m: &mut Model<D>, s: &Step<D>) {
        let (mut by_bonds, mut newton_euler) = (false, false);
        for b in &m.bodies {
            match b.kind.advance() {
                Advance::ByGrid | Advance::AtOwnVelocity => {}
                Advance::ByBonds => by_bonds = true,
                Advance::NewtonEuler => newton_euler = true,
            }
        }
        if let (true, Some(pd)) = (by_bonds, &mut m.peridynamics) {
            let p = &mut m.particles;
            let (ramp_of, mass, load) = (&m.load_ramp_of, &p.mass, &p.load);
            let applied = |q: usize| s.applied(ramp_of, mass, load, q);
            let meets = (self.contact.as_mut()).filter(|c| c.bonded_meets_continuum());
            let meets = meets.map(|c| {
                c.deliver_to_bonded(&self.stencils, &self.map, mass);
                &*c
            });
            let kick = meets.map(|c| move |q: usize| c.bonded_kick(q) * (mass[q] / s.dt));
            for b in pd.bodies.iter_mut() {
                let contact = kick.as_ref().map(|k| k as &dyn Fn(usize) -> Vector<D>);
                crate::physics::peridynamics::advance(
                    b, &mut p.x, &mut p.v, mass, applied, contact, s.dt,
                );
            }
        }
        let Some(c) = &mut self.contact else {
            return;
        };
        if let (true, Some(free)) = (newton_euler, c.free_bodies()) {
            let p = &m.particles;
            let force: Vec<Vector<D>> = (free.particles())
                .map(|q| s.applied(&m.load_ramp_of, &p.mass, &p.load, q))
                .collect();
            free.advance(&mut m.particles, &force, m.axisymmetric, s.dt);
        }
        c.keep_out_of_rigid_bodies(m);
    }

    /// Peridynamic bodies that meet continuum ones at the nodes
    /// (`Contact::bonded_meets_continuum`): their particles' bond and
    /// short-range forces to their nodes (`physics::peridynamics::grid_force`),
    /// so that their field's updated velocity is where the bonds take them.
    fn add_bond_forces(&mut self, m: &Model<D>) {
        let (Some(pd), Some(c)) = (&m.peridynamics, &self.contact) else {
            return;
        };
        if !c.bonded_meets_continuum() {
            return;
        }
        let mut on: Vec<Option<Vector<D>>> = vec![None; m.particles.len()];
        for b in &pd.bodies {
            for (i, &q) in b.particles.iter().enumerate() {
                on[q] = Some(crate::physics::peridynamics::grid_force(b, i));
            }
        }
        let st = &self.stencils;
        let bonds = self.map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
            on[q].map_or_else(Vector::<D>::zeros, |f| f * st.weight_at(q, e))
        });
        for (f, b) in self.force.iter_mut().zip(bonds) {
            *f += b;
        }
    }

    /// Does particle q take a share of the loads' work? Not when it is
    /// removed, nor when its body moves at its own velocity (a prescribed
    /// rigid motion takes the work done on it).
    fn takes_load_work(&self, m: &Model<D>, q: usize) -> bool {
        let removed = self.removed.get(q).is_some_and(|&r| r);
        let own_motion = match m.kind_of(q).advance() {
            Advance::ByGrid | Advance::NewtonEuler | Advance::ByBonds => false,
            Advance::AtOwnVelocity => true,
        };
        !removed && !own_motion
    }

    /// APIC: the particles' affine moments B_p from the updated nodes, where
    /// the particles are before they move.
    fn affine_moments(&self, m: &mut Model<D>) {
        let (st, map, velocity_new) = (&self.stencils, &self.map, &self.velocity_new);
        let (mp, positions) = (&mut m.particles, &self.positions);
        let x = &mp.x;
        mp.affine = (0..mp.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| apic::moment(map, st, q, &x[q], positions, velocity_new))
            .collect();
    }

    /// G2P: the particles' velocity (PIC/FLIP blend, 2-27) and position
    /// (2-26) from the updated nodes; returns their step-start velocities.
    /// Removed particles (`physics::transfer::stencils` gave them no stencil)
    /// keep theirs.
    fn move_particles(&self, m: &mut Model<D>, s: &Step<D>) -> Vec<Vector<D>> {
        let (st, map, removed) = (&self.stencils, &self.map, &self.removed);
        let (accel, velocity_new) = (&self.accel, &self.velocity_new);
        let mp = &mut m.particles;
        let old_v = mp.v.clone();
        mp.v.par_iter_mut()
            .zip(mp.x.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter(|(q, _)| !removed.get(*q).is_some_and(|&r| r))
            .for_each(|(q, (v, x))| {
                let (a, v_pic) = interpolate_two(map, st, q, accel, velocity_new);
                *v = blend(v, &a, &v_pic, s.flip, s.dt);
                *x += v_pic * s.dt;
            });
        old_v
    }

    /// The work of the loads over the step on the particles that take a share
    /// (`takes_load_work`), from their velocities at the step's start `old_v`
    /// and end.
    fn work_of_loads(&self, m: &Model<D>, s: &Step<D>, old_v: &[Vector<D>]) -> f64 {
        let p = &m.particles;
        let power = |q: usize| {
            let applied = s.applied(&m.load_ramp_of, &p.mass, &p.load, q);
            load_power(&applied, &old_v[q], &p.v[q])
        };
        let counted = |q: usize| match self.takes_load_work(m, q) {
            true => power(q),
            false => 0.0,
        };
        s.dt * deterministic_sum(p.len(), counted)
    }

    /// MUSL: the particles' updated momentum mapped back to the nodes (APIC:
    /// with the affine part, where the particles were at the step start).
    fn remap(&mut self, m: &Model<D>, s: &Step<D>) {
        let (st, map, p) = (&self.stencils, &self.map, &m.particles);
        let x = self.step_start_x.as_deref().unwrap_or(&p.x);
        let affine = self.affine(m, x, s);
        let term = affine.as_ref().map(|a| move |q, e, n| a.term(st, q, e, n));
        (_, self.momentum) = mass_momentum(map, st, p, term.as_ref().map(|t| t as _));
    }

    /// The nodes' conditions this step: their constraints, the friction faces
    /// of the nodes on some, and the mirror's lines.
    fn node_conditions(&mut self, m: &Model<D>, s: &Step<D>) {
        let map = &self.map;
        let faces = m.faces_during(s.t, s.dt);
        self.constraint = (0..map.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| node_constraint(&m.grid, &faces, map.grid_node(a)))
            .collect();
        self.friction = friction_nodes(m, map);
        self.walls = m.walls_during(s.t, s.dt).into_owned();
        // Cubic and domain-averaged B-splines: the image problem's masses at faces
        // with prescribed velocities. Point-sampled quadratic B-splines keep the
        // clamped masses: the mirror removes their O(ε) stress error at the face
        // too, but their knot-crossing quadrature error then dominates and makes the
        // refinement sequence non-monotone (docs/accuracy.md); the suite's target
        // for them (tests/verification/column_explicit.rs) stays as it was.
        self.mirror = match s.shape {
            ShapeFunction::Bspline2 => Mirror::default(),
            _ => Mirror::build(&m.grid, &faces, map),
        };
    }

    /// The stress update from nodal velocities `velocity` (2-31, 2-32): the
    /// shared deformation update with the nodal displacement u_I = Δt v_I,
    /// then the Darcy flow of coupled pore water.
    fn update_stress_from(
        &mut self,
        m: &mut Model<D>,
        s: &Step<D>,
        velocity: &[Vector<D>],
    ) -> Result<(), Divergence> {
        let u: Vec<Vector<D>> = velocity.iter().map(|v| v * s.dt).collect();
        let (st, map) = (&self.stencils, &self.map);
        (self.trial)
            .advance(&mut m.particles, &m.materials, st, map, &u, s.dt)
            .map_err(|(q, det)| inverted(q, det, s.step + 1, s.t + s.dt))?;
        // Coupled pore water: the flow part of its storage equation, after
        // each point's undrained part (`physics::pore_flow`).
        crate::physics::pore_flow::darcy_step(m, st, map, s.dt);
        Ok(())
    }

    /// Nodal velocities of `momentum` over the nodal masses, with the mirror
    /// (`mirror`), contact correcting them as pass `pass` (`Contact::correct`)
    /// and the conditions: the raw one and the conditioned one.
    fn velocity_of(
        &mut self,
        momentum: &[Vector<D>],
        dt: f64,
        pass: Pass,
    ) -> (Vec<Vector<D>>, Vec<Vector<D>>) {
        let mut raw = mass_average(&self.mass, momentum);
        self.mirror.velocity(&self.mass, momentum, &mut raw);
        if let Some(c) = &mut self.contact {
            c.correct(&self.mass, &mut raw, dt, pass);
        }
        let velocity = self.conditioned(&raw);
        (raw, velocity)
    }

    /// The velocities `raw` with the conditions of their nodes.
    fn conditioned(&self, raw: &[Vector<D>]) -> Vec<Vector<D>> {
        let mut v: Vec<Vector<D>> = (raw.iter().zip(&self.constraint))
            .map(|(v, c)| with_conditions(v, c, &self.walls, &[]))
            .collect();
        for (a, on) in &self.friction {
            v[*a] = with_conditions(&raw[*a], &self.constraint[*a], &self.walls, on);
        }
        v
    }

    /// The affine momentum of APIC for P2G at the particles' positions `x`.
    fn affine<'a>(
        &'a self,
        m: &'a Model<D>,
        x: &'a [Vector<D>],
        s: &Step<D>,
    ) -> Option<AffineMomentum<'a, D>> {
        (s.apic).then(|| {
            AffineMomentum::new(
                &self.map,
                &self.stencils,
                &m.particles,
                x,
                &self.positions,
                s.shape,
            )
        })
    }
}

impl<const D: usize> Backend<D> for NodeMapStep<D> {
    fn locate(&mut self, m: &mut Model<D>, s: &Step<D>) {
        if s.apic {
            apic::ensure(m, s.shape);
        }
        self.removed = removed_particles(m);
        if let Some(pd) = &mut m.peridynamics {
            pd.begin_step(&m.particles.x, &m.particles.v);
            crate::physics::peridynamics::step_forces(&mut pd.bodies, s.dt);
        }
        if let (None, Some(plan)) = (&self.contact, &m.contact) {
            self.contact = Some(Contact::new(plan.clone(), m));
        }
        let (st, map) = (&mut self.stencils, &mut self.map);
        match &mut self.contact {
            None => stencils_and_nodes(m, s.shape, st, map),
            Some(c) => c.stencils_and_fields(m, s.shape, st, map),
        }
        if s.fbar {
            self.trial.use_fbar(&m.grid, &m.particles.x);
        }
        self.node_conditions(m, s);
        self.positions = match s.apic {
            true => apic::node_positions(&self.map, &m.grid),
            false => Vec::new(),
        };
        self.step_start_x = (s.apic && s.scheme == Scheme::Musl).then(|| m.particles.x.clone());
    }

    /// P2G through the node map's gathers (`physics::transfer`, which the
    /// implicit step shares): at every active node its entries in increasing
    /// particle order.
    fn p2g(&mut self, m: &Model<D>, s: &Step<D>, what: P2g) {
        let (st, map, p) = (&self.stencils, &self.map, &m.particles);
        if what != P2g::Force {
            // APIC: the affine part of the momentum.
            let affine = self.affine(m, &p.x, s);
            let term = affine.as_ref().map(|a| move |q, e, n| a.term(st, q, e, n));
            (self.mass, self.momentum) = mass_momentum(map, st, p, term.as_ref().map(|t| t as _));
        }
        if what != P2g::Motion {
            let factor = |q: usize| load_factor(&m.load_ramp_of, q, &s.scales);
            self.force = nodal_force(map, st, p, &s.gravity, &factor);
            self.add_bond_forces(m);
        }
    }

    fn start_velocity(&mut self, _m: &Model<D>, s: &Step<D>) {
        // Contact after P2G: its momentum reaches the particles through the PIC part.
        let momentum = std::mem::take(&mut self.momentum);
        (self.raw_velocity, self.velocity) = self.velocity_of(
            &momentum,
            s.dt,
            Pass::StepStart {
                delivered: 1.0 - s.flip,
            },
        );
        self.momentum = momentum;
    }

    fn start_forces(&mut self, m: &Model<D>, s: &Step<D>) {
        let (st, map, p) = (&self.stencils, &self.map, &m.particles);
        if let Some(v) = &s.viscosity {
            let l = m.grid.h_min();
            v.add_force(map, st, p, &m.materials, &self.velocity, l, &mut self.force);
        }
        // Absorbing faces: dashpot (and spring) forces on the outer cell layer (2-63).
        absorbing::add_force(
            &m.absorbing,
            &m.grid,
            p,
            map,
            st,
            &self.velocity,
            s.t,
            &mut self.force,
        );
    }

    fn grid_update(&mut self, m: &Model<D>, s: &Step<D>, start: Start) {
        if start == Start::Form {
            self.start_velocity(m, s);
        }
        let (mass, force, constraint) = (&self.mass, &self.force, &self.constraint);
        let (raw, velocity) = (&self.raw_velocity, &self.velocity);
        self.accel = (0..self.map.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| {
                let c = &constraint[a];
                acceleration(
                    mass[a],
                    &force[a],
                    &velocity[a],
                    &raw[a],
                    c,
                    s.damping,
                    s.tiny,
                    s.dt,
                )
            })
            .collect();
        let damped = |f: f64, v: f64| {
            local_damping(&Vector::<1>::new(f), &Vector::<1>::new(v), s.damping)[0]
        };
        self.mirror
            .acceleration(mass, force, velocity, damped, &mut self.accel);
        self.velocity_new = (0..self.map.len())
            .map(|a| updated_velocity(&raw[a], &self.accel[a], &constraint[a], &[], &[], s.dt).0)
            .collect();
        // Friction faces act on the updated velocity; the acceleration follows.
        for (a, on) in &self.friction {
            let (v, acc) = updated_velocity(
                &raw[*a],
                &self.accel[*a],
                &constraint[*a],
                &self.walls,
                on,
                s.dt,
            );
            (self.velocity_new[*a], self.accel[*a]) = (v, acc);
        }
        // Contact after the grid update (rigid bodies' nodes keep their velocity:
        // zero acceleration); prescribed components win.
        if let Some(c) = &mut self.contact {
            for a in c.correct(mass, &mut self.velocity_new, s.dt, Pass::Updated) {
                constraint[a].apply_velocity(&mut self.velocity_new[a]);
                self.accel[a] = (self.velocity_new[a] - raw[a]) / s.dt;
            }
        }
    }

    fn g2p(&mut self, m: &mut Model<D>, s: &Step<D>, then: Then) -> Result<f64, Divergence> {
        if s.apic {
            self.affine_moments(m);
        }
        let old_v = self.move_particles(m, s);
        self.advance_bodies(m, s);
        let work = self.work_of_loads(m, s, &old_v);
        match then {
            Then::Stress => {
                let velocity_new = std::mem::take(&mut self.velocity_new);
                let updated = self.update_stress_from(m, s, &velocity_new);
                self.velocity_new = velocity_new;
                updated?;
            }
            Then::Remap => self.remap(m, s),
            Then::Nothing => {}
        }
        Ok(work)
    }

    fn remapped_velocity(&mut self, _m: &Model<D>, s: &Step<D>) {
        let momentum = std::mem::take(&mut self.momentum);
        (_, self.velocity) = self.velocity_of(&momentum, s.dt, Pass::Remapped);
        self.momentum = momentum;
    }

    fn update_stress(
        &mut self,
        m: &mut Model<D>,
        s: &Step<D>,
        _from: Velocity,
    ) -> Result<(), Divergence> {
        // USF: the step-start velocity; MUSL: the remapped one (`remapped_velocity`).
        let velocity = std::mem::take(&mut self.velocity);
        let updated = self.update_stress_from(m, s, &velocity);
        self.velocity = velocity;
        updated
    }

    fn check(&self, m: &Model<D>, s: &Step<D>) -> Result<(), Divergence> {
        check_state(m, s.step + 1, s.t + s.dt)
    }
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
