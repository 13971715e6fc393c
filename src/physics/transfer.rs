//! Particle-to-grid and grid-to-particle transfers (thesis 2-20…2-27, GIMP 2-50…2-52).
//!
//! Only nodes touched by a particle are active. P2G is a gather: every active node
//! sums its particle contributions in increasing particle order, so the result is
//! bit-identical for any number of threads. G2P loops over particles, each reading
//! its own stencil.

use crate::dim::{Tensor, Vector};
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::{ShapeFunction, Stencils};
use rayon::prelude::*;

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
}

impl NodeMap {
    pub const NONE: u32 = u32::MAX;

    /// Rebuild for this step's stencils on a grid with `n_nodes` nodes.
    pub fn build<const D: usize>(&mut self, st: &Stencils<D>, n_nodes: usize) {
        if self.local.len() != n_nodes {
            self.local = vec![Self::NONE; n_nodes];
        } else {
            for &g in &self.active {
                self.local[g as usize] = Self::NONE;
            }
        }
        self.active.clear();
        let n_particles = st.count.len();
        for p in 0..n_particles {
            for e in st.range(p) {
                let g = st.node[e] as usize;
                if self.local[g] == Self::NONE {
                    self.local[g] = 0;
                    self.active.push(g as u32);
                }
            }
        }
        self.active.sort_unstable();
        for (a, &g) in self.active.iter().enumerate() {
            self.local[g as usize] = a as u32;
        }
        // Counting sort of entries by node, stable in entry order.
        self.start.clear();
        self.start.resize(self.active.len() + 1, 0);
        for p in 0..n_particles {
            for e in st.range(p) {
                self.start[self.local[st.node[e] as usize] as usize + 1] += 1;
            }
        }
        for a in 0..self.active.len() {
            self.start[a + 1] += self.start[a];
        }
        let mut next: Vec<u32> = self.start[..self.active.len()].to_vec();
        self.entries.resize(*self.start.last().unwrap() as usize, 0);
        for p in 0..n_particles {
            for e in st.range(p) {
                let a = self.local[st.node[e] as usize] as usize;
                self.entries[next[a] as usize] = e as u32;
                next[a] += 1;
            }
        }
    }

    pub fn len(&self) -> usize {
        self.active.len()
    }

    pub fn is_empty(&self) -> bool {
        self.active.is_empty()
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
        (0..self.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|a| {
                self.node_entries(a)
                    .iter()
                    .fold(zero, |acc, &e| acc + f(e as usize / stride, e as usize))
            })
            .collect()
    }
}

/// The particles' shape-function stencils on the grid and the active nodes they
/// touch: what every step starts from.
pub fn stencils_and_nodes<const D: usize>(
    m: &Model<D>,
    shape: ShapeFunction,
    st: &mut Stencils<D>,
    map: &mut NodeMap,
) {
    let p = &m.particles;
    st.compute(shape, &m.grid, &p.x, &p.half_length0, &p.f);
    map.build(st, m.grid.node_count());
}

/// Nodal mass (2-24) and momentum (2-25).
pub fn mass_momentum<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
) -> (Vec<f64>, Vec<Vector<D>>) {
    let mass = map.gather(st.stride, 0.0, |q, e| p.mass[q] * st.weight[e]);
    let momentum = map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        p.v[q] * (p.mass[q] * st.weight[e])
    });
    (mass, momentum)
}

/// v_I = p_I / m_I (2-25); zero on a node whose mass is exactly zero.
pub fn mass_average<const D: usize>(mass: &[f64], momentum: &[Vector<D>]) -> Vec<Vector<D>> {
    (0..mass.len())
        .map(|a| {
            if mass[a] > 0.0 {
                momentum[a] / mass[a]
            } else {
                Vector::<D>::zeros()
            }
        })
        .collect()
}

/// Nodal force f_ext − f_int: internal −Σ V_p σ_p ∇S_Ip (2-51), external
/// Σ S_Ip (m_p g + s_p f_p) (2-52) with s_p the load factor of particle p.
pub fn nodal_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: &Particles<D>,
    gravity: &Vector<D>,
    load_factor: &(impl Fn(usize) -> f64 + Sync),
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        let sigma: Tensor<D> = crate::dim::restrict::<D>(&p.stress[q]);
        let internal = sigma * st.grad[e] * p.volume[q];
        let external = applied_force(p, q, gravity, load_factor) * st.weight[e];
        external - internal
    })
}

/// Force applied to particle q: m_q g + s_q f_q (gravity and its scaled load).
pub fn applied_force<const D: usize>(
    p: &Particles<D>,
    q: usize,
    gravity: &Vector<D>,
    load_factor: &impl Fn(usize) -> f64,
) -> Vector<D> {
    gravity * p.mass[q] + p.load[q] * load_factor(q)
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
        applied_force(p, q, gravity, load_factor) * st.weight[e]
    })
}

/// Σ_I S_Ip u_I for particle p (interpolation of a nodal vector field).
pub fn interpolate<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[Vector<D>],
) -> Vector<D> {
    st.range(p).fold(Vector::<D>::zeros(), |acc, e| {
        acc + u[map.local[st.node[e] as usize] as usize] * st.weight[e]
    })
}

/// Σ_I u_I ⊗ ∇S_Ip for particle p (gradient of a nodal vector field, e.g. L_p).
pub fn gradient<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    p: usize,
    u: &[Vector<D>],
) -> Tensor<D> {
    st.range(p).fold(Tensor::<D>::zeros(), |acc, e| {
        acc + u[map.local[st.node[e] as usize] as usize] * st.grad[e].transpose()
    })
}
