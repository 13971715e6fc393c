//! Particle-side transfers on a dense box of nodes, for the explicit step's
//! box-scatter back-end (`solver::explicit::scatter`): separable shape
//! functions (linear, GIMP, B-splines); what else it serves the features
//! declare (`solver::explicit::features`).
//!
//! The nodes that the particles can touch form a box (their cells' range,
//! widened by the family's reach). P2G is a scatter: each particle evaluates
//! its 1D factors (`shape::separable_axes`) and adds its contributions into the
//! box's nodes, the tensor product formed on the fly; nothing per entry is
//! stored. Scatters in parallel stay deterministic by colouring: the box's
//! cells are grouped into tiles of `TILE` cells per axis, the particles are
//! sorted by tile (stable, `parallel::bucket_sort`), and the tiles are visited
//! colour by colour (the parity of the tile index on every axis, 2^D colours).
//! Two tiles of one colour are two or more tiles apart on some axis, so they
//! share no node (`TILE` ≥ the family's reach, checked for every particle), and
//! every node receives its contributions in one fixed order: colour by colour,
//! within a tile in increasing particle order. The sums are therefore the same
//! on any number of threads; they differ from the node map's (increasing
//! particle order at every node) at round-off. G2P needs no colouring: each
//! particle reads its nodes and writes only itself.

use crate::dim::{Mat3, Vector};
use crate::model::grid::{greville, Grid};
use crate::model::particles::Particles;
use crate::model::tensors::Tensors;
use crate::parallel::{bucket_sort, DisjointSlice, MIN_PARALLEL_LEN, NO_BUCKET};
use crate::physics::shape::linear::{cell_coordinate, cell_index};
use crate::physics::shape::{deformation_for, separable_axes, ShapeFunction, MAX_PER_AXIS};
use rayon::prelude::*;

/// Cells per axis of a tile. Must be at least the family's reach − 1
/// (`Reach::tile_ok`): 4 serves every separable family.
const TILE: usize = 4;

/// The nodes a family touches relative to a particle's cell c along one axis:
/// [c − below, c + above).
#[derive(Clone, Copy, Debug)]
struct Reach {
    below: usize,
    above: usize,
}

impl Reach {
    fn of(shape: ShapeFunction) -> Option<Reach> {
        let (below, above) = match shape {
            ShapeFunction::Linear => (0, 2),
            ShapeFunction::Ugimp | ShapeFunction::Cpgimp => (1, 3),
            ShapeFunction::Bspline2 => (0, 3),
            ShapeFunction::Bspline3 => (0, 4),
            ShapeFunction::Cpbspline2 => (1, 4),
            ShapeFunction::Cpdi => return None,
        };
        Some(Reach { below, above })
    }

    /// Tiles of one colour are a tile apart: a particle of one writes nodes up
    /// to (t+1)·TILE − 1 + above − 1, one of the next from (t+2)·TILE − below.
    fn tile_ok(&self) -> bool {
        self.above + self.below < TILE + 2
    }
}

/// The shape functions of one particle on the box: the 1D factors of every
/// axis (a 2D particle has a third axis with one factor 1, slope 0) and the box
/// index of its first node.
#[derive(Clone, Copy, Debug)]
pub struct Stencil<const D: usize> {
    base: usize,
    first: [usize; 3],
    count: [usize; 3],
    weight: [[f64; MAX_PER_AXIS]; 3],
    slope: [[f64; MAX_PER_AXIS]; 3],
}

impl<const D: usize> Stencil<D> {
    /// Calls `visit(node, S_Ip, ∇S_Ip)` for every node of the tensor product,
    /// `node` the box index (`stride` the box's strides), x fastest. S_I =
    /// S_x (S_y S_z), ∂S_I/∂x = S'_x (S_y S_z), ∂S_I/∂y = S_x (S'_y S_z),
    /// ∂S_I/∂z = S_x (S_y S'_z).
    #[inline(always)]
    pub fn for_each(&self, stride: &[usize; 3], mut visit: impl FnMut(usize, f64, Vector<D>)) {
        // The second "gradient" is the first again, unused: the compiler drops it.
        self.for_each_with(stride, &self.slope, |b, w, g, _| visit(b, w, g))
    }

    /// `for_each` that also forms `second` 1D slopes t as ∇S_I forms the
    /// first: `visit(node, S_I, ∇S_I, G_I)` with G_I,x = t_x (S_y S_z) and so on
    /// (APIC's moments and affine weights).
    #[inline(always)]
    pub fn for_each_with(
        &self,
        stride: &[usize; 3],
        second: &Slopes,
        mut visit: impl FnMut(usize, f64, Vector<D>, Vector<D>),
    ) {
        let (w, s, t) = (&self.weight, &self.slope, second);
        for k in 0..self.count[2] {
            for j in 0..self.count[1] {
                let row = self.base + j * stride[1] + k * stride[2];
                let wyz = w[1][j] * w[2][k];
                let (syz, wysz) = (s[1][j] * w[2][k], w[1][j] * s[2][k]);
                let (tyz, wytz) = (t[1][j] * w[2][k], w[1][j] * t[2][k]);
                for i in 0..self.count[0] {
                    let g = [s[0][i] * wyz, w[0][i] * syz, w[0][i] * wysz];
                    let h = [t[0][i] * wyz, w[0][i] * tyz, w[0][i] * wytz];
                    visit(
                        row + i,
                        w[0][i] * wyz,
                        Vector::<D>::from_fn(|d, _| g[d]),
                        Vector::<D>::from_fn(|d, _| h[d]),
                    );
                }
            }
        }
    }

    /// The offsets δ_i = x_i − x_p of the stencil's nodes along every axis
    /// (node positions as `Grid::node_position`: Greville abscissae for B-splines).
    pub fn offsets(&self, grid: &Grid<D>, x: &Vector<D>) -> Slopes {
        let mut delta = [[0.0; MAX_PER_AXIS]; 3];
        let p = grid.degree;
        for d in 0..D {
            let (first, count, h) = (self.first[d], self.count[d], grid.h[d]);
            // Away from the clamped ends the Greville abscissae are a cell apart,
            // node i at i − (p − 1)/2 cells (every node of the degree-1 families).
            if first + 1 >= p && first + count <= grid.cells[d] + 1 {
                let start = grid.min[d] + h * (first as f64 - 0.5 * (p - 1) as f64) - x[d];
                for (i, o) in delta[d].iter_mut().enumerate().take(count) {
                    *o = start + h * i as f64;
                }
                continue;
            }
            for (i, o) in delta[d].iter_mut().enumerate().take(count) {
                let node = greville(first + i, p, grid.cells[d]);
                *o = grid.min[d] + h * node - x[d];
            }
        }
        delta
    }

    /// The 1D factors of APIC (`solver::explicit::apic`) along every axis: the moments
    /// w_i δ_i and the inertia D_dd = Σ_i w_i δ_i² (D_p is diagonal for a tensor
    /// product of 1D bases that reproduce linear functions).
    pub fn moments(&self, grid: &Grid<D>, x: &Vector<D>) -> Moments {
        let delta = self.offsets(grid, x);
        let (mut moment, mut inertia) = ([[0.0; MAX_PER_AXIS]; 3], [0.0; 3]);
        for d in 0..D {
            for i in 0..self.count[d] {
                moment[d][i] = self.weight[d][i] * delta[d][i];
                inertia[d] += moment[d][i] * delta[d][i];
            }
        }
        (moment, inertia)
    }

    /// The first slopes S'_i along every axis.
    pub fn slopes(&self) -> Slopes {
        self.slope
    }
}

/// APIC's 1D moments w_i δ_i of a stencil along every axis and its inertia
/// D_dd per axis (`Stencil::moments`).
pub type Moments = (Slopes, [f64; 3]);

/// One value per node along every axis of a stencil (1D factors).
pub type Slopes = [[f64; MAX_PER_AXIS]; 3];

/// What the shape functions read of the particles: the positions and, for
/// GIMP and the domain B-splines, the domains' reference half-lengths and F.
#[derive(Clone, Copy)]
pub struct Points<'a, const D: usize> {
    pub x: &'a [Vector<D>],
    pub half_length0: &'a [Vector<D>],
    pub f: &'a Tensors,
}

impl<'a, const D: usize> Points<'a, D> {
    pub fn of(p: &'a Particles<D>) -> Self {
        Points {
            x: &p.x,
            half_length0: &p.half_length0,
            f: &p.f,
        }
    }
}

/// The box of nodes of one step and the particles sorted by tile.
#[derive(Clone, Debug)]
pub struct NodeBox<const D: usize> {
    /// First grid node of the box on every axis, and its nodes per axis.
    lo: [usize; D],
    len: [usize; D],
    /// Box strides (x fastest), padded to 3 axes.
    pub stride: [usize; 3],
    /// The first particle cell on every axis (tile 0 starts there), tiles per axis.
    cell_lo: [usize; D],
    tiles: [usize; D],
    /// Particles by tile: tile t holds `order[start[t]..start[t + 1]]`.
    start: Vec<u32>,
    order: Vec<u32>,
    /// Per particle: its tile (scratch of `locate`).
    key: Vec<u32>,
}

impl<const D: usize> Default for NodeBox<D> {
    fn default() -> Self {
        NodeBox {
            lo: [0; D],
            len: [0; D],
            stride: [1, 0, 0],
            cell_lo: [0; D],
            tiles: [0; D],
            start: vec![0],
            order: Vec::new(),
            key: Vec::new(),
        }
    }
}

impl<const D: usize> NodeBox<D> {
    /// Can the family be scattered on a box?
    pub fn serves(shape: ShapeFunction) -> bool {
        Reach::of(shape).is_some_and(|r| r.tile_ok())
    }

    /// Nodes in the box.
    pub fn nodes(&self) -> usize {
        self.len.iter().product()
    }

    /// The grid node of box node b.
    pub fn grid_ijk(&self, b: usize) -> [usize; D] {
        let mut rest = b;
        std::array::from_fn(|d| {
            let i = rest % self.len[d];
            rest /= self.len[d];
            self.lo[d] + i
        })
    }

    /// Box nodes per x-row, rows in box order (for loops over the box by rows).
    pub fn row_len(&self) -> usize {
        self.len[0]
    }

    /// Set the box and the tiles for the particles at `x`. Those outside the
    /// grid touch no node (as in `Stencils::compute`), nor do those that
    /// `removed` marks (empty: none; `Model::removed`).
    pub fn locate(
        &mut self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        x: &[Vector<D>],
        removed: &[bool],
    ) {
        let reach = Reach::of(shape).expect("a separable family");
        let cell = |xq: &Vector<D>| -> [usize; D] {
            std::array::from_fn(|d| cell_index(cell_coordinate(grid, xq, d), grid.cells[d]))
        };
        // The cells' range from the positions' range: the cell of a point is
        // non-decreasing in each of its coordinates. In chunks, plain loops.
        let none = || (Vector::<D>::repeat(f64::MAX), Vector::<D>::repeat(f64::MIN));
        let (x_lo, x_hi) = x
            .par_chunks(MIN_PARALLEL_LEN)
            .map(|xs| {
                xs.iter()
                    .filter(|xq| grid.contains(xq))
                    .fold(none(), |(lo, hi), xq| (lo.inf(xq), hi.sup(xq)))
            })
            .reduce(none, |(a, b), (c, e)| (a.inf(&c), b.sup(&e)));
        if x_lo[0] > x_hi[0] {
            // No particle in the grid: an empty box.
            let (key, order) = (
                std::mem::take(&mut self.key),
                std::mem::take(&mut self.order),
            );
            *self = NodeBox {
                key,
                order,
                ..Default::default()
            };
            self.order.clear();
            return;
        }
        let (lo, hi) = (cell(&x_lo), cell(&x_hi));
        self.cell_lo = lo;
        self.tiles = std::array::from_fn(|d| (hi[d] - lo[d]) / TILE + 1);
        self.lo = std::array::from_fn(|d| lo[d].saturating_sub(reach.below));
        self.len = std::array::from_fn(|d| (hi[d] + reach.above).min(grid.nodes[d]) - self.lo[d]);
        self.stride = [1, 0, 0];
        for d in 1..3 {
            self.stride[d] = match d < D {
                true => self.stride[d - 1] * self.len[d - 1],
                false => 0,
            };
        }
        let tile_stride = strides(&self.tiles);
        let (cell_lo, key) = (self.cell_lo, &mut self.key);
        key.resize(x.len(), 0);
        key.par_chunks_mut(MIN_PARALLEL_LEN)
            .zip(x.par_chunks(MIN_PARALLEL_LEN))
            .for_each(|(ks, xs)| {
                for (k, xq) in ks.iter_mut().zip(xs) {
                    *k = match grid.contains(xq) {
                        true => {
                            let c = cell(xq);
                            (0..D)
                                .map(|d| (c[d] - cell_lo[d]) / TILE * tile_stride[d])
                                .sum::<usize>() as u32
                        }
                        false => NO_BUCKET,
                    };
                }
            });
        for (k, _) in key.iter_mut().zip(removed).filter(|(_, &r)| r) {
            *k = NO_BUCKET;
        }
        let n_tiles = self.tiles.iter().product();
        bucket_sort(&self.key, n_tiles, &mut self.start, &mut self.order);
    }

    /// The stencil of a particle at `x` (half-lengths and F for the GIMP and
    /// domain families), `None` outside the grid.
    #[inline(always)]
    pub fn stencil(
        &self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        x: &Vector<D>,
        half_length0: &Vector<D>,
        f: &Mat3,
    ) -> Option<Stencil<D>> {
        if !grid.contains(x) {
            return None;
        }
        let axes = separable_axes(shape, grid, x, half_length0, f);
        let mut st = Stencil {
            base: 0,
            first: [0; 3],
            count: [1; 3],
            weight: [[1.0; MAX_PER_AXIS]; 3],
            slope: [[0.0; MAX_PER_AXIS]; 3],
        };
        for (d, a) in axes.iter().enumerate() {
            // A node below the box wraps to an index beyond it: the reads and
            // writes check their bounds.
            st.base = st
                .base
                .wrapping_add(a.first.wrapping_sub(self.lo[d]) * self.stride[d]);
            st.first[d] = a.first;
            st.count[d] = a.count;
            st.weight[d] = a.weight;
            st.slope[d] = a.slope;
        }
        Some(st)
    }

    /// The nodes the particles of tile `t` may write along every axis without
    /// meeting another tile of its colour: [first, end).
    fn tile_nodes(&self, t: usize, reach: Reach) -> ([usize; D], [usize; D]) {
        let tile_stride = strides(&self.tiles);
        let start = |d: usize| self.cell_lo[d] + (t / tile_stride[d] % self.tiles[d]) * TILE;
        (
            std::array::from_fn(|d| start(d).saturating_sub(reach.below)),
            std::array::from_fn(|d| start(d) + TILE - 1 + reach.above),
        )
    }

    /// P2G by colours: for every particle q in the grid, `add(node, &source(q,
    /// stencil), S_Iq, ∇S_Iq)` at each of its nodes, `nodes` one value per box
    /// node. `source` is called once per particle (in its tile's task, so it may
    /// also update particle q alone), `add` once per entry.
    pub fn scatter<N: Send, S>(
        &self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        points: Points<D>,
        nodes: &mut [N],
        source: impl Fn(usize, &Stencil<D>) -> S + Sync,
        add: impl Fn(&mut N, &S, f64, &Vector<D>) + Sync,
    ) {
        self.coloured(shape, grid, points, nodes, |q, st, out| {
            let s = source(q, st);
            st.for_each(&self.stride, |b, w, g| {
                // SAFETY: tiles of one colour touch disjoint nodes (module doc),
                // and this tile's particles are visited by this task alone.
                add(unsafe { out.at(b) }, &s, w, &g)
            })
        });
    }

    /// `scatter` with second slopes that `source` gives beside its value
    /// (`Stencil::for_each_with`): `add(node, &s, S_Iq, ∇S_Iq, G_Iq)`.
    pub fn scatter_with_second<N: Send, S>(
        &self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        points: Points<D>,
        nodes: &mut [N],
        source: impl Fn(usize, &Stencil<D>) -> (S, Slopes) + Sync,
        add: impl Fn(&mut N, &S, f64, &Vector<D>, &Vector<D>) + Sync,
    ) {
        self.coloured(shape, grid, points, nodes, |q, st, out| {
            let (s, second) = source(q, st);
            st.for_each_with(&self.stride, &second, |b, w, g, h| {
                // SAFETY: as in `scatter`.
                add(unsafe { out.at(b) }, &s, w, &g, &h)
            })
        });
    }

    /// The colouring of the scatters (module doc): `each(q, stencil, nodes)`
    /// for every particle q in the grid, the tiles of one colour in parallel.
    fn coloured<N: Send>(
        &self,
        shape: ShapeFunction,
        grid: &Grid<D>,
        points: Points<D>,
        nodes: &mut [N],
        each: impl Fn(usize, &Stencil<D>, &DisjointSlice<N>) + Sync,
    ) {
        assert_eq!(nodes.len(), self.nodes(), "one value per box node");
        let reach = Reach::of(shape).expect("a separable family");
        let out = DisjointSlice::new(nodes);
        let tile_stride = strides(&self.tiles);
        let n_tiles: usize = self.tiles.iter().product();
        for colour in 0..1usize << D {
            let of_colour: Vec<usize> = (0..n_tiles)
                .filter(|&t| {
                    (0..D).all(|d| (t / tile_stride[d] % self.tiles[d]) & 1 == colour >> d & 1)
                })
                .collect();
            // Tasks of at least MIN_PARALLEL_LEN particles on average: a small
            // scene scatters in one task (the sums are the same either way).
            let per_tile = self.order.len() / n_tiles.max(1) + 1;
            let tiles_per_task = MIN_PARALLEL_LEN.div_ceil(per_tile);
            of_colour.par_iter().with_min_len(tiles_per_task).for_each(|&t| {
                let (first, end) = self.tile_nodes(t, reach);
                for &q in &self.order[self.start[t] as usize..self.start[t + 1] as usize] {
                    let q = q as usize;
                    let f = deformation_for(shape, || points.f.get(q));
                    let (x, half) = (&points.x[q], &points.half_length0[q]);
                    let Some(st) = self.stencil(shape, grid, x, half, &f) else {
                        continue;
                    };
                    assert!(
                        (0..D).all(|d| st.first[d] >= first[d] && st.first[d] + st.count[d] <= end[d]),
                        "{shape:?} reaches beyond its tile's nodes: the colouring would not hold"
                    );
                    each(q, &st, &out);
                }
            });
        }
    }
}

/// Strides of a D-dimensional array with `len` entries per axis, x fastest.
fn strides<const D: usize>(len: &[usize; D]) -> [usize; D] {
    let mut s = [1; D];
    for d in 1..D {
        s[d] = s[d - 1] * len[d - 1];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::shape::tests::sample_points;
    use crate::physics::shape::Stencils;
    use crate::physics::transfer::NodeMap;
    use strum::IntoEnumIterator;

    fn particles<const D: usize>(grid: &Grid<D>, n: usize) -> Particles<D> {
        let mut p = Particles::<D>::default();
        for (k, x) in sample_points(grid, n).into_iter().enumerate() {
            let half = Vector::<D>::repeat(0.2 * grid.h.min());
            let v = Vector::<D>::from_fn(|d, _| ((k * (d + 3)) % 7) as f64 - 3.0);
            p.push(x, v, 1.0 + (k % 5) as f64, 0.1, half, 0, 0, 0);
        }
        p
    }

    /// The box's mass and momentum equal the node map's gather at every node
    /// (to round-off: the orders differ), for every separable family in 2D
    /// and 3D, on 1 and 3 threads with the same bits.
    fn scatter_is_the_gather<const D: usize>(cells: usize) {
        for shape in ShapeFunction::iter().filter(|&s| NodeBox::<D>::serves(s)) {
            let degree = shape.degree();
            let grid = Grid::<D>::new(
                Vector::<D>::zeros(),
                Vector::<D>::repeat(2.0),
                [cells; D],
                degree,
            );
            let p = particles(&grid, 3000);
            let mut st = Stencils::<D>::default();
            st.compute(shape, &grid, &p.x, &p.half_length0, &p.f);
            let mut map = NodeMap::default();
            map.build(&st, grid.node_count());
            let (mass, momentum) = crate::physics::transfer::mass_momentum(&map, &st, &p, None);
            let mut bits: Option<Vec<f64>> = None;
            for threads in [1, 3] {
                let mut nb = NodeBox::<D>::default();
                let mut nodes = Vec::new();
                crate::parallel::on_threads(threads, || {
                    nb.locate(shape, &grid, &p.x, &[]);
                    nodes = vec![(0.0, Vector::<D>::zeros()); nb.nodes()];
                    nb.scatter(
                        shape,
                        &grid,
                        Points::of(&p),
                        &mut nodes,
                        |q, _| (p.mass[q], p.v[q] * p.mass[q]),
                        |n, s, w, _| {
                            n.0 += s.0 * w;
                            n.1 += s.1 * w;
                        },
                    )
                });
                let mut seen = 0;
                for (b, n) in nodes.iter().enumerate() {
                    let g = grid.node_index(nb.grid_ijk(b));
                    let a = map.local[g];
                    if a == NodeMap::NONE {
                        assert_eq!(n.0, 0.0, "{shape:?}: mass at an inactive node");
                        continue;
                    }
                    seen += 1;
                    let a = a as usize;
                    assert!(
                        (n.0 - mass[a]).abs() <= 1e-13 * mass[a].max(1.0),
                        "{shape:?}"
                    );
                    assert!((n.1 - momentum[a]).norm() <= 1e-12 * (1.0 + momentum[a].norm()));
                }
                assert_eq!(
                    seen,
                    map.len(),
                    "{shape:?}: every active node is in the box"
                );
                let these: Vec<f64> = nodes.iter().flat_map(|n| [n.0, n.1[0]]).collect();
                match &bits {
                    None => bits = Some(these),
                    Some(b) => assert_eq!(b, &these, "{shape:?}: bits differ on {threads} threads"),
                }
            }
        }
    }

    #[test]
    fn scatter_gives_the_gather_2d() {
        scatter_is_the_gather::<2>(13);
    }

    #[test]
    fn scatter_gives_the_gather_3d() {
        scatter_is_the_gather::<3>(9);
    }
}
