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
//! axis (it is diagonal for them: `solver::explicit::node_box::Stencil::moments`); CPDI
//! takes it whole.

use crate::dim::{Tensor, Vector};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::ShapeFunction;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{mass_average, mass_momentum, stencils, NodeMap};
use crate::solver::explicit::node_box::{Moments, Slopes, Stencil};
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
    /// From the particles' B_p, at their positions `x` (where `st` of
    /// `shape` was formed).
    pub fn new(
        map: &NodeMap,
        st: &Stencils<D>,
        p: &Particles<D>,
        x: &'a [Vector<D>],
        positions: &'a [Vector<D>],
        shape: ShapeFunction,
    ) -> Self {
        let hats = shape == ShapeFunction::Linear;
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
            (0..n)
                .filter(|&q| p.body[q] != b)
                .for_each(|q| st.count[q] = 0);
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
/// tensor-product stencil of `shape` (`Stencil::for_each_with`), from its
/// `moments` (`Stencil::moments`): w_i δ_i / D_dd per axis, or the hats' own
/// slopes (their weight is ∇S_I, module doc).
pub fn weight_slopes<const D: usize>(
    st: &Stencil<D>,
    moments: &Moments,
    shape: ShapeFunction,
) -> Slopes {
    if shape == ShapeFunction::Linear {
        return st.slopes();
    }
    let (mut slopes, inertia) = *moments;
    for d in 0..D {
        let scale = match inertia[d] > 0.0 {
            true => 1.0 / inertia[d],
            false => 0.0,
        };
        slopes[d].iter_mut().for_each(|s| *s *= scale);
    }
    slopes
}

/// B_p = Σ_I S_Ip v_I (x_I − x_p)ᵀ on a tensor-product stencil with these
/// `moments` (`Stencil::moments`), from the nodal values `velocity(node)` of a
/// box of nodes.
#[inline(always)]
pub fn box_moment<const D: usize>(
    st: &Stencil<D>,
    moments: &Moments,
    stride: &[usize; 3],
    velocity: impl Fn(usize) -> Vector<D>,
) -> Tensor<D> {
    let mut b = Tensor::<D>::zeros();
    st.for_each_with(stride, &moments.0, |node, _, _, moment| {
        b += velocity(node) * moment.transpose()
    });
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Mat3;
    use crate::physics::shape::tests::sample_points;
    use crate::physics::transfer::interpolate;
    use crate::solver::explicit::node_box::{NodeBox, Points};
    use strum::IntoEnumIterator;

    /// A grid of 8 cells per axis on [0, 2]^D for `shape`.
    fn grid<const D: usize>(shape: ShapeFunction) -> Grid<D> {
        Grid::new(
            Vector::<D>::zeros(),
            Vector::<D>::repeat(2.0),
            [8; D],
            shape.degree(),
        )
    }

    /// Particles in the grid's middle half (no domain clipped by the grid's
    /// faces), some on grid lines and within 1e-7 h of them, masses 1 to 5.
    fn particles<const D: usize>(grid: &Grid<D>) -> Particles<D> {
        let mut p = Particles::<D>::default();
        let inside = |x: &Vector<D>| x.iter().all(|&c| (0.5..=1.5).contains(&c));
        for (k, x) in sample_points(grid, 4000)
            .into_iter()
            .filter(inside)
            .enumerate()
        {
            let half = Vector::<D>::repeat(0.25 * grid.h.min());
            p.push(
                x,
                Vector::<D>::zeros(),
                1.0 + (k % 5) as f64,
                0.1,
                half,
                0,
                0,
                0,
            );
        }
        p.affine = vec![Tensor::<D>::zeros(); p.len()];
        p
    }

    /// The affine field v(x) = a + C x.
    fn field<const D: usize>(x: &Vector<D>) -> Vector<D> {
        let a = Vector::<D>::from_fn(|d, _| 0.3 - 0.2 * d as f64);
        let c = Tensor::<D>::from_fn(|i, j| 1.0 + 0.5 * i as f64 - 1.5 * j as f64 + (i * j) as f64);
        a + c * x
    }

    fn gradient<const D: usize>() -> Tensor<D> {
        let (x0, mut c) = (Vector::<D>::zeros(), Tensor::<D>::zeros());
        for j in 0..D {
            c.set_column(
                j,
                &(field(&Vector::<D>::from_fn(|i, _| if i == j { 1.0 } else { 0.0 })) - field(&x0)),
            );
        }
        c
    }

    fn close<const D: usize>(a: &Vector<D>, b: &Vector<D>, what: &str) {
        assert!(
            (a - b).norm() < 1e-12 * (1.0 + b.norm()),
            "{what}: {a} against {b}"
        );
    }

    /// An affine nodal field goes to the particles (v_p = v(x_p), B_p = C D_p)
    /// and back to every node with mass unchanged, through the node map, for
    /// every family, particles on grid lines included.
    fn round_trip_on_the_node_map<const D: usize>() {
        let c = gradient::<D>();
        for shape in ShapeFunction::iter() {
            let grid = grid::<D>(shape);
            let mut p = particles(&grid);
            let (mut st, mut map) = (Stencils::<D>::default(), NodeMap::default());
            st.compute(shape, &grid, &p.x, &p.half_length0, &p.f);
            map.build(&st, grid.node_count());
            let positions = node_positions(&map, &grid);
            let nodal: Vec<Vector<D>> = positions.iter().map(field).collect();
            for q in 0..p.len() {
                p.v[q] = interpolate(&map, &st, q, &nodal);
                close(&p.v[q], &field(&p.x[q]), &format!("{shape:?}: v_p"));
                p.affine[q] = moment(&map, &st, q, &p.x[q], &positions, &nodal);
                let cd = c * inertia(&map, &st, q, &p.x[q], &positions);
                assert!(
                    (p.affine[q] - cd).norm() < 1e-12 * (1.0 + cd.norm()),
                    "{shape:?}: B_p"
                );
            }
            let affine = AffineMomentum::new(&map, &st, &p, &p.x, &positions, shape);
            let term = |q, e, a| affine.term(&st, q, e, a);
            let (mass, momentum) = mass_momentum(&map, &st, &p, Some(&term));
            for a in (0..map.len()).filter(|&a| mass[a] > 0.0) {
                close(
                    &(momentum[a] / mass[a]),
                    &nodal[a],
                    &format!("{shape:?}: v_I"),
                );
            }
        }
    }

    #[test]
    fn an_affine_field_goes_to_the_particles_and_back_on_the_node_map() {
        round_trip_on_the_node_map::<2>();
        round_trip_on_the_node_map::<3>();
    }

    /// The same on the box of nodes (`solver::explicit::node_box`) for the families it serves.
    fn round_trip_on_the_box<const D: usize>() {
        let c = gradient::<D>();
        for shape in ShapeFunction::iter().filter(|&s| NodeBox::<D>::serves(s)) {
            let grid = grid::<D>(shape);
            let mut p = particles(&grid);
            let mut nb = NodeBox::<D>::default();
            nb.locate(shape, &grid, &p.x, &[]);
            let position = |b: usize| grid.node_position(nb.grid_ijk(b));
            let nodal: Vec<Vector<D>> = (0..nb.nodes()).map(|b| field(&position(b))).collect();
            for q in 0..p.len() {
                let (x, half) = (p.x[q], p.half_length0[q]);
                let st = nb
                    .stencil(shape, &grid, &x, &half, &Mat3::identity())
                    .unwrap();
                let moments = st.moments(&grid, &x);
                p.affine[q] = box_moment(&st, &moments, &nb.stride, |b| nodal[b]);
                let inertia = moments.1;
                let cd = c * Tensor::<D>::from_fn(|i, j| if i == j { inertia[i] } else { 0.0 });
                assert!(
                    (p.affine[q] - cd).norm() < 1e-12 * (1.0 + cd.norm()),
                    "{shape:?}: B_p"
                );
                p.v[q] = field(&x);
            }
            let mut nodes = vec![(0.0, Vector::<D>::zeros()); nb.nodes()];
            let source = |q: usize, st: &Stencil<D>| {
                let slopes = weight_slopes(st, &st.moments(&grid, &p.x[q]), shape);
                (
                    (p.mass[q], p.v[q] * p.mass[q], p.affine[q] * p.mass[q]),
                    slopes,
                )
            };
            let add = |n: &mut (f64, Vector<D>),
                       s: &(f64, Vector<D>, Tensor<D>),
                       w: f64,
                       _: &Vector<D>,
                       a: &Vector<D>| {
                n.0 += s.0 * w;
                n.1 += s.1 * w + s.2 * a;
            };
            nb.scatter_with_second(shape, &grid, Points::of(&p), &mut nodes, source, add);
            for (b, n) in nodes.iter().enumerate().filter(|(_, n)| n.0 > 0.0) {
                close(&(n.1 / n.0), &nodal[b], &format!("{shape:?}: v_I"));
            }
        }
    }

    #[test]
    fn an_affine_field_goes_to_the_particles_and_back_on_the_box() {
        round_trip_on_the_box::<2>();
        round_trip_on_the_box::<3>();
    }
}
