//! Contact between bodies in the explicit solver: the multi-velocity-field method
//! (Bardenhagen, Brackbill & Sulsky, CMAME 187, 2000) with one common normal per
//! node, made collinear so that momentum is conserved, and the gap criterion of
//! Huang, Zhang, Ma & Huang (IJNME 85, 2011; review 002 eqs. 37–42), applied after
//! P2G and again after the grid update (Bardenhagen et al., CMES 2, 2001; Nairn,
//! Hammerquist & Smith, CMAME 362, 2020).
//!
//! **Split nodes and meetings** (`physics::contact::field_split`): every grid node that
//! particles of two or more velocity fields touch is split, one node per field,
//! so every transfer (mass, momentum, forces, the velocity gradient, G2P) works
//! per field there without change; a scene whose fields never share a node splits
//! nothing and runs bit for bit as without contact. Each pair of fields r < s at a
//! split node meets with one normal n from r to s (37; by default the maximum
//! volume gradient: the average tilts at the corners of a body sliding on another
//! and catches there, a block that should slide 0.87 m on a frictionless incline
//! slides 0.77 m with it, 0.864 m with the maximum, docs/contact.md), a nodal area
//! and the gap D between their surfaces.
//!
//! **Contact at a meeting**, fields r < s:
//! - approach: (v_r − v_s)·n > 0 (39);
//! - gap criterion: D ≤ λ h (42), h the smallest cell size;
//! - correction (41 and Coulomb): the momentum that sticking takes from r is
//!   P = m_r m_s/(m_r + m_s) (v_r − v_s); the contact removes its normal part P_n and
//!   of the tangential part P_t at most μ P_n + c A Δt (c the adhesion, A the
//!   nodal area |Σ_p V_p ∇S_Ip| averaged over r and s); s receives the opposite,
//!   so momentum is conserved to round-off.
//!
//! With three or more fields at a node the pairs are corrected one after another,
//! in field order.
//!
//! **Peridynamic bodies** are advanced by their bonds from the step start
//! (`physics::peridynamics::advance`), not by G2P. They meet continuum bodies
//! at the nodes all the same: their particles bring their mass, momentum and
//! this step's bond and short-range forces to the nodes of their own field
//! (`physics::peridynamics::grid_force`), so that field's updated velocity is
//! where the bonds take them. The momentum J_I exchanged at each of its nodes
//! reaches its particles through the consistent mass (`bonded_kicks`), so that
//! their momentum projected back on the nodes changes by J_I, as the
//! correction asked; it sums to Σ_I J_I, what the continuum field lost, so
//! momentum is conserved to round-off. (A continuum field takes its share by
//! FLIP: its stress follows the corrected nodal velocities; a peridynamic
//! field's bond forces follow its particles alone.) They meet rigid bodies
//! by the rigid projection alone (`keep_out_of_rigid_bodies`, the push-out of
//! seed 003 eqs. 28–29), which conserves momentum between the two to
//! round-off, and other peridynamic bodies by their short-range repulsion.

use crate::dim::Vector;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::contact::field_split::{pair_position, FieldSplit, Meeting};
use crate::physics::contact::totals::{pair_totals, PairTotal};
use crate::physics::rigid::newton_euler::FreeBodies;
use crate::physics::rigid::surface::{on_grid_boundary, rigid_surfaces, Push, Surface};
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::NodeMap;
use crate::scene::contact::ContactPlan;
use rayon::prelude::*;

/// The nodal velocities a contact pass corrects (`Contact::correct`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pass {
    /// After P2G, the step-start velocities: the PIC fraction `delivered`
    /// (1 − FLIP) of the exchange reaches the particles.
    StepStart { delivered: f64 },
    /// After the grid update: all of it reaches the particles.
    Updated,
    /// MUSL's remapped velocities, for the stress update alone: none does.
    Remapped,
}

impl Pass {
    /// The fraction of the exchange that reaches the particles.
    pub fn delivered(self) -> f64 {
        match self {
            Pass::StepStart { delivered } => delivered,
            Pass::Updated => 1.0,
            Pass::Remapped => 0.0,
        }
    }
}

/// The contact state of an explicit run.
#[derive(Debug)]
pub struct Contact<const D: usize> {
    plan: ContactPlan,
    /// Field of each particle.
    field: Vec<u32>,
    /// The split of the shared nodes (`physics::contact::field_split`).
    fields: FieldSplit,
    meetings: Vec<Meeting<D>>,
    /// Active nodes of rigid fields this step, with the rigid body's velocity.
    rigid_nodes: Vec<(usize, Vector<D>)>,
    totals: Vec<PairTotal<D>>,
    /// The free rigid bodies (`physics::rigid::newton_euler`), if any.
    free: Option<FreeBodies<D>>,
    /// The rigid fields that keep deformable particles out
    /// (`physics::rigid::surface`).
    surfaces: Vec<Surface>,
    /// This step's momentum exchanged at each node (by the node map's index),
    /// as far as it reaches the particles (the `delivered` fractions), and
    /// the momentum the rigid surfaces gave particles they pushed out, with
    /// the step's Δt: the per-particle forces (`particle_forces`).
    node_impulse: Vec<Vector<D>>,
    pushed: Vec<(usize, Vector<D>)>,
    /// This step's velocity change of the peridynamic particles the exchange
    /// reached, by particle (`deliver_to_bonded`).
    kicks: Vec<(usize, Vector<D>)>,
    dt: f64,
}

impl<const D: usize> Contact<D> {
    /// The contact state of a run of model m with `plan`.
    pub fn new(plan: ContactPlan, m: &Model<D>) -> Self {
        let particles = &m.particles;
        let field: Vec<u32> = particles
            .body
            .iter()
            .map(|&b| plan.field_of_body[b as usize])
            .collect();
        let totals = pair_totals(&plan);
        Contact {
            free: FreeBodies::new(&plan.free, &field),
            surfaces: surfaces(&plan, m, &field),
            plan,
            fields: FieldSplit::new(field.clone()),
            field,
            meetings: Vec::new(),
            rigid_nodes: Vec::new(),
            node_impulse: Vec::new(),
            pushed: Vec::new(),
            kicks: Vec::new(),
            dt: 0.0,
            totals,
        }
    }

    /// This step's stencils (`Stencils::compute`), with the shared nodes split
    /// per field, the node map over them, and the meetings at the shared nodes.
    pub fn stencils_and_fields(
        &mut self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &mut Stencils<D>,
        map: &mut NodeMap,
    ) {
        crate::physics::transfer::stencils(m, shape, st);
        let p = &m.particles;
        let n_grid = m.grid.node_count();
        self.fields.split(st, map, n_grid);
        self.meetings = self.fields.meetings(&self.plan, m, st, map, false);
        let plan = &self.plan;
        self.meetings
            .retain(|mt| plan.meet_at_nodes(mt.fields[0], mt.fields[1]));
        self.node_impulse.clear();
        self.node_impulse.resize(map.len(), Vector::<D>::zeros());
        self.pushed.clear();
        self.kicks.clear();
        self.rigid_nodes.clear();
        if let Some(free) = &mut self.free {
            free.start(p, m.axisymmetric);
        }
        if self.plan.rigid.iter().any(|&r| r) {
            // A node of a rigid field holds only that body's particles: it moves
            // with the body (a free body's velocity there, or the prescribed one).
            let (owner, rigid, field) = (st.owner(), &self.plan.rigid, &self.field);
            let free = &self.free;
            let grid = &m.grid;
            self.rigid_nodes = (0..map.len())
                .into_par_iter()
                .with_min_len(MIN_PARALLEL_LEN)
                .filter_map(|a| {
                    let q = owner.of(map.node_entries(a)[0]);
                    let k = field[q] as usize;
                    rigid[k].then(|| {
                        let x = || grid.node_position(grid.node_ijk(map.grid_node(a)));
                        let v = free.as_ref().and_then(|f| f.node_velocity(k, &x()));
                        (a, v.unwrap_or(p.v[q]))
                    })
                })
                .collect();
        }
    }

    /// The free rigid bodies, if the scene has any.
    pub fn free_bodies(&mut self) -> Option<&mut FreeBodies<D>> {
        self.free.as_mut()
    }

    /// Give the nodes of rigid bodies their body's velocity, then correct the
    /// nodal velocities `v` (masses `mass`) of the pass `pass` at the meetings
    /// where the fields approach within the gap; return the nodes changed
    /// (both). The fraction of the momentum change and of the kinetic energy
    /// taken that reaches the particles (`Pass::delivered`) is counted; a pass
    /// that delivers something also counts the nodes in contact.
    ///
    /// A peridynamic field meets at the nodes after the grid update alone:
    /// its particles advance from their own step-start velocities, so a
    /// correction of its step-start nodal velocities would not reach them
    /// (but for the PIC fraction) and would hide their approach from the
    /// pass that does.
    pub fn correct(
        &mut self,
        mass: &[f64],
        v: &mut [Vector<D>],
        dt: f64,
        pass: Pass,
    ) -> Vec<usize> {
        let delivered = pass.delivered();
        let bonded = &self.plan.bonded;
        if delivered > 0.0 {
            for t in &mut self.totals {
                t.nodes = 0;
            }
        }
        let mut corrected = Vec::with_capacity(self.rigid_nodes.len());
        for &(a, velocity) in &self.rigid_nodes {
            v[a] = velocity;
            corrected.push(a);
        }
        for mt in &self.meetings {
            let (mr, ms) = (mass[mt.r], mass[mt.s]);
            if !(mt.close && mr > 0.0 && ms > 0.0) {
                continue;
            }
            if matches!(pass, Pass::StepStart { .. }) && mt.fields.iter().any(|&k| bonded[k]) {
                continue;
            }
            // A rigid field has infinite mass: it keeps its velocity.
            let reduced = match mt.rigid {
                [false, false] => mr * ms / (mr + ms),
                [false, true] => mr,
                [true, false] => ms,
                [true, true] => continue,
            };
            let Some(dp) = exchange(reduced, &v[mt.r], &v[mt.s], mt, dt) else {
                continue;
            };
            if !mt.rigid[0] {
                v[mt.r] += dp / mr;
            }
            if !mt.rigid[1] {
                v[mt.s] -= dp / ms;
            }
            corrected.extend([mt.r, mt.s]);
            if delivered > 0.0 {
                if let Some(free) = &mut self.free {
                    free.receive(mt.fields[0], &mt.position, &(dp * delivered));
                    free.receive(mt.fields[1], &mt.position, &(-dp * delivered));
                }
                let total = &mut self.totals[mt.pair];
                // Work of the friction impulse on the slip that remains, −J_t·w_t'
                // (zero where the fields stick).
                let slip_after = tangential(&(v[mt.r] - v[mt.s]), &mt.normal);
                let friction = tangential(&dp, &mt.normal);
                total.dissipation -= friction.dot(&slip_after) * delivered;
                total.impulse += dp * delivered;
                total.nodes += 1;
                self.node_impulse[mt.r] += dp * delivered;
                self.node_impulse[mt.s] -= dp * delivered;
                self.dt = dt;
            }
        }
        corrected.sort_unstable();
        corrected.dedup();
        corrected
    }

    /// Put the deformable particles that entered a rigid body back on its
    /// surface, without inward velocity relative to it, and give the body the
    /// opposite momentum (`physics::rigid::surface`). After G2P and the free
    /// bodies' advance.
    pub fn keep_out_of_rigid_bodies(&mut self, m: &mut Model<D>) {
        if self.surfaces.is_empty() {
            return;
        }
        if let Some(free) = &mut self.free {
            free.start(&m.particles, m.axisymmetric);
        }
        let pushes = self.pushes(m);
        let mut kicks = Vec::new();
        for push in &pushes {
            let k = push.field as usize;
            let (q, p) = (push.particle, &mut m.particles);
            p.x[q] = push.x;
            let approach = (p.v[q] - push.body_velocity).dot(&push.normal);
            if approach >= 0.0 {
                continue;
            }
            let dv = -push.normal * approach;
            p.v[q] += dv;
            let dp = dv * p.mass[q];
            let fq = self.field[q] as usize;
            let total = &mut self.totals[pair_position(self.plan.fields, fq.min(k), fq.max(k))];
            total.impulse += if fq < k { dp } else { -dp };
            self.pushed.push((q, dp));
            if self.plan.free[k] {
                kicks.push((k, push.x, -dp));
            }
        }
        if let (Some(free), false) = (&mut self.free, kicks.is_empty()) {
            free.kick(&mut m.particles, &kicks, m.axisymmetric);
        }
    }

    /// The deformable particles inside a rigid body they are in contact with,
    /// in particle order, with where they go and the body's velocity there (a
    /// free body's from its last `start`).
    fn pushes(&self, m: &Model<D>) -> Vec<Push<D>> {
        let placements: Vec<_> = (self.surfaces.iter())
            .map(|s| s.placement(&m.particles))
            .collect();
        let on_boundary = on_grid_boundary(&m.grid);
        let (plan, field, removes) = (&self.plan, &self.field, m.removes_particles());
        let free = self.free.as_ref();
        (0..m.particles.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .filter_map(|q| {
                let f = field[q];
                if plan.rigid[f as usize] || (removes && m.removed(q)) {
                    return None;
                }
                let x = &m.particles.x[q];
                (self.surfaces.iter().zip(&placements))
                    .filter(|(s, _)| plan.law(f, s.field).is_some_and(|l| l.rigid_projection))
                    .find_map(|(s, at)| {
                        let (x, normal) = s.push_out(at, x, &on_boundary)?;
                        let free = free.and_then(|f| f.node_velocity(s.field as usize, &x));
                        Some(Push {
                            particle: q,
                            field: s.field,
                            x,
                            normal,
                            body_velocity: free.unwrap_or(m.particles.v[s.particle()]),
                        })
                    })
            })
            .collect()
    }

    /// Do the peridynamic particles meet continuum ones at the nodes
    /// (`ContactPlan::bonded_meets_continuum`)? Then their bond forces go to
    /// their nodes and the exchange there to them.
    pub fn bonded_meets_continuum(&self) -> bool {
        (0..self.plan.fields).any(|k| self.plan.bonded_meets_continuum(k))
    }

    /// The impulse of this step's nodal exchange on continuum particle q of
    /// mass m_q, Σ_I (m_q S_Iq / m_I) J_I (its FLIP share). `st`, `map` and
    /// `mass` are the step's.
    fn node_impulse_on(
        &self,
        st: &Stencils<D>,
        map: &NodeMap,
        mass: &[f64],
        q: usize,
        mass_q: f64,
    ) -> Vector<D> {
        (st.range(q))
            .map(|e| (map.local_of(st, e), st.weight_at(q, e)))
            .filter(|&(a, _)| mass[a] > 0.0)
            .fold(Vector::<D>::zeros(), |f, (a, w)| {
                f + self.node_impulse[a] * (mass_q * w / mass[a])
            })
    }

    /// After the grid update's pass: the velocity changes the exchange gives
    /// the peridynamic particles this step (`bonded_kicks`), kept for
    /// `bonded_kick` and `particle_forces`.
    pub fn deliver_to_bonded(&mut self, st: &Stencils<D>, map: &NodeMap, particle_mass: &[f64]) {
        self.kicks = self.bonded_kicks(st, map, particle_mass);
    }

    /// The velocity change Δv_q the exchange gives peridynamic particle q
    /// this step (`deliver_to_bonded`; zero where it reached none).
    pub fn bonded_kick(&self, q: usize) -> Vector<D> {
        match self.kicks.binary_search_by_key(&q, |(p, _)| *p) {
            Ok(i) => self.kicks[i].1,
            Err(_) => Vector::<D>::zeros(),
        }
    }

    /// The velocity change this step's nodal exchange gives the peridynamic
    /// particles, per particle touched (global index, ascending). The
    /// exchange J_I at the nodes of a peridynamic field reaches its particles
    /// through nodal increments u: Δv_p = Σ_I S_Ip u_I with the consistent
    /// mass M_IJ = Σ_p m_p S_Ip S_Jp, M u = J, so that the particles' momentum
    /// projected on the nodes changes by J_I at every node, as the nodal
    /// correction asked. (The lumped share u_I = J_I / m_I, the FLIP
    /// increment, reaches the nodes as Σ_p m_p S_Ip² / m_I of J_I only, about
    /// 0.6 with linear shape functions: an interface whose particles keep
    /// approaching.) M is assembled over the particles that touch a node with
    /// an exchange alone, exact for them; it is solved by conjugate gradients
    /// preconditioned by the lumped mass, and what the iterations leave of
    /// Σ J is shared by mass, so momentum is conserved to round-off.
    fn bonded_kicks(
        &self,
        st: &Stencils<D>,
        map: &NodeMap,
        particle_mass: &[f64],
    ) -> Vec<(usize, Vector<D>)> {
        let (plan, field, impulse) = (&self.plan, &self.field, &self.node_impulse);
        if impulse.len() != map.len() {
            return Vec::new();
        }
        let zero = Vector::<D>::zeros();
        // The particles of the peridynamic fields at the nodes that exchanged
        // momentum (a split node holds one field's entries).
        let owner = st.owner();
        let mut touched: Vec<usize> = (0..map.len())
            .filter(|&a| impulse[a] != zero)
            .flat_map(|a| map.node_entries(a).iter().map(|&e| owner.of(e)))
            .filter(|&q| plan.bonded[field[q] as usize])
            .collect();
        touched.sort_unstable();
        touched.dedup();
        if touched.is_empty() {
            return Vec::new();
        }
        // The nodes the touched particles reach, numbered compactly.
        let mut index = std::collections::HashMap::new();
        let entries: Vec<Vec<(usize, f64)>> = (touched.iter())
            .map(|&q| {
                st.range(q)
                    .map(|e| {
                        let a = map.local_of(st, e);
                        let n = index.len();
                        (*index.entry(a).or_insert(n), st.weight_at(q, e))
                    })
                    .collect()
            })
            .collect();
        let mut b = vec![zero; index.len()];
        for (&a, &k) in &index {
            b[k] = impulse[a];
        }
        let mass_of = |i: usize| particle_mass[touched[i]];
        let lumped = {
            let mut m = vec![0.0; b.len()];
            for (i, en) in entries.iter().enumerate() {
                for &(k, w) in en {
                    m[k] += mass_of(i) * w;
                }
            }
            m
        };
        let at_particles = |u: &[Vector<D>]| -> Vec<Vector<D>> {
            (entries.iter())
                .map(|en| en.iter().fold(zero, |acc, &(k, w)| acc + u[k] * w))
                .collect()
        };
        let consistent = |u: &[Vector<D>]| -> Vec<Vector<D>> {
            let mut y = vec![zero; u.len()];
            for (i, vp) in at_particles(u).into_iter().enumerate() {
                for &(k, w) in &entries[i] {
                    y[k] += vp * (mass_of(i) * w);
                }
            }
            y
        };
        let u = consistent_solve(&consistent, &lumped, &b);
        let mut dv = at_particles(&u);
        // What the iterations leave of Σ J, shared by mass.
        let total: Vector<D> = b.iter().sum();
        let given = (dv.iter().enumerate()).fold(zero, |acc, (i, v)| acc + v * mass_of(i));
        let m_all: f64 = (0..touched.len()).map(mass_of).sum();
        let rest = (total - given) / m_all;
        dv.iter_mut().for_each(|v| *v += rest);
        touched.into_iter().zip(dv).collect()
    }

    /// The contact force on every particle in the last step: the momentum
    /// exchanged at each node, J_I, shared by the particles of its field by
    /// their mass, f_p = Σ_I (m_p S_Ip / m_I) J_I / Δt (a peridynamic
    /// particle: m_p Δv_p / Δt of `bonded_kicks`, which shares J_I the same
    /// in sum), plus a push out of a rigid body, Δp/Δt. Over a field's particles they sum to the nodes'
    /// J_I/Δt (Σ_p m_p S_Ip = m_I), the pair's force in contact.csv over
    /// that step. `st`, `map` and `mass` are the step's.
    pub fn particle_forces(
        &self,
        st: &Stencils<D>,
        map: &NodeMap,
        mass: &[f64],
        p: &Particles<D>,
    ) -> Vec<Vector<D>> {
        let mut f = vec![Vector::<D>::zeros(); p.len()];
        if self.dt <= 0.0 || self.node_impulse.len() != map.len() {
            return f;
        }
        let bonded = |q: usize| self.plan.bonded[self.field[q] as usize];
        for (q, fq) in f.iter_mut().enumerate() {
            *fq = match bonded(q) {
                true => self.bonded_kick(q) * p.mass[q],
                false => self.node_impulse_on(st, map, mass, q, p.mass[q]),
            };
        }
        for &(q, dp) in &self.pushed {
            f[q] += dp;
        }
        f.iter_mut().for_each(|fq| *fq /= self.dt);
        f
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

/// M u = b for the consistent mass M (`consistent`, applied to nodal vectors)
/// by conjugate gradients preconditioned by the lumped mass `lumped`, over
/// the D components at once (M ⊗ I), to 1e-12 of ‖b‖ or 200 iterations.
fn consistent_solve<const D: usize>(
    consistent: &dyn Fn(&[Vector<D>]) -> Vec<Vector<D>>,
    lumped: &[f64],
    b: &[Vector<D>],
) -> Vec<Vector<D>> {
    use crate::solver::linear::iterative::Settings;
    let flat = |v: &[Vector<D>]| -> Vec<f64> { v.iter().flat_map(|x| x.iter().copied()).collect() };
    let vectors =
        |f: &[f64]| -> Vec<Vector<D>> { f.chunks(D).map(Vector::<D>::from_column_slice).collect() };
    let diagonal: Vec<f64> = lumped.iter().flat_map(|&m| [m; D]).collect();
    let precond = crate::solver::linear::preconditioner::Jacobi::new(diagonal);
    let settings = Settings {
        tolerance: 1e-12,
        max_iterations: 200,
        restart: 0,
    };
    let mut x = vec![0.0; b.len() * D];
    let apply = |v: &[f64], out: &mut [f64]| -> Result<(), ()> {
        out.copy_from_slice(&flat(&consistent(&vectors(v))));
        Ok(())
    };
    let _ = crate::solver::linear::cg::cg(apply, &precond, &flat(b), &mut x, &settings);
    vectors(&x)
}

/// The rigid fields whose contact with some other field keeps that field's
/// particles out (`rigid_projection`), with their particles and geometries.
fn surfaces<const D: usize>(plan: &ContactPlan, m: &Model<D>, field: &[u32]) -> Vec<Surface> {
    let keeps_out = |k: usize| {
        (0..plan.fields).any(|j| {
            j != k
                && plan
                    .law(k as u32, j as u32)
                    .is_some_and(|l| l.rigid_projection)
        })
    };
    rigid_surfaces(plan, m, field, &keeps_out)
}

/// The part of v tangential to the unit normal n.
fn tangential<const D: usize>(v: &Vector<D>, n: &Vector<D>) -> Vector<D> {
    v - n * v.dot(n)
}

/// The momentum change of field r at a meeting (s gets the opposite), or None if
/// the fields do not approach and the contact has no adhesion (with adhesion, a
/// separating node exchanges tangential momentum up to c A Δt only):
/// −P_n n − min(μ P_n + c A Δt, |P_t|) P_t/|P_t| with
/// P = m (v_r − v_s), m the reduced mass m_r m_s/(m_r + m_s) (review 002 eq. 41
/// with Coulomb's cap; m_r or m_s against a rigid field).
fn exchange<const D: usize>(
    reduced: f64,
    vr: &Vector<D>,
    vs: &Vector<D>,
    mt: &Meeting<D>,
    dt: f64,
) -> Option<Vector<D>> {
    let p = (vr - vs) * reduced;
    let pn = p.dot(&mt.normal);
    let adhesion = mt.law.adhesion * mt.area * dt;
    // Separating fields that touch (the gap criterion holds) keep the interface's
    // shear strength, but no normal exchange and no friction.
    if pn <= 0.0 && adhesion == 0.0 {
        return None;
    }
    let pn = pn.max(0.0);
    let pt = p - mt.normal * p.dot(&mt.normal);
    let slide = pt.norm();
    let cap = mt.law.friction * pn + adhesion;
    let tangential = if slide <= cap { pt } else { pt * (cap / slide) };
    Some(-(mt.normal * pn) - tangential)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::contact::ContactLaw;
    use crate::scene::ContactNormal;

    fn meeting(normal: Vector<2>, mu: f64) -> Meeting<2> {
        Meeting {
            r: 0,
            s: 1,
            pair: 0,
            fields: [0, 1],
            position: Vector::<2>::zeros(),
            normal,
            rigid: [false, false],
            area: 1.0,
            gap: 0.0,
            reach: [0.0; 2],
            outermost: [u32::MAX; 2],
            close: true,
            law: ContactLaw {
                friction: mu,
                adhesion: 0.0,
                gap_factor: 0.5,
                normal: ContactNormal::MaxGradient,
                rigid_projection: true,
                penalty_factor: 100.0,
            },
        }
    }

    /// Head-on, frictionless: the normal velocities meet at the centre of mass,
    /// the tangential ones are kept, momentum is conserved.
    #[test]
    fn approaching_fields_meet_at_the_centre_of_mass_velocity() {
        let n = Vector::<2>::new(1.0, 0.0);
        let (mr, ms) = (2.0, 1.0);
        let (vr, vs) = (Vector::<2>::new(1.0, 0.5), Vector::<2>::new(-2.0, 0.0));
        let dp = exchange(mr * ms / (mr + ms), &vr, &vs, &meeting(n, 0.0), 1.0).unwrap();
        let (ur, us) = (vr + dp / mr, vs - dp / ms);
        assert!((ur.x - us.x).abs() < 1e-15 && (ur.x - 0.0).abs() < 1e-15);
        assert_eq!((ur.y, us.y), (0.5, 0.0));
        assert!((ur * mr + us * ms - (vr * mr + vs * ms)).norm() < 1e-15);
    }

    /// Coulomb: slip with the tangential momentum reduced by μ P_n, stick when
    /// μ P_n exceeds it; separating fields are left alone.
    #[test]
    fn friction_caps_the_tangential_exchange() {
        let n = Vector::<2>::new(0.0, -1.0);
        let (vr, vs) = (Vector::<2>::new(3.0, -1.0), Vector::<2>::zeros());
        // m_r = m_s = 2: P = (3, −1), P_n = 1, P_t = (3, 0).
        let slip = exchange(1.0, &vr, &vs, &meeting(n, 0.5), 1.0).unwrap();
        assert!((slip - Vector::<2>::new(-0.5, 1.0)).norm() < 1e-15);
        let stick = exchange(1.0, &vr, &vs, &meeting(n, 5.0), 1.0).unwrap();
        assert!((stick - Vector::<2>::new(-3.0, 1.0)).norm() < 1e-15);
        assert!(exchange(1.0, &-vr, &vs, &meeting(n, 5.0), 1.0).is_none());
    }

    /// Adhesion holds a separating interface in shear (up to c A Δt) but does not
    /// pull it together.
    #[test]
    fn adhesion_acts_in_shear_on_separating_fields() {
        let n = Vector::<2>::new(0.0, -1.0);
        let mut mt = meeting(n, 0.0);
        mt.law.adhesion = 0.5;
        // Separating (P_n = −1) with P_t = (3, 0): the shear exchange is c A Δt = 0.5.
        let dp = exchange(
            1.0,
            &Vector::<2>::new(3.0, 1.0),
            &Vector::<2>::zeros(),
            &mt,
            1.0,
        );
        assert!((dp.unwrap() - Vector::<2>::new(-0.5, 0.0)).norm() < 1e-15);
    }
}
