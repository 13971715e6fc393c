//! Particle-to-grid and grid-to-particle transfers (thesis 2-20…2-27, GIMP 2-50…2-52),
//! for both solvers: one gather per nodal quantity (mass, momentum, internal and
//! external force, the consistent-mass product) and the interpolations back.
//!
//! Only nodes touched by a particle are active. P2G is a gather: every active node
//! sums its particle contributions in increasing particle order, so the result is
//! bit-identical for any number of threads. G2P loops over particles, each reading
//! its own stencil. (The explicit step of scenes that need no node map takes the
//! particle-side scatter of `solver::explicit::node_box` instead.)

use crate::dim::{restrict, Mat3, Tensor, Vector};
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::{DisjointSlice, MIN_PARALLEL_LEN};
use crate::physics::shape::hoop::hoop_gradients;
use crate::physics::shape::{Owner, ShapeFunction, Stencils};
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;
use std::sync::atomic::Ordering::Relaxed;

/// Active nodes of one step and, for each, the stencil entries that touch it.
#[derive(Clone, Debug, Default)]
pub struct NodeMap {
    /// Global ids of the active nodes, ascending.
    pub active: Vec<u32>,
    /// Global node id → active index (`NONE` if inactive); sized to the grid.
    pub local: Vec<u32>,
    /// CSR offsets into `entries`, one range per active node.
    pub start: Vec<u32>,
    /// Stencil entry indices (p·stride + k) in increasing order within each node.
    pub entries: Vec<u32>,
    /// Grid node of each split node (`solver::explicit::contact`): node ids from
    /// `local.len() − split.len()` on stand for one velocity field at a grid node
    /// that several fields share. Empty without contact.
    pub split: Vec<u32>,
    /// Buffers of `build`, kept between steps.
    scratch: BuildScratch,
}

/// The buffer the parallel `NodeMap::build` writes through shared references.
#[derive(Debug, Default)]
struct BuildScratch {
    /// Per grid node: touched by an entry this step (cleared after the build).
    touched: Vec<AtomicBool>,
}

impl Clone for BuildScratch {
    /// Scratch is not state: a copy starts without it.
    fn clone(&self) -> Self {
        BuildScratch::default()
    }
}

impl NodeMap {
    pub const NONE: u32 = u32::MAX;

    /// Rebuild for this step's stencils on a grid with `n_nodes` nodes: the
    /// active nodes in ascending order and, per node, its entries in ascending
    /// order (a stable counting sort of the entries by node). In parallel over
    /// chunks of particles; every chunk writes only positions that the counts
    /// fix, so the map is the same for any number of threads.
    pub fn build<const D: usize>(&mut self, st: &Stencils<D>, n_nodes: usize) {
        let n_particles = st.count.len();
        let chunk = n_particles
            .div_ceil(rayon::current_num_threads())
            .max(MIN_PARALLEL_LEN);
        let scratch = &mut self.scratch;
        if scratch.touched.len() < n_nodes {
            scratch
                .touched
                .resize_with(n_nodes, || AtomicBool::new(false));
        }
        let touched = &scratch.touched;
        (0..n_particles)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|p| {
                for e in st.range(p) {
                    touched[st.node[e] as usize].store(true, Relaxed);
                }
            });
        for &g in &self.active {
            if let Some(l) = self.local.get_mut(g as usize) {
                *l = Self::NONE;
            }
        }
        self.local.resize(n_nodes, Self::NONE);
        self.active = (0..n_nodes as u32)
            .into_par_iter()
            .filter(|&g| touched[g as usize].load(Relaxed))
            .collect();
        for (a, &g) in self.active.iter().enumerate() {
            self.local[g as usize] = a as u32;
            touched[g as usize].store(false, Relaxed);
        }
        // Entries per chunk of particles and node: counts[c · n + a].
        let n = self.active.len();
        let chunks = n_particles.div_ceil(chunk).max(1);
        let mut counts = vec![0u32; chunks * n];
        counts
            .par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(c, count)| {
                for p in c * chunk..((c + 1) * chunk).min(n_particles) {
                    for e in st.range(p) {
                        count[self.local_of(st, e)] += 1;
                    }
                }
            });
        // Node a's entries start at start[a]; chunk c's at start[a] + Σ_{c'<c} counts[c'][a].
        self.start.clear();
        self.start.push(0);
        for a in 0..n {
            let total: u32 = (0..chunks).map(|c| counts[c * n + a]).sum();
            self.start.push(self.start[a] + total);
        }
        let mut next = counts;
        for a in 0..n {
            let mut at = self.start[a];
            for c in 0..chunks {
                let count = next[c * n + a];
                next[c * n + a] = at;
                at += count;
            }
        }
        let total = self.start[n] as usize;
        self.entries.resize(total, 0);
        // Each chunk writes only the positions its counts reserved (node a's
        // range from start[a] + the entries of the chunks before it).
        let (entries, local) = (DisjointSlice::new(&mut self.entries), &self.local);
        next.par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(c, next)| {
                for p in c * chunk..((c + 1) * chunk).min(n_particles) {
                    for e in st.range(p) {
                        let a = local[st.node[e] as usize] as usize;
                        // SAFETY: a position reserved for this chunk's entry e alone.
                        unsafe { *entries.at(next[a] as usize) = e as u32 };
                        next[a] += 1;
                    }
                }
            });
    }

    pub fn len(&self) -> usize {
        self.active.len()
    }

    pub fn is_empty(&self) -> bool {
        self.active.is_empty()
    }

    /// The grid node of active node a (a split node's grid node).
    pub fn grid_node(&self, a: usize) -> usize {
        let g = self.active[a] as usize;
        let grid_nodes = self.local.len() - self.split.len();
        if g < grid_nodes {
            g
        } else {
            self.split[g - grid_nodes] as usize
        }
    }

    /// Is active node a one field's part of a shared grid node?
    pub fn is_split(&self, a: usize) -> bool {
        self.active[a] as usize >= self.local.len() - self.split.len()
    }

    /// Active index of the node of stencil entry e (the node must be active).
    pub fn local_of<const D: usize>(&self, st: &Stencils<D>, e: usize) -> usize {
        self.local[st.node[e] as usize] as usize
    }

    /// Entries of active node a.
    pub fn node_entries(&self, a: usize) -> &[u32] {
        &self.entries[self.start[a] as usize..self.start[a + 1] as usize]
    }

    /// For each active node, sum `f(p, e)` over its entries in particle order.
    pub fn gather<T, F>(&self, stride: usize, zero: T, f: F) -> Vec<T>
    where
        T: Copy + Send + Sync + std::ops::Add<Output = T>,
        F: Fn(usize, usize) -> T + Sync,
    {
        let owner = Owner::new(stride);
        (0..self.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| {
                self.node_entries(a)
                    .iter()
                    .fold(zero, |acc, &e| acc + f(owner.of(e), e as usize))
            })
            .collect()
    }
}

/// The particles' shape-function stencils on the grid (with the hoop gradients
/// S_Ip / r_p in axisymmetric mode).
pub fn stencils<const D: usize>(m: &Model<D>, shape: ShapeFunction, st: &mut Stencils<D>) {
    let p = &m.particles;
    st.compute(shape, &m.grid, &p.x, &p.half_length0, &p.f);
    if m.axisymmetric {
        hoop_gradients(st, &p.x);
    }
    if m.removes_particles() {
        // Eroded particles and those outside the grid touch no node: no mass,
        // momentum or force reaches the grid from them, and they take no
        // velocity from it (they stay where they were removed, with the
        // velocity and energy they had).
        for q in (0..p.len()).filter(|&q| m.removed(q)) {
            st.count[q] = 0;
        }
    }
}

/// The particles' stencils and the active nodes they touch: what every step
/// starts from (with contact: `solver::explicit::contact::Contact::stencils_and_fields`).
pub fn stencils_and_nodes<const D: usize>(
    m: &Model<D>,
    shape: ShapeFunction,
    st: &mut Stencils<D>,
    map: &mut NodeMap,
) {
    stencils(m, shape, st);
    map.build(st, m.grid.node_count());
}

/// A particle's momentum at a node beyond m_p S_Ip v_p: `extra(q, e, a)` for
/// particle q, stencil entry e, active node a (APIC's affine part,
/// `solver::explicit::apic::AffineMomentum::term`).
pub type ExtraMomentum<'a, const D: usize> = &'a (dyn Fn(usize, usize, usize) -> Vector<D> + Sync);

/// Nodal mass (2-24) and momentum (2-25), in one pass over the entries; with
/// an extra momentum per entry if given.
pub fn mass_momentum<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    extra: Option<ExtraMomentum<D>>,
) -> (Vec<f64>, Vec<Vector<D>>) {
    let owner = st.owner();
    (0..map.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|a| {
            let (mut mass, mut momentum) = (0.0, Vector::<D>::zeros());
            for &e in map.node_entries(a) {
                let (q, e) = (owner.of(e), e as usize);
                let w = st.weight_at(q, e);
                mass += p.mass[q] * w;
                momentum += p.v[q] * (p.mass[q] * w);
                if let Some(extra) = extra {
                    momentum += extra(q, e, a);
                }
            }
            (mass, momentum)
        })
        .unzip()
}

/// Σ_p m_p S_Ip a_p at every active node: the nodal momentum (2-25) of a particle
/// field, velocities, or accelerations for the Newmark projection of the implicit
/// solver.
pub fn mass_weighted<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    a: &[Vector<D>],
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        a[q] * (p.mass[q] * st.weight_at(q, e))
    })
}

/// v_I = p_I / m_I (2-25); zero on a node whose mass is exactly zero.
pub fn mass_average<const D: usize>(mass: &[f64], momentum: &[Vector<D>]) -> Vec<Vector<D>> {
    (0..mass.len())
        .map(|a| nodal_velocity(mass[a], &momentum[a]))
        .collect()
}

/// v_I = p_I / m_I of one node (2-25); zero when its mass is exactly zero.
pub fn nodal_velocity<const D: usize>(mass: f64, momentum: &Vector<D>) -> Vector<D> {
    if mass > 0.0 {
        momentum / mass
    } else {
        Vector::<D>::zeros()
    }
}

/// scale · Σ_J M_IJ w_J with the consistent mass matrix M_IJ = Σ_p m_p S_Ip S_Jp
/// (2-24 before lumping): the implicit inertial force with a consistent mass.
pub fn consistent_mass_product<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    w: &[Vector<D>],
    scale: f64,
) -> Vec<Vector<D>> {
    let at_particles: Vec<Vector<D>> = (0..p.len()).map(|q| interpolate(map, st, q, w)).collect();
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        at_particles[q] * (p.mass[q] * st.weight(e) * scale)
    })
}

/// Internal force of a particle at one stencil entry, V τ ∇S_I: the Cauchy stress
/// and the current volume (2-51), or the relative first Piola-Kirchhoff stress and
/// the step-start volume (the implicit step, 2-21 pulled back). Axisymmetric:
/// plus V τ_θθ S_I / r_p on the radial component (`physics::shape::hoop`).
fn internal_force_at<const D: usize>(
    stress: &Mat3,
    volume: f64,
    grad: &Vector<D>,
    hoop: Option<f64>,
) -> Vector<D> {
    let tau: Tensor<D> = restrict::<D>(stress);
    let mut f = tau * grad;
    if let Some(h) = hoop {
        // f_Ir += V_p σ_θθ S_Ip / r_p (the hoop term of the virtual work).
        f[0] += stress[(2, 2)] * h;
    }
    f * volume
}

/// The hoop gradient S_Ip / r_p of entry e in axisymmetric mode (`Stencils::hoop`).
fn hoop_at<const D: usize>(st: &Stencils<D>, e: usize) -> Option<f64> {
    st.hoop.get(e).copied()
}

/// External force of particle q at a stencil entry of weight S_Iq:
/// S_Iq (m_q g + s_q f_q) (2-52).
fn external_force_at<const D: usize>(
    p: &Particles<D>,
    q: usize,
    weight: f64,
    gravity: &Vector<D>,
    load_factor: &impl Fn(usize) -> f64,
) -> Vector<D> {
    applied_force(p, q, gravity, load_factor) * weight
}

/// Internal force f_I = Σ_p V_p τ_p ∇S_Ip at every active node, for the stress
/// measure τ and volumes V given (see `internal_force_at`).
pub fn internal_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    stress: &[Mat3],
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        internal_force_at(&stress[q], volume[q], &st.grad(e), hoop_at(st, e))
    })
}

/// External nodal force Σ_p S_Ip (m_p g + s_p f_p) (2-52), s_p the load factor.
pub fn external_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    gravity: &Vector<D>,
    load_factor: &(impl Fn(usize) -> f64 + Sync),
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        external_force_at(p, q, st.weight(e), gravity, load_factor)
    })
}

/// What a particle contributes to the nodal force at each of its entries:
/// the applied force m g + s f, the in-plane stress, the hoop stress
/// (axisymmetric) and the volume.
#[derive(Clone, Copy)]
struct ForceSource<const D: usize> {
    applied: Vector<D>,
    stress: Tensor<D>,
    hoop_stress: f64,
    volume: f64,
}

/// Nodal force f_ext − f_int with the particles' total Cauchy stress σ′ − p I
/// (`Particles::total_stress`) and current volume (2-51, 2-52), summed entry by
/// entry (one gather over per-particle sources).
pub fn nodal_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    gravity: &Vector<D>,
    load_factor: &(impl Fn(usize) -> f64 + Sync),
) -> Vec<Vector<D>> {
    let sources: Vec<ForceSource<D>> = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            let total = p.stored_total_stress(q);
            ForceSource {
                applied: applied_force(p, q, gravity, load_factor),
                stress: restrict::<D>(&total),
                hoop_stress: total[(2, 2)],
                volume: p.volume[q],
            }
        })
        .collect();
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        let s = &sources[q];
        let (weight, grad) = st.value_at(q, e);
        let mut f = force_at_node(&s.applied, weight, &s.stress, &grad, s.volume);
        if let Some(h) = hoop_at(st, e) {
            // f_Ir −= V_p σ_θθ S_Ip / r_p (the hoop term of the internal force).
            f[0] -= s.hoop_stress * h * s.volume;
        }
        f
    })
}

/// The force a particle gives node I of weight S_I and gradient ∇S_I:
/// S_I (m g + s f) − V σ ∇S_I (2-51, 2-52), for the applied force m g + s f,
/// the in-plane Cauchy stress σ and the current volume V. (A caller that
/// forms V σ once per particle passes it with V = 1, which is exact.)
#[inline(always)]
pub fn force_at_node<const D: usize>(
    applied: &Vector<D>,
    weight: f64,
    stress: &Tensor<D>,
    grad: &Vector<D>,
    volume: f64,
) -> Vector<D> {
    applied * weight - stress * grad * volume
}

/// Force applied to particle q: m_q g + s_q f_q (gravity and its scaled load).
#[inline(always)]
pub fn applied_force<const D: usize>(
    p: &Particles<D>,
    q: usize,
    gravity: &Vector<D>,
    load_factor: &impl Fn(usize) -> f64,
) -> Vector<D> {
    applied_to(gravity, p.mass[q], &p.load, q, || load_factor(q))
}

/// [`applied`] for particle q of the loads `load` (`Particles::load`: empty
/// when no particle carries one, and then neither load nor factor is read).
#[inline(always)]
pub fn applied_to<const D: usize>(
    gravity: &Vector<D>,
    mass: f64,
    load: &[Vector<D>],
    q: usize,
    factor: impl Fn() -> f64,
) -> Vector<D> {
    match load.get(q) {
        Some(f) => applied(gravity, mass, f, factor()),
        None => gravity * mass,
    }
}

/// m g + s f: gravity on a mass m and a load f at load factor s.
#[inline(always)]
pub fn applied<const D: usize>(
    gravity: &Vector<D>,
    mass: f64,
    load: &Vector<D>,
    s: f64,
) -> Vector<D> {
    gravity * mass + load * s
}

/// Σ_I S_Ip u_I for particle p (interpolation of a nodal vector field).
pub fn interpolate<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[Vector<D>],
) -> Vector<D> {
    st.range(p).fold(Vector::<D>::zeros(), |acc, e| {
        acc + u[map.local_of(st, e)] * st.weight_at(p, e)
    })
}

/// (Σ_I S_Ip u_I, Σ_I S_Ip w_I) for particle p: two nodal fields in one pass
/// (each sum as `interpolate` forms it).
pub fn interpolate_two<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[Vector<D>],
    w: &[Vector<D>],
) -> (Vector<D>, Vector<D>) {
    st.range(p).fold(
        (Vector::<D>::zeros(), Vector::<D>::zeros()),
        |(su, sw), e| {
            let (a, weight) = (map.local_of(st, e), st.weight_at(p, e));
            (su + u[a] * weight, sw + w[a] * weight)
        },
    )
}

/// Σ_I u_I ⊗ ∇S_Ip for particle p (gradient of a nodal vector field, e.g. L_p).
pub fn gradient<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[Vector<D>],
) -> Tensor<D> {
    st.range(p).fold(Tensor::<D>::zeros(), |acc, e| {
        acc + u[map.local_of(st, e)] * st.grad_at(p, e).transpose()
    })
}

/// Σ_I S_Ip u_I for particle p of a scalar nodal field.
pub fn interpolate_scalar<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[f64],
) -> f64 {
    (st.range(p)).fold(0.0, |acc, e| {
        acc + u[map.local_of(st, e)] * st.weight_at(p, e)
    })
}

/// Σ_I u_I ∇S_Ip for particle p: the gradient of a scalar nodal field.
pub fn scalar_gradient<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[f64],
) -> Vector<D> {
    (st.range(p)).fold(Vector::<D>::zeros(), |acc, e| {
        acc + st.grad_at(p, e) * u[map.local_of(st, e)]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::grid::Grid;
    use crate::model::tensors::{Layout, Tensors};
    use crate::physics::shape::tests::sample_points;

    /// The map by the definition: nodes in ascending order, each with its
    /// entries in ascending order.
    fn by_definition<const D: usize>(st: &Stencils<D>) -> (Vec<u32>, Vec<Vec<u32>>) {
        let mut pairs: Vec<(u32, u32)> = (0..st.count.len())
            .flat_map(|p| st.range(p).map(|e| (st.node[e], e as u32)))
            .collect();
        pairs.sort_unstable();
        let mut active: Vec<u32> = pairs.iter().map(|&(g, _)| g).collect();
        active.dedup();
        let entries = active
            .iter()
            .map(|&g| {
                pairs
                    .iter()
                    .filter(|&&(h, _)| h == g)
                    .map(|&(_, e)| e)
                    .collect()
            })
            .collect();
        (active, entries)
    }

    /// The parallel build gives the map of the definition on 1, 2 and 3 threads,
    /// also when rebuilt on a map of an earlier step.
    #[test]
    fn node_map_is_the_stable_sort_of_entries_by_node() {
        let grid = Grid::<2>::new(
            Vector::<2>::new(0.0, 0.0),
            Vector::<2>::new(3.0, 2.0),
            [30, 20],
            2,
        );
        let x = sample_points(&grid, 5000);
        let half = vec![Vector::<2>::repeat(0.025); x.len()];
        let f = Tensors::filled(Layout::gradient(2), x.len(), &Mat3::identity());
        let mut st = Stencils::<2>::default();
        st.compute(
            ShapeFunction::Bspline2,
            &grid,
            &x[..3000],
            &half[..3000],
            &f,
        );
        let mut earlier = NodeMap::default();
        earlier.build(&st, grid.node_count());
        st.compute(ShapeFunction::Bspline2, &grid, &x, &half, &f);
        let (active, entries) = by_definition(&st);
        for threads in 1..=3 {
            for mut map in [NodeMap::default(), earlier.clone()] {
                crate::parallel::on_threads(threads, || map.build(&st, grid.node_count()));
                assert_eq!(map.active, active, "{threads} threads");
                for (a, expected) in entries.iter().enumerate() {
                    assert_eq!(
                        map.node_entries(a),
                        &expected[..],
                        "{threads} threads, node {a}"
                    );
                    assert_eq!(map.local[active[a] as usize] as usize, a);
                }
                let inactive = map.local.iter().filter(|&&l| l == NodeMap::NONE).count();
                assert_eq!(inactive, grid.node_count() - active.len());
            }
        }
    }
}
