//! Affine particle-in-cell transfers (APIC: Jiang, Schroeder, Selle, Teran &
//! Stomakhin 2015, SIGGRAPH; Jiang, Schroeder & Teran 2017, JCP 338), for the
//! explicit step with `velocity_transfer = "apic"`.
//!
//! A particle carries, beside its velocity v_p, the affine moment
//!   B_p = Σ_I S_Ip v_I (x_I − x_p)ᵀ                          (G2P, with v_p = Σ_I S_Ip v_I)
//! and gives the nodes the momentum of its affine velocity field:
//!   p_I = Σ_p m_p S_Ip (v_p + B_p D_p⁻¹ (x_I − x_p)),
//!   D_p = Σ_I S_Ip (x_I − x_p)(x_I − x_p)ᵀ                   (P2G; Jiang et al. 2017 §5)
//! D_p is taken where the particle is at the P2G, not where its B_p was formed:
//! then, for shape functions that reproduce linear fields (all here; B-spline
//! nodes at their Greville abscissae), the transfers conserve linear and
//! angular momentum exactly (a particle's angular momentum counts x_p × m_p v_p
//! and the skew part of m_p B_p), and an affine nodal field goes to the
//! particles and back unchanged (B_p D_p⁻¹ is its gradient). The particles'
//! velocity is PIC's, without FLIP's noise and with far less of PIC's loss.
//!
//! Linear hats: S_I D_p⁻¹ (x_I − x_p) = ∇S_I wherever D_p is invertible, and
//! D_p is singular on grid lines, so the P2G weight there is ∇S_I (the same
//! field; Hu et al. 2018, MLS-MPM §4). The tensor-product families take D_p per
//! axis (it is diagonal for them: `physics::scatter::Stencil::moments`); CPDI
//! takes it whole.

use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::physics::scatter::Stencil;
use crate::physics::shape::{Stencils, MAX_PER_AXIS};
use crate::model::Model;
use crate::physics::shape::ShapeFunction;
use crate::physics::transfer::{mass_average, mass_momentum, stencils, NodeMap};
use crate::parallel::MIN_PARALLEL_LEN;
use rayon::prelude::*;

/// The positions x_I of the active nodes of `map` (a split node at its grid node).
pub fn node_positions<const D: usize>(map: &NodeMap, grid: &Grid<D>) -> Vec<Vector<D>> {
    (0..map.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|a| grid.node_position(grid.node_ijk(map.grid_node(a))))
        .collect()
}

/// The affine part of the particles' momentum on the nodes of the node map:
/// node I receives from particle p the momentum `term(p, I)` beside m_p S_Ip v_p.
pub struct AffineMomentum<'a, const D: usize> {
    /// m_p B_p D_p⁻¹ per particle, or m_p B_p for linear hats.
    k: Vec<Tensor<D>>,
    hats: bool,
    positions: &'a [Vector<D>],
    x: &'a [Vector<D>],
}

impl<'a, const D: usize> AffineMomentum<'a, D> {
    /// From the particles' B_p, at their positions `x` (where `st` was formed),
    /// for linear hats (`hats`) or any other family.
    pub fn new(
        map: &NodeMap,
        st: &Stencils<D>,
        p: &Particles<D>,
        x: &'a [Vector<D>],
        positions: &'a [Vector<D>],
        hats: bool,
    ) -> Self {
        let k = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| {
                let mb = p.affine[q] * p.mass[q];
                match hats {
                    true => mb,
                    false => inertia(map, st, q, &x[q], positions)
                        .try_inverse()
                        .map_or_else(Tensor::<D>::zeros, |d_inv| mb * d_inv),
                }
            })
            .collect();
        AffineMomentum {
            k,
            hats,
            positions,
            x,
        }
    }

    /// The affine momentum that particle q gives active node a through stencil
    /// entry e: m B D⁻¹ (x_I − x_p) S_I, or m B ∇S_I for linear hats.
    #[inline(always)]
    pub fn term(&self, st: &Stencils<D>, q: usize, e: usize, a: usize) -> Vector<D> {
        match self.hats {
            true => self.k[q] * st.grad_at(q, e),
            false => self.k[q] * ((self.positions[a] - self.x[q]) * st.weight_at(q, e)),
        }
    }
}

/// D_p = Σ_I S_Ip (x_I − x_p)(x_I − x_p)ᵀ of particle q at x.
fn inertia<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    q: usize,
    x: &Vector<D>,
    positions: &[Vector<D>],
) -> Tensor<D> {
    st.range(q).fold(Tensor::<D>::zeros(), |acc, e| {
        let delta = positions[map.local_of(st, e)] - x;
        acc + delta * delta.transpose() * st.weight_at(q, e)
    })
}

/// B_p = Σ_I S_Ip v_I (x_I − x_p)ᵀ of particle q at x, from the nodal velocities v.
pub fn moment<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    q: usize,
    x: &Vector<D>,
    positions: &[Vector<D>],
    v: &[Vector<D>],
) -> Tensor<D> {
    st.range(q).fold(Tensor::<D>::zeros(), |acc, e| {
        let a = map.local_of(st, e);
        acc + v[a] * (positions[a] - x).transpose() * st.weight_at(q, e)
    })
}

/// Give every particle an affine moment if it has none (the first step of an
/// APIC stage after a stage that kept none): B_p of the particles' velocities
/// projected on the grid, v_I = Σ_p m_p S_Ip v_p / m_I. A body that starts in
/// rigid rotation ω then starts with B_p ≈ ω × D_p, the spin of the particle's
/// own neighbourhood, and keeps ω; with B_p = 0 it would start slower, its
/// particles' affine inertia counted but not their spin. With contact each
/// body is projected alone (bodies that meet keep their own velocity fields).
pub fn ensure<const D: usize>(m: &mut Model<D>, shape: ShapeFunction) {
    let n = m.particles.len();
    if m.particles.affine.len() == n {
        return;
    }
    let mut all = Stencils::default();
    stencils(m, shape, &mut all);
    let p = &m.particles;
    let groups: Vec<Option<u32>> = match m.contact.is_some() {
        true => (0..m.bodies.len() as u32).map(Some).collect(),
        false => vec![None],
    };
    let mut affine = vec![Tensor::<D>::zeros(); n];
    let mut map = NodeMap::default();
    for body in groups {
        let mut st = all.clone();
        if let Some(b) = body {
            (0..n).filter(|&q| p.body[q] != b).for_each(|q| st.count[q] = 0);
        }
        map.build(&st, m.grid.node_count());
        let (mass, momentum) = mass_momentum(&map, &st, p, None);
        let velocity = mass_average(&mass, &momentum);
        let positions = node_positions(&map, &m.grid);
        for q in (0..n).filter(|&q| body.is_none_or(|b| p.body[q] == b)) {
            affine[q] = moment(&map, &st, q, &p.x[q], &positions, &velocity);
        }
    }
    m.particles.affine = affine;
}

/// The 1D slopes that make APIC's P2G weight S_I D_p⁻¹ (x_I − x_p) on a
/// tensor-product stencil at x (`Stencil::for_each_with`): w_i δ_i / D_dd per
/// axis, or the hats' own slopes (their weight is ∇S_I, module doc).
pub fn weight_slopes<const D: usize>(
    st: &Stencil<D>,
    grid: &Grid<D>,
    x: &Vector<D>,
    hats: bool,
) -> [[f64; MAX_PER_AXIS]; 3] {
    if hats {
        return st.slopes();
    }
    let (mut slopes, inertia) = st.moments(grid, x);
    for d in 0..D {
        let scale = match inertia[d] > 0.0 {
            true => 1.0 / inertia[d],
            false => 0.0,
        };
        slopes[d].iter_mut().for_each(|s| *s *= scale);
    }
    slopes
}

/// B_p = Σ_I S_Ip v_I (x_I − x_p)ᵀ on a tensor-product stencil at x, from the
/// nodal values `velocity(node)` of a box of nodes.
#[inline(always)]
pub fn box_moment<const D: usize>(
    st: &Stencil<D>,
    grid: &Grid<D>,
    x: &Vector<D>,
    stride: &[usize; 3],
    velocity: impl Fn(usize) -> Vector<D>,
) -> Tensor<D> {
    let mut st = *st;
    st.set_second(st.moments(grid, x).0);
    let mut b = Tensor::<D>::zeros();
    st.for_each_with(stride, |node, _, _, moment| {
        b += velocity(node) * moment.transpose()
    });
    b
}
