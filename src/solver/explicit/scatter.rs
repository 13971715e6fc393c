//! The box-scatter back-end of the explicit step (`solver::explicit::step`):
//! particle-side transfers on a box of nodes (`solver::explicit::node_box`),
//! without a node map or stored stencils. Each particle pass evaluates the
//! particle's 1D factors again, which costs less than storing the tensor
//! product and reading it back through a map.
//!
//! The passes fuse what the scheme lets them: USL takes one scatter (mass,
//! momentum, force), one pass over the nodes and one over the particles (G2P,
//! ΔF = I + Δt L, the stress). USF and MUSL add a scatter and a particle pass
//! each; MUSL maps the momentum back in its G2P pass and moves the particles
//! in its last pass, which needs their stencils at the step start. No body
//! that is not a continuum takes its own motion between them: rigid bodies
//! come with contact, which needs the node map (`solver::explicit::features`).

use crate::dim::{compose, embed_deformation, Mat3, Tensor, Vector};
use crate::model::conditions::{Constraint, FaceCondition, FrictionFace};
use crate::model::grid::Grid;
use crate::model::particles::{History, Particles};
use crate::model::tensors::{Tensors, TensorsMut};
use crate::model::Model;
use crate::parallel::{deterministic_sum, DisjointSlice, MIN_PARALLEL_LEN, SUM_CHUNK};
use crate::physics::boundary::absorbing;
use crate::physics::boundary::conditions::{node_constraint, node_friction};
use crate::physics::kinematics::deformation::{update_particle, ParticleState};
use crate::physics::kinematics::fbar::{scale_factor, scaled, Cells};
use crate::physics::shape::deformation_for;
use crate::physics::transfer::nodal_velocity;
use crate::solver::divergence::{inverted, sound, unsound, Divergence};
use crate::solver::explicit::apic;
use crate::solver::explicit::bulk_viscosity::BulkViscosity;
use crate::solver::explicit::grid_update::{acceleration, updated_velocity, with_conditions};
use crate::solver::explicit::motion::{blend, load_power};
use crate::solver::explicit::node_box::{NodeBox, Points, Stencil};
use crate::solver::explicit::p2g::{hoop_stress, Source};
use crate::solver::explicit::step::{removed_particles, Backend, P2g, Start, Step, Then, Velocity};
use rayon::prelude::*;
use std::borrow::Cow;

/// Particles per task of a particle pass: small enough that a scene of a few
/// thousand particles keeps every thread busy. The work of the loads is summed
/// afterwards in the chunks of `parallel::deterministic_sum` (`SUM_CHUNK`, a
/// multiple of it), so it sums the same on any number of threads.
const TASK: usize = MIN_PARALLEL_LEN;
const _: () = assert!(SUM_CHUNK % TASK == 0);

/// What a box node gathers. After the node pass: `momentum` holds the updated
/// velocity and `force` the acceleration.
#[derive(Clone, Copy, Debug)]
struct Node<const D: usize> {
    mass: f64,
    momentum: Vector<D>,
    force: Vector<D>,
}

impl<const D: usize> Node<D> {
    fn zero() -> Self {
        Node {
            mass: 0.0,
            momentum: Vector::<D>::zeros(),
            force: Vector::<D>::zeros(),
        }
    }
}

/// The buffers of the scatter path, kept between steps.
#[derive(Clone, Debug, Default)]
pub struct ScatterStep<const D: usize> {
    nb: NodeBox<D>,
    nodes: Vec<Node<D>>,
    /// USF: the step-start nodal velocity with the conditions applied. MUSL:
    /// the remapped momentum, then velocity.
    second: Vec<Vector<D>>,
    /// MUSL: the work of the loads per particle over the step.
    work: Vec<f64>,
    /// Per particle: removed from the transfers this step (`Model::removed`;
    /// empty when the scene removes none).
    removed: Vec<bool>,
    /// F-bar's cells and the recorded ΔF_p (`fbar_update`).
    fbar: FBarStep,
    /// Nodes with mass in the last step.
    pub active: usize,
}

/// F-bar on the box: the cells of the particles' step-start positions and
/// each particle's ΔF_p before the cells' mean dilatation replaces its own.
#[derive(Clone, Debug, Default)]
struct FBarStep {
    cells: Cells,
    df: Vec<Mat3>,
}

/// The face conditions and friction walls of one step (`Model::faces_during`,
/// `Model::walls_during`).
struct StepFaces<'a, const D: usize> {
    conditions: Cow<'a, [FaceCondition<D>]>,
    walls: Cow<'a, [FrictionFace<D>]>,
}

impl<'a, const D: usize> StepFaces<'a, D> {
    fn of(m: &'a Model<D>, s: &Step<D>) -> Self {
        StepFaces {
            conditions: m.faces_during(s.t, s.dt),
            walls: m.walls_during(s.t, s.dt),
        }
    }
}

/// A face node's conditions: its constraint and the friction faces it lies on.
struct Conditions<const D: usize> {
    constraint: Constraint<D>,
    friction: Vec<u8>,
}

impl<const D: usize> Backend<D> for ScatterStep<D> {
    fn locate(&mut self, m: &mut Model<D>, s: &Step<D>) {
        self.removed = removed_particles(m);
        let p = &m.particles;
        self.nb.locate(s.shape, &m.grid, &p.x, &self.removed);
        if s.fbar {
            self.fbar.cells = Cells::locate(&m.grid, &p.x);
        }
        if s.apic && p.affine.len() != p.len() {
            self.initial_affine(s, m);
        }
    }

    fn p2g(&mut self, m: &Model<D>, s: &Step<D>, what: P2g) {
        if what != P2g::Force {
            self.nodes.clear();
            self.nodes.resize(self.nb.nodes(), Node::zero());
        }
        // P2G: mass (2-24), momentum (2-25) and the force (2-51, 2-52).
        match what {
            P2g::Motion if s.apic => self.scatter::<true, false, true>(s, m),
            P2g::Motion => self.scatter::<true, false, false>(s, m),
            P2g::MotionAndForce if s.apic => self.scatter::<true, true, true>(s, m),
            P2g::MotionAndForce => self.scatter::<true, true, false>(s, m),
            P2g::Force => self.scatter::<false, true, false>(s, m),
        }
        if what != P2g::Motion && m.axisymmetric {
            self.add_hoop_force(s, m);
        }
    }

    fn start_velocity(&mut self, m: &Model<D>, s: &Step<D>) {
        self.start_velocity(m, &StepFaces::of(m, s));
    }

    fn start_forces(&mut self, m: &Model<D>, s: &Step<D>) {
        self.add_start_forces(m, s);
    }

    fn grid_update(&mut self, m: &Model<D>, s: &Step<D>, start: Start) {
        let faces = StepFaces::of(m, s);
        self.node_pass(m, &faces, start == Start::Formed, s.damping, s.tiny, s.dt);
    }

    fn g2p(&mut self, m: &mut Model<D>, s: &Step<D>, then: Then) -> Result<f64, Divergence> {
        match then {
            Then::Stress => self.particle_pass(s, m, Pass::Full),
            Then::Nothing => self.particle_pass(s, m, Pass::Motion),
            Then::Remap => Ok(self.velocity_and_remap(s, m)),
        }
    }

    fn remapped_velocity(&mut self, m: &Model<D>, s: &Step<D>) {
        self.remapped_velocity(m, &StepFaces::of(m, s));
    }

    fn update_stress(
        &mut self,
        m: &mut Model<D>,
        s: &Step<D>,
        from: Velocity,
    ) -> Result<(), Divergence> {
        let pass = match from {
            Velocity::Start => Pass::Stress,
            Velocity::Remapped => Pass::Remapped,
        };
        self.particle_pass(s, m, pass).map(|_| ())
    }

    /// The last particle pass checked every particle.
    fn check(&self, _: &Model<D>, _: &Step<D>) -> Result<(), Divergence> {
        Ok(())
    }
}

impl<const D: usize> ScatterStep<D> {
    /// P2G into the nodes: mass and momentum (`MOTION`), the force
    /// f_ext − f_int = Σ S_I (m g + s f) − V σ ∇S_I (`FORCE`).
    fn scatter<const MOTION: bool, const FORCE: bool, const APIC: bool>(
        &mut self,
        s: &Step<D>,
        m: &Model<D>,
    ) {
        let p = &m.particles;
        let source = |q: usize| {
            let applied = match FORCE {
                true => s.applied(&m.load_ramp_of, &p.mass, &p.load, q),
                false => Vector::<D>::zeros(),
            };
            Source::of(p, q, applied)
        };
        let add = |n: &mut Node<D>, s: &Source<D>, w: f64, g: &Vector<D>| {
            if MOTION {
                n.mass += s.mass * w;
                n.momentum += s.momentum * w;
            }
            if FORCE {
                n.force += s.force_at(w, g);
            }
        };
        let (shape, grid, points) = (s.shape, &m.grid, Points::of(p));
        if !(MOTION && APIC) {
            self.nb
                .scatter(shape, grid, points, &mut self.nodes, |q, _| source(q), add);
            return;
        }
        // APIC: m B_p, given to node I with the weight S_I D⁻¹ (x_I − x_p).
        let source = |q: usize, st: &Stencil<D>| {
            let slopes = apic::weight_slopes(st, &st.moments(grid, &p.x[q]), shape);
            ((source(q), p.affine[q] * p.mass[q]), slopes)
        };
        let add =
            |n: &mut Node<D>, s: &(Source<D>, Tensor<D>), w: f64, g: &Vector<D>, a: &Vector<D>| {
                add(n, &s.0, w, g);
                n.momentum += s.1 * a;
            };
        self.nb
            .scatter_with_second(shape, grid, points, &mut self.nodes, source, add);
    }

    /// APIC's first step on the box (as `solver::explicit::apic::ensure` on the node
    /// map): B_p of the particles' velocities projected on the nodes.
    fn initial_affine(&mut self, s: &Step<D>, m: &mut Model<D>) {
        self.nodes.clear();
        self.nodes.resize(self.nb.nodes(), Node::zero());
        self.scatter::<true, false, false>(s, m);
        let (nb, nodes, grid, removed) = (&self.nb, &self.nodes, &m.grid, &self.removed);
        let p = &m.particles;
        let affine = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| {
                let f = deformation_for(s.shape, || p.f.get(q));
                let st = match removed.get(q) {
                    Some(true) => None,
                    _ => nb.stencil(s.shape, grid, &p.x[q], &p.half_length0[q], &f),
                };
                st.map_or_else(Tensor::<D>::zeros, |st| {
                    apic::box_moment(&st, &st.moments(grid, &p.x[q]), &nb.stride, |b| {
                        nodal_velocity(nodes[b].mass, &nodes[b].momentum)
                    })
                })
            })
            .collect();
        m.particles.affine = affine;
    }

    /// MUSL: the particles' velocity from the updated nodes (G2P, 2-27) and its
    /// momentum mapped back into `second`, in one coloured pass (the scatter's
    /// tile task owns its particles, so it may update them). Positions move in
    /// the last pass. Returns the work of the loads over the step, summed in the
    /// chunks of `deterministic_sum` from the per-particle terms.
    fn velocity_and_remap(&mut self, s: &Step<D>, m: &mut Model<D>) -> f64 {
        let (nb, nodes) = (&self.nb, &self.nodes[..]);
        self.second.clear();
        self.second.resize(self.nodes.len(), Vector::<D>::zeros());
        let n = m.particles.len();
        self.work.clear();
        self.work.resize(n, 0.0);
        let (grid, ramp_of, dt) = (&m.grid, &m.load_ramp_of, s.dt);
        let Particles {
            x,
            v,
            f,
            half_length0,
            mass,
            load,
            affine,
            ..
        } = &mut m.particles;
        let points = Points { x, half_length0, f };
        let (velocity, work) = (DisjointSlice::new(v), DisjointSlice::new(&mut self.work));
        let affine = DisjointSlice::new(affine);
        let source = |q: usize, st: &Stencil<D>| {
            let (vp, a, _) = gather::<D, true, 0>(st, nb, nodes, &[]);
            // SAFETY: particle q belongs to this tile's task alone.
            let (v, w) = unsafe { (velocity.at(q), work.at(q)) };
            let v_old = *v;
            *v = blend(&v_old, &a, &vp, s.flip, dt);
            *w = load_power(&s.applied(ramp_of, mass, load, q), &v_old, v);
            *v * mass[q]
        };
        let add = |n: &mut Vector<D>, s: &Vector<D>, w: f64, _: &Vector<D>| *n += s * w;
        if !s.apic {
            nb.scatter(s.shape, grid, points, &mut self.second, source, add);
            return deterministic_sum(n, |q| self.work[q]) * dt;
        }
        // APIC: B_p from the updated nodes, remapped with its affine weight.
        let source = |q: usize, st: &Stencil<D>| {
            let momentum = source(q, st);
            let moments = st.moments(grid, &x[q]);
            let b = apic::box_moment(st, &moments, &nb.stride, |b| nodes[b].momentum);
            // SAFETY: as above.
            unsafe { *affine.at(q) = b };
            let slopes = apic::weight_slopes(st, &moments, s.shape);
            ((momentum, b * mass[q]), slopes)
        };
        let add = |n: &mut Vector<D>,
                   s: &(Vector<D>, Tensor<D>),
                   w: f64,
                   g: &Vector<D>,
                   a: &Vector<D>| {
            add(n, &s.0, w, g);
            *n += s.1 * a;
        };
        nb.scatter_with_second(s.shape, grid, points, &mut self.second, source, add);
        deterministic_sum(n, |q| self.work[q]) * dt
    }

    /// The conditions of box node b at grid multi-index `ijk`, `None` for a
    /// node on no grid face (most nodes).
    fn conditions(m: &Model<D>, faces: &StepFaces<D>, ijk: [usize; D]) -> Option<Conditions<D>> {
        let grid = &m.grid;
        if !(0..D).any(|d| ijk[d] == 0 || ijk[d] + 1 == grid.nodes[d]) {
            return None;
        }
        let g = grid.node_index(ijk);
        Some(Conditions {
            constraint: node_constraint(grid, &faces.conditions, g),
            friction: node_friction(grid, &m.friction, g),
        })
    }

    /// v = p/m on a node with mass (2-25), with its conditions applied.
    fn velocity(
        walls: &[FrictionFace<D>],
        raw: &Vector<D>,
        c: &Option<Conditions<D>>,
    ) -> Vector<D> {
        match c {
            Some(c) => with_conditions(raw, &c.constraint, walls, &c.friction),
            None => *raw,
        }
    }

    /// Calls `f(node, second, grid multi-index)` for every box node, in
    /// parallel over the box's x-rows; sets `active` to the nodes with mass.
    fn for_nodes(&mut self, f: impl Fn(&mut Node<D>, &mut Vector<D>, [usize; D]) + Sync) {
        let (nb, row) = (&self.nb, self.nb.row_len().max(1));
        self.second.resize(self.nodes.len(), Vector::<D>::zeros());
        self.active = (self.nodes.par_chunks_mut(row))
            .zip(self.second.par_chunks_mut(row))
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN.div_ceil(row))
            .map(|(r, (nodes, second))| {
                let mut ijk = nb.grid_ijk(r * row);
                let mut with_mass = 0;
                for (n, s) in nodes.iter_mut().zip(second) {
                    f(n, s, ijk);
                    with_mass += (n.mass > 0.0) as usize;
                    ijk[0] += 1;
                }
                with_mass
            })
            .sum();
    }

    /// The grid update (2-23, 2-29): acceleration from the force with local
    /// damping (no acceleration on nodes lighter than `tiny`), prescribed
    /// components landing on their value, friction faces on the updated
    /// velocity. Leaves the updated velocity in `momentum` and the
    /// acceleration in `force`. USF (`usf`): `momentum` already holds p/m and
    /// `second` the constrained velocity.
    fn node_pass(
        &mut self,
        m: &Model<D>,
        faces: &StepFaces<D>,
        usf: bool,
        damping: f64,
        tiny: f64,
        dt: f64,
    ) {
        self.for_nodes(|n, second, ijk| {
            let c = Self::conditions(m, faces, ijk);
            let (raw, v) = match usf {
                true => (n.momentum, *second),
                false => {
                    let raw = nodal_velocity(n.mass, &n.momentum);
                    (raw, Self::velocity(&faces.walls, &raw, &c))
                }
            };
            let free = Constraint::free();
            let constraint = c.as_ref().map_or(&free, |c| &c.constraint);
            let acc = acceleration(n.mass, &n.force, &v, &raw, constraint, damping, tiny, dt);
            let on: &[u8] = c.as_ref().map_or(&[], |c| &c.friction);
            (n.momentum, n.force) = updated_velocity(&raw, &acc, constraint, &faces.walls, on, dt);
        });
    }

    /// USF: p/m into `momentum`, and the velocity with the conditions into `second`.
    fn start_velocity(&mut self, m: &Model<D>, faces: &StepFaces<D>) {
        self.for_nodes(|n, second, ijk| {
            n.momentum = nodal_velocity(n.mass, &n.momentum);
            let c = Self::conditions(m, faces, ijk);
            *second = Self::velocity(&faces.walls, &n.momentum, &c);
        });
    }

    /// MUSL: the remapped momentum in `second` becomes the velocity with the
    /// conditions.
    fn remapped_velocity(&mut self, m: &Model<D>, faces: &StepFaces<D>) {
        self.for_nodes(|n, second, ijk| {
            let raw = nodal_velocity(n.mass, second);
            *second = Self::velocity(&faces.walls, &raw, &Self::conditions(m, faces, ijk));
        });
    }

    /// One pass over the particles (`Pass`), in fixed chunks; returns the work
    /// of the applied forces over the step (passes that move the particles).
    /// Removed particles (`removed`) take nothing from the grid: they keep
    /// their position and velocity, and no load does work on them. With F-bar
    /// the pass records ΔF_p, and `fbar_update` updates the stress.
    fn particle_pass(
        &mut self,
        s: &Step<D>,
        m: &mut Model<D>,
        pass: Pass,
    ) -> Result<f64, Divergence> {
        match m.removes_particles() || m.axisymmetric || s.fbar {
            true => self.particle_pass_with::<true>(s, m, pass),
            false => self.particle_pass_with::<false>(s, m, pass),
        }
    }

    /// `particle_pass`, with (`RARE`) or without the checks that removed
    /// particles, axisymmetry and F-bar need (the plain step's pass has none
    /// of their branches).
    fn particle_pass_with<const RARE: bool>(
        &mut self,
        s: &Step<D>,
        m: &mut Model<D>,
        pass: Pass,
    ) -> Result<f64, Divergence> {
        let (t, dt, step) = (s.t, s.dt, s.step);
        let fbar = RARE && s.fbar && pass != Pass::Motion;
        if fbar {
            let n = m.particles.len();
            self.fbar.df.resize(n, Mat3::identity());
        }
        let (nb, nodes, second) = (&self.nb, &self.nodes[..], &self.second[..]);
        let (removed, recorded) = (&self.removed[..], DisjointSlice::new(&mut self.fbar.df));
        let (grid, materials, ramp_of) = (&m.grid, &m.materials, &m.load_ramp_of);
        let axisymmetric = RARE && m.axisymmetric;
        let placed = Placed::of(grid, RARE && m.remove_outside, axisymmetric);
        let Particles {
            x,
            v,
            f,
            stress,
            volume,
            history,
            mass,
            volume0,
            half_length0,
            load,
            material,
            affine,
            ..
        } = &mut m.particles;
        let (mass, volume0, half_length0, load, material) =
            (&*mass, &*volume0, &*half_length0, &*load, &*material);
        let affine = DisjointSlice::new(affine);
        let applied = |q: usize| s.applied(ramp_of, mass, load, q);
        // The last pass checks the state, as `check_state` does after a step
        // (with F-bar, `fbar_update` does).
        let last = matches!(pass, Pass::Full | Pass::Motion | Pass::Remapped);
        let checks = last && !fbar;
        let body = |q: usize, mut state: Moving<D>| -> (f64, bool, bool) {
            let left_out = RARE && removed.get(q) == Some(&true);
            let sc = match left_out {
                true => None,
                false => nb.stencil(
                    s.shape,
                    grid,
                    state.x,
                    &half_length0[q],
                    &deformation_for(s.shape, || state.deformation.f.get()),
                ),
            };
            let (vp, a, l) = match (pass, &sc) {
                (_, None) => (
                    Vector::<D>::zeros(),
                    Vector::<D>::zeros(),
                    Tensor::<D>::zeros(),
                ),
                (Pass::Full, Some(sc)) => gather::<D, true, 1>(sc, nb, nodes, second),
                (Pass::Stress, Some(sc)) => gather::<D, false, 2>(sc, nb, nodes, second),
                (Pass::Motion, Some(sc)) => gather::<D, true, 0>(sc, nb, nodes, second),
                (Pass::Remapped, Some(sc)) => gather::<D, true, 2>(sc, nb, nodes, second),
            };
            // Axisymmetric: the hoop rate v_r(x_p)/r_p = Σ_I v_Ir S_Ip / r_p at the
            // step start (`physics::shape::hoop`).
            let hoop = match (RARE && axisymmetric && pass != Pass::Motion, &sc) {
                (true, Some(sc)) => match pass {
                    Pass::Full => hoop_rate(sc, nb, |b| nodes[b].momentum[0], state.x),
                    _ => hoop_rate(sc, nb, |b| second[b][0], state.x),
                },
                _ => 0.0,
            };
            let mut work = 0.0;
            if s.apic && matches!(pass, Pass::Full | Pass::Motion) {
                // APIC's B_p from the updated nodes, where the particle is now.
                let b = sc.as_ref().map_or_else(Tensor::<D>::zeros, |sc| {
                    apic::box_moment(sc, &sc.moments(grid, state.x), &nb.stride, |b| {
                        nodes[b].momentum
                    })
                });
                // SAFETY: particle q belongs to this chunk's task alone.
                unsafe { *affine.at(q) = b };
            }
            if !left_out && matches!(pass, Pass::Full | Pass::Motion) {
                // PIC/FLIP blend (2-27); the applied forces' work over the step.
                let v_old = *state.v;
                *state.v = blend(&v_old, &a, &vp, s.flip, dt);
                work = load_power(&applied(q), &v_old, state.v);
            }
            if !left_out && last {
                // x ← x + Δt v_PIC (2-26).
                *state.x += vp * dt;
            }
            // det F of the updated state: from the stress update, or formed.
            let det = match pass != Pass::Motion {
                true => {
                    // ΔF = I + Δt L (2-31); axisymmetric ΔF_θθ = 1 + Δt v_r/r_p.
                    let mut df = embed_deformation::<D>(&(Tensor::<D>::identity() + l * dt));
                    if RARE && axisymmetric {
                        df[(2, 2)] = 1.0 + dt * hoop;
                    }
                    match RARE && fbar {
                        // SAFETY: particle q belongs to this chunk's task alone.
                        true => unsafe {
                            *recorded.at(q) = df;
                            1.0
                        },
                        false => {
                            let law = materials[material[q] as usize].as_ref();
                            update_particle(law, &df, dt, volume0[q], &mut state.deformation)
                        }
                    }
                }
                false if checks => state.deformation.f.get().determinant(),
                false => 1.0,
            };
            // NaN counts as inverted, as in `check_state`.
            let intact = det > 0.0;
            let stress = state.deformation.stress.get();
            let placed = match RARE {
                true => placed.at(state.x),
                false => grid.contains(state.x),
            };
            let bad = checks && !sound(state.x, state.v, &stress, det, placed);
            (work, !intact, bad)
        };
        let parts = Parts {
            x,
            v,
            f,
            stress,
            volume,
            history,
        };
        let (work, first_inverted, first_bad) = over_particles(parts, body);
        if let Some(q) = first_inverted {
            let det = m.particles.f.get(q).determinant();
            return Err(inverted(q, det, step + 1, t + dt));
        }
        if let Some(q) = first_bad {
            return Err(unsound(m, q, step + 1, t + dt));
        }
        if fbar {
            self.fbar_update(s, m, last)?;
        }
        Ok(work * dt)
    }

    /// F-bar's stress update from the ΔF_p that the particle pass recorded:
    /// every particle takes the mean dilatation of its cell, ΔF̄_p = (ΔJ̄_c /
    /// ΔJ_p)^{1/n} ΔF_p (`physics::kinematics::fbar`; n = 3 in axisymmetric
    /// mode), then the stress from ΔF̄_p. `checks`: the state is checked after.
    fn fbar_update(
        &mut self,
        s: &Step<D>,
        m: &mut Model<D>,
        checks: bool,
    ) -> Result<(), Divergence> {
        let (t, dt, step) = (s.t, s.dt, s.step);
        let fb = &self.fbar;
        let dj: Vec<f64> = (fb.df.par_iter())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|df| df.determinant())
            .collect();
        if let Some(q) = dj.iter().position(|&j| j <= 0.0) {
            let det = compose(&fb.df[q], &m.particles.f.get(q)).determinant();
            return Err(inverted(q, det, step + 1, t + dt));
        }
        // The cells' mean dilatation over the step-start volumes.
        let dj_bar = fb.cells.mean_dilatation(&m.particles.volume, &dj);
        let (axisymmetric, materials) = (m.axisymmetric, &m.materials);
        let placed = Placed::of(&m.grid, m.remove_outside, axisymmetric);
        let Particles {
            x,
            v,
            f,
            stress,
            volume,
            history,
            volume0,
            material,
            ..
        } = &mut m.particles;
        let (volume0, material) = (&*volume0, &*material);
        let body = |q: usize, mut state: Moving<D>| -> (f64, bool, bool) {
            let (dj_bar, dj, df) = (dj_bar[fb.cells.of[q] as usize], dj[q], &fb.df[q]);
            let df = match axisymmetric {
                true => scaled::<3>(df, scale_factor::<3>(dj_bar, dj)),
                false => scaled::<D>(df, scale_factor::<D>(dj_bar, dj)),
            };
            let law = materials[material[q] as usize].as_ref();
            let det = update_particle(law, &df, dt, volume0[q], &mut state.deformation);
            let stress = state.deformation.stress.get();
            let bad = checks && !sound(state.x, state.v, &stress, det, placed.at(state.x));
            (0.0, det.is_nan() || det <= 0.0, bad)
        };
        let parts = Parts {
            x,
            v,
            f,
            stress,
            volume,
            history,
        };
        let (_, first_inverted, first_bad) = over_particles(parts, body);
        if let Some(q) = first_inverted {
            let det = m.particles.f.get(q).determinant();
            return Err(inverted(q, det, step + 1, t + dt));
        }
        if let Some(q) = first_bad {
            return Err(unsound(m, q, step + 1, t + dt));
        }
        Ok(())
    }

    /// Axisymmetric mode: the hoop part of the internal force, − V σ_θθ S_Ip / r_p
    /// on the radial component (`physics::shape::hoop`), in a scatter of its own.
    fn add_hoop_force(&mut self, s: &Step<D>, m: &Model<D>) {
        let p = &m.particles;
        let source = |q: usize, _: &Stencil<D>| hoop_stress(p, q);
        let add = |n: &mut Node<D>, hoop: &f64, w: f64, _: &Vector<D>| n.force[0] -= hoop * w;
        let points = Points::of(p);
        self.nb
            .scatter(s.shape, &m.grid, points, &mut self.nodes, source, add);
    }

    /// The forces that read the step-start velocity (`second`, after
    /// `start_velocity`): bulk viscosity, then the absorbing faces.
    fn add_start_forces(&mut self, m: &Model<D>, s: &Step<D>) {
        if let Some(viscosity) = &s.viscosity {
            self.add_viscous_force(m, s, viscosity);
        }
        self.add_absorbing_force(m, s);
    }

    /// Bulk viscosity: Σ_p q_p V_p ∇S_Ip (with the hoop part q_p V_p S_Ip / r_p
    /// on the radial component), q_p from ε̇_v = tr L_p of the step-start
    /// velocity (`solver::explicit::bulk_viscosity`), in one coloured pass that
    /// gathers the rate and scatters the force.
    fn add_viscous_force(&mut self, m: &Model<D>, s: &Step<D>, viscosity: &BulkViscosity) {
        let (nb, second, p) = (&self.nb, &self.second[..], &m.particles);
        let (l, axisymmetric) = (m.grid.h_min(), m.axisymmetric);
        let source = |q: usize, st: &Stencil<D>| {
            let (mut rate, mut v_r) = (0.0, 0.0);
            st.for_each(&nb.stride, |b, w, g| {
                rate += second[b].dot(&g);
                v_r += second[b][0] * w;
            });
            let r = p.x[q][0];
            if axisymmetric {
                rate += v_r / r;
            }
            let qv = viscosity.pressure_volume(p, &m.materials, q, l, rate);
            (qv, if axisymmetric { qv / r } else { 0.0 })
        };
        // −(−q I) : ∇S V, with the hoop part on the radial component.
        let add = |n: &mut Node<D>, s: &(f64, f64), w: f64, g: &Vector<D>| {
            n.force += g * s.0;
            n.force[0] += s.1 * w;
        };
        let points = Points::of(p);
        nb.scatter(s.shape, &m.grid, points, &mut self.nodes, source, add);
    }

    /// Absorbing faces: the dashpot (and spring) force f_p = −(C v_p + K u_p) of
    /// every particle in their outer cell layer (2-63), v_p = Σ_I S_Ip v_I of the
    /// step-start velocity, and an incoming wave's 2 C v_in(t) at the step
    /// start, spread as S_Ip f_p, in particle order.
    fn add_absorbing_force(&mut self, m: &Model<D>, s: &Step<D>) {
        let p = &m.particles;
        for lp in absorbing::layer(&m.absorbing, &m.grid, p, s.t) {
            let q = lp.q;
            if self.removed.get(q) == Some(&true) {
                continue;
            }
            let f = deformation_for(s.shape, || p.f.get(q));
            let st = self
                .nb
                .stencil(s.shape, &m.grid, &p.x[q], &p.half_length0[q], &f);
            let Some(st) = st else { continue };
            let mut v = Vector::<D>::zeros();
            st.for_each(&self.nb.stride, |b, w, _| v += self.second[b] * w);
            // u_p = x_p − X_p.
            let force = lp.force(&v, &(p.x[q] - p.x0[q]));
            let nodes = &mut self.nodes;
            st.for_each(&self.nb.stride, |b, w, _| nodes[b].force += force * w);
        }
    }
}

/// Axisymmetric mode: the hoop rate v_r(x_p) / r_p = Σ_I v_Ir S_Ip / r_p of a
/// particle at x with stencil `sc`, `v_r(node)` the nodal radial velocity.
#[inline(never)]
fn hoop_rate<const D: usize>(
    sc: &Stencil<D>,
    nb: &NodeBox<D>,
    v_r: impl Fn(usize) -> f64,
    x: &Vector<D>,
) -> f64 {
    let mut sum = 0.0;
    sc.for_each(&nb.stride, |b, w, _| sum += v_r(b) * w);
    sum / x[0]
}

/// Where a particle may be after a step (`divergence::check_state`): in the
/// grid unless the scene removes particles that leave it, and off the axis in
/// axisymmetric mode.
#[derive(Clone, Copy)]
struct Placed<'a, const D: usize> {
    grid: &'a Grid<D>,
    remove_outside: bool,
    axisymmetric: bool,
}

impl<'a, const D: usize> Placed<'a, D> {
    fn of(grid: &'a Grid<D>, remove_outside: bool, axisymmetric: bool) -> Self {
        Placed {
            grid,
            remove_outside,
            axisymmetric,
        }
    }

    #[inline(always)]
    fn at(&self, x: &Vector<D>) -> bool {
        (self.grid.contains(x) || self.remove_outside) && (!self.axisymmetric || x[0] > 0.0)
    }
}

/// The particle arrays a particle pass changes.
struct Parts<'a, const D: usize> {
    x: &'a mut [Vector<D>],
    v: &'a mut [Vector<D>],
    f: &'a mut Tensors,
    stress: &'a mut Tensors,
    volume: &'a mut [f64],
    history: &'a mut History,
}

/// `body(q, state)` for every particle, in parallel over tasks of `TASK`
/// particles; `body` returns the particle's work term, whether it inverted
/// and whether it is unsound. Returns the summed work (in particle order
/// within each chunk of `parallel::deterministic_sum`, then over the chunks),
/// the first inverted and the first unsound particle.
#[inline(always)]
fn over_particles<const D: usize>(
    parts: Parts<D>,
    body: impl Fn(usize, Moving<D>) -> (f64, bool, bool) + Sync,
) -> (f64, Option<usize>, Option<usize>) {
    let Parts {
        x,
        v,
        f,
        stress,
        volume,
        history,
    } = parts;
    let mut works = vec![0.0; x.len()];
    let chunk = |c: usize,
                 ws: &mut [f64],
                 xs: &mut [Vector<D>],
                 vs: &mut [Vector<D>],
                 mut fs: TensorsMut,
                 mut ss: TensorsMut,
                 vols: &mut [f64],
                 mut hs: Option<&mut [&mut [f64]]>| {
        let (mut first_inverted, mut bad) = (usize::MAX, usize::MAX);
        for i in 0..xs.len() {
            let history: &mut [f64] = match &mut hs {
                Some(hs) => hs[i],
                None => &mut [],
            };
            let state = Moving {
                x: &mut xs[i],
                v: &mut vs[i],
                deformation: ParticleState {
                    f: fs.at(i),
                    stress: ss.at(i),
                    volume: &mut vols[i],
                    history,
                },
            };
            let q = c * TASK + i;
            let (w, inverts, unsound) = body(q, state);
            ws[i] = w;
            if inverts {
                first_inverted = first_inverted.min(q);
            }
            if unsound {
                bad = bad.min(q);
            }
        }
        (first_inverted, bad)
    };
    let chunks = (works.par_chunks_mut(TASK))
        .zip(x.par_chunks_mut(TASK))
        .zip(v.par_chunks_mut(TASK))
        .zip(f.par_chunks_mut(TASK))
        .zip(stress.par_chunks_mut(TASK))
        .zip(volume.par_chunks_mut(TASK))
        .enumerate();
    let per_task: Vec<(usize, usize)> = match history.data.is_empty() {
        true => chunks
            .map(|(c, (((((ws, xs), vs), fs), ss), vols))| chunk(c, ws, xs, vs, fs, ss, vols, None))
            .collect(),
        false => {
            let mut slots = history.own_slots_mut();
            chunks
                .zip(slots.par_chunks_mut(TASK))
                .map(|((c, (((((ws, xs), vs), fs), ss), vols)), hs)| {
                    chunk(c, ws, xs, vs, fs, ss, vols, Some(hs))
                })
                .collect()
        }
    };
    (
        chunked_sum(&works),
        first(per_task.iter().map(|t| t.0)),
        first(per_task.iter().map(|t| t.1)),
    )
}

/// Σ w in particle order within each chunk of `SUM_CHUNK`, then over the
/// chunks: the sum `parallel::deterministic_sum` forms.
fn chunked_sum(works: &[f64]) -> f64 {
    let chunk_sum = |c: &[f64]| {
        let mut sum = 0.0;
        for w in c {
            sum += w;
        }
        sum
    };
    works.chunks(SUM_CHUNK).map(chunk_sum).sum()
}

/// The least particle index of `qs` (usize::MAX: none).
fn first(qs: impl Iterator<Item = usize>) -> Option<usize> {
    qs.min().filter(|&q| q != usize::MAX)
}

/// What one particle pass does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pass {
    /// USL: G2P (velocity and position) and the stress from the updated velocity.
    Full,
    /// USF: the stress from the step-start velocity (`second`).
    Stress,
    /// USF: G2P.
    Motion,
    /// MUSL: the position, and the stress from the remapped velocity (`second`).
    Remapped,
}

/// The state of one particle that a pass changes: its motion and what the
/// stress update changes.
struct Moving<'a, const D: usize> {
    x: &'a mut Vector<D>,
    v: &'a mut Vector<D>,
    deformation: ParticleState<'a>,
}

/// A particle's Σ S_I v_I and Σ S_I a_I from the updated nodes (`MOTION`), and
/// L = Σ v_I ⊗ ∇S_I from the updated velocity (`GRAD` = 1) or from `second`
/// (`GRAD` = 2).
#[inline(always)]
fn gather<const D: usize, const MOTION: bool, const GRAD: u8>(
    sc: &crate::solver::explicit::node_box::Stencil<D>,
    nb: &NodeBox<D>,
    nodes: &[Node<D>],
    second: &[Vector<D>],
) -> (Vector<D>, Vector<D>, Tensor<D>) {
    let (mut vp, mut a, mut l) = (
        Vector::<D>::zeros(),
        Vector::<D>::zeros(),
        Tensor::<D>::zeros(),
    );
    sc.for_each(&nb.stride, |b, w, g| {
        let n = &nodes[b];
        if MOTION {
            vp += n.momentum * w;
            a += n.force * w;
        }
        match GRAD {
            1 => l += n.momentum * g.transpose(),
            2 => l += second[b] * g.transpose(),
            _ => {}
        }
    });
    (vp, a, l)
}
