//! The grid hierarchy of the multigrid preconditioner (`solver::linear::multigrid`):
//! the background grid coarsened by two per direction, over the active nodes only,
//! and the prolongations between the levels.
//!
//! Level l + 1 has ⌈n_l / 2⌉ cells per direction where level l has n_l (a
//! direction of one cell stays), so its cells are unions of level-l cells (the
//! last one may reach past the grid; its nodes there are ordinary unknowns of
//! the coarse space). The shape-function space of every family is a tensor
//! product of one-dimensional splines of degree p on the level's knots (p = 1:
//! the hats of linear, GIMP and CPDI grids; p = 2, 3: the clamped B-splines,
//! `physics::shape::bspline`), and the coarse space lies inside the fine one.
//! The prolongation is therefore exact: per direction, the fine coefficients of
//! each coarse basis function N^c_J are those of its interpolant at the fine
//! Greville abscissae g_i,
//!
//!   Σ_j N^f_j(g_i) P_jJ = N^c_J(g_i)        (the two-scale relation; de Boor 2001, Ch. XI:
//!                                            Schoenberg–Whitney makes the collocation matrix
//!                                            invertible; for p = 1 it is the identity, and P
//!                                            is linear interpolation),
//!
//! and P = P_x ⊗ P_y (⊗ P_z), component by component: every component a node
//! carries (`Dofs::per_node`: the D displacements, then any scalar fields) is
//! prolongated alike. Every level reproduces any field the coarse space holds,
//! in particular linear fields.
//!
//! Unknowns: level 0 has those of the step (`Dofs`: free components of untied
//! active nodes). A tied node (`min_node_support`) has no unknowns: it follows
//! its masters (u = T ũ), so the fine operator Tᵀ K T already holds it and P
//! interpolates to the untied nodes only. A coarse component is an unknown when
//! some finer unknown interpolates from it, unless the finer node that
//! coincides with it (its row of P is the unit row) has that component
//! prescribed: then the coarse component is prescribed too (a homogeneous
//! Dirichlet condition on the correction) and leaves P.

use crate::model::grid::{greville, Grid};
use crate::physics::shape::bspline::axis_values;
use crate::solver::implicit::assembly::Dofs;
use crate::solver::linear::multigrid::{Csr, Transfer};
use nalgebra::DMatrix;

/// Coarsening stops when a level would keep more than this fraction of the
/// unknowns of the finer one.
const LEAST_REDUCTION: f64 = 0.8;
const MAX_LEVELS: usize = 16;

/// Component states besides an unknown's number.
const ABSENT: u32 = u32::MAX;
const PRESCRIBED: u32 = u32::MAX - 1;

/// The nodes and unknowns of one level.
#[derive(Clone, Debug)]
pub struct Level<const D: usize> {
    /// Cells per direction and their size.
    pub cells: [usize; D],
    pub h: [f64; D],
    /// Its nodes (flat indices in the level's node layout, `cells + p` per
    /// direction, x fastest), ascending at coarse levels.
    pub nodes: Vec<usize>,
    /// Components per node (those of the step's unknowns, `Dofs::per_node`).
    pub components: usize,
    /// Per node k and component c, at k·components + c: the unknown's
    /// number, `PRESCRIBED` or `ABSENT`.
    index: Vec<u32>,
    pub unknowns: usize,
}

impl<const D: usize> Level<D> {
    /// The state of component c of node k.
    fn state(&self, k: usize, c: usize) -> u32 {
        self.index[k * self.components + c]
    }

    /// The unknown of component c of node k, if it is one.
    pub fn unknown(&self, k: usize, c: usize) -> Option<usize> {
        let i = self.state(k, c);
        (i < PRESCRIBED).then_some(i as usize)
    }

    /// The unknowns of each node that has some: the smoother's blocks, all
    /// the components of a node together.
    fn blocks(&self) -> Vec<Vec<usize>> {
        (0..self.nodes.len())
            .map(|k| {
                (0..self.components)
                    .filter_map(|c| self.unknown(k, c))
                    .collect::<Vec<_>>()
            })
            .filter(|b| !b.is_empty())
            .collect()
    }
}

/// The grid levels (finest first) and the transfers between them.
pub struct Hierarchy<const D: usize> {
    /// The levels themselves: the prolongations are all a solve needs; the
    /// tests check the levels' nodes and components against them.
    #[cfg_attr(not(test), allow(dead_code))]
    pub levels: Vec<Level<D>>,
    pub transfers: Vec<Transfer>,
}

/// Multi-index of flat node `k` in a layout of `nodes` per direction (x fastest).
pub fn node_ijk<const D: usize>(mut k: usize, nodes: [usize; D]) -> [usize; D] {
    std::array::from_fn(|d| {
        let i = k % nodes[d];
        k /= nodes[d];
        i
    })
}

fn flat<const D: usize>(ijk: [usize; D], nodes: [usize; D]) -> usize {
    (0..D).rev().fold(0, |acc, d| acc * nodes[d] + ijk[d])
}

impl<const D: usize> Level<D> {
    /// Position of node k (the tests' check of the prolongations): its Greville abscissa on the level's knots, from the
    /// grid's min corner.
    #[cfg(test)]
    pub fn position(&self, grid: &Grid<D>, k: usize) -> [f64; D] {
        let nodes: [usize; D] = std::array::from_fn(|d| self.cells[d] + grid.degree);
        let ijk = node_ijk(self.nodes[k], nodes);
        std::array::from_fn(|d| {
            grid.min[d] + self.h[d] * greville(ijk[d], grid.degree, self.cells[d])
        })
    }
}

/// The hierarchy over the step's active nodes (`active`: grid indices, in the
/// order of `dofs`), coarsened until a level has at most `coarse_unknowns`.
pub fn hierarchy<const D: usize>(
    grid: &Grid<D>,
    active: &[u32],
    dofs: &Dofs,
    coarse_unknowns: usize,
) -> Hierarchy<D> {
    let components = dofs.per_node();
    let index: Vec<u32> = (0..active.len())
        .flat_map(|a| {
            let tied = dofs.ties.get(a).is_some_and(|t| t.is_some());
            (0..components).map(move |c| match dofs.of(a, c) {
                Some(i) => i as u32,
                None if tied => ABSENT,
                None => PRESCRIBED,
            })
        })
        .collect();
    let mut levels = vec![Level {
        cells: grid.cells,
        h: std::array::from_fn(|d| grid.h[d]),
        nodes: active.iter().map(|&g| g as usize).collect(),
        components,
        index,
        unknowns: dofs.free,
    }];
    let mut transfers = Vec::new();
    while levels.last().unwrap().unknowns > coarse_unknowns && levels.len() < MAX_LEVELS {
        let fine = levels.last().unwrap();
        let Some((transfer, coarse)) = coarsen(fine, grid.degree) else {
            break;
        };
        if coarse.unknowns as f64 > LEAST_REDUCTION * fine.unknowns as f64 || coarse.unknowns == 0 {
            break;
        }
        transfers.push(transfer);
        levels.push(coarse);
    }
    Hierarchy { levels, transfers }
}

/// One direction's prolongation from `coarse` to `fine` cells, degree p: per
/// fine basis function, its (coarse function, coefficient) pairs.
fn axis_prolongation(fine: usize, coarse: usize, p: usize) -> Vec<Vec<(usize, f64)>> {
    let (nf, nc) = (fine + p, coarse + p);
    // Fine Greville abscissae in fine cell units; coarse cells are two fine ones
    // (a direction of one cell is not coarsened).
    let ratio = if fine == coarse { 1.0 } else { 2.0 };
    let g: Vec<f64> = (0..nf).map(|i| greville(i, p, fine)).collect();
    let mut b = DMatrix::<f64>::zeros(nf, nc);
    for (i, &x) in g.iter().enumerate() {
        for (j, v) in axis_values(x / ratio, p, coarse) {
            b[(i, j)] = v;
        }
    }
    if p > 1 {
        let mut c = DMatrix::<f64>::zeros(nf, nf);
        for (i, &x) in g.iter().enumerate() {
            for (j, v) in axis_values(x, p, fine) {
                c[(i, j)] = v;
            }
        }
        b = c
            .lu()
            .solve(&b)
            .expect("collocation at the Greville abscissae is invertible");
    }
    (0..nf)
        .map(|i| {
            (0..nc)
                .filter_map(|j| {
                    let v = b[(i, j)];
                    (v.abs() > 1e-12).then_some((j, v))
                })
                .collect()
        })
        .collect()
}

/// The next coarser level of `fine` and the transfer to it, or None when no
/// direction can be coarsened.
fn coarsen<const D: usize>(fine: &Level<D>, p: usize) -> Option<(Transfer, Level<D>)> {
    let cells: [usize; D] = std::array::from_fn(|d| fine.cells[d].div_ceil(2));
    if cells == fine.cells {
        return None;
    }
    let fine_nodes: [usize; D] = std::array::from_fn(|d| fine.cells[d] + p);
    let coarse_nodes: [usize; D] = std::array::from_fn(|d| cells[d] + p);
    let axes: [Vec<Vec<(usize, f64)>>; D] =
        std::array::from_fn(|d| axis_prolongation(fine.cells[d], cells[d], p));
    let total: usize = coarse_nodes.iter().product();
    // Per coarse node j and component c, at j·n + c.
    let n = fine.components;
    let (mut referenced, mut prescribed) = (vec![false; total * n], vec![false; total * n]);
    for (k, &node) in fine.nodes.iter().enumerate() {
        let ijk = node_ijk(node, fine_nodes);
        if let Some(j) = coincident(&axes, ijk, coarse_nodes) {
            for c in 0..n {
                if fine.state(k, c) == PRESCRIBED {
                    prescribed[j * n + c] = true;
                }
            }
        }
        if (0..n).any(|c| fine.unknown(k, c).is_some()) {
            for_each_parent(&axes, ijk, coarse_nodes, |j, _| {
                for c in 0..n {
                    referenced[j * n + c] |= fine.unknown(k, c).is_some();
                }
            });
        }
    }
    let mut coarse = Level {
        cells,
        h: std::array::from_fn(|d| {
            if cells[d] == fine.cells[d] {
                fine.h[d]
            } else {
                2.0 * fine.h[d]
            }
        }),
        nodes: Vec::new(),
        components: n,
        index: Vec::new(),
        unknowns: 0,
    };
    let mut position = vec![u32::MAX; total];
    for j in 0..total {
        let (referenced, prescribed) = (&referenced[j * n..][..n], &prescribed[j * n..][..n]);
        if !(0..n).any(|c| referenced[c] || prescribed[c]) {
            continue;
        }
        position[j] = coarse.nodes.len() as u32;
        coarse.nodes.push(j);
        for c in 0..n {
            let state = if prescribed[c] {
                PRESCRIBED
            } else if referenced[c] {
                coarse.unknowns += 1;
                coarse.unknowns as u32 - 1
            } else {
                ABSENT
            };
            coarse.index.push(state);
        }
    }
    // P, row by row in the order of the fine unknowns (node by node).
    let mut prolongation = Csr {
        rows: fine.unknowns,
        cols: coarse.unknowns,
        row_ptr: vec![0],
        ..Default::default()
    };
    let mut row: Vec<(u32, f64)> = Vec::new();
    let mut next_row = 0;
    for (k, &node) in fine.nodes.iter().enumerate() {
        let ijk = node_ijk(node, fine_nodes);
        for c in 0..n {
            let Some(u) = fine.unknown(k, c) else {
                continue;
            };
            debug_assert_eq!(u, next_row, "unknowns numbered node by node");
            next_row += 1;
            row.clear();
            for_each_parent(&axes, ijk, coarse_nodes, |j, w| {
                let i = coarse.state(position[j] as usize, c);
                if i < PRESCRIBED {
                    row.push((i, w));
                }
            });
            row.sort_by_key(|&(i, _)| i);
            for &(i, w) in &row {
                prolongation.col.push(i);
                prolongation.val.push(w);
            }
            prolongation.row_ptr.push(prolongation.col.len());
        }
    }
    let transfer = Transfer {
        prolongation,
        fine_blocks: fine.blocks(),
    };
    Some((transfer, coarse))
}

/// Calls `f(coarse node, weight)` for every coarse node whose basis function
/// the fine node `ijk` takes a nonzero coefficient from.
fn for_each_parent<const D: usize>(
    axes: &[Vec<Vec<(usize, f64)>>; D],
    ijk: [usize; D],
    coarse_nodes: [usize; D],
    mut f: impl FnMut(usize, f64),
) {
    let rows: [&[(usize, f64)]; D] = std::array::from_fn(|d| axes[d][ijk[d]].as_slice());
    let count: usize = rows.iter().map(|r| r.len()).product();
    for mut c in 0..count {
        let mut w = 1.0;
        let jk: [usize; D] = std::array::from_fn(|d| {
            let (j, v) = rows[d][c % rows[d].len()];
            c /= rows[d].len();
            w *= v;
            j
        });
        f(flat(jk, coarse_nodes), w);
    }
}

/// The coarse node that fine node `ijk` coincides with (its row of P is a unit
/// row), if any.
fn coincident<const D: usize>(
    axes: &[Vec<Vec<(usize, f64)>>; D],
    ijk: [usize; D],
    coarse_nodes: [usize; D],
) -> Option<usize> {
    let mut jk = [0; D];
    for d in 0..D {
        match axes[d][ijk[d]].as_slice() {
            [(j, w)] if (w - 1.0).abs() < 1e-12 => jk[d] = *j,
            _ => return None,
        }
    }
    Some(flat(jk, coarse_nodes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Vector;
    use crate::solver::implicit::assembly::Tie;
    use crate::solver::linear::cg::cg;
    use crate::solver::linear::iterative::Settings;
    use crate::solver::linear::multigrid::Multigrid;

    /// A grid of `cells` on [0, 1]^D (cell size 1/cells[0] along x, h = 1 cell
    /// unit elsewhere scaled alike) with the given degree.
    fn grid<const D: usize>(cells: [usize; D], degree: usize) -> Grid<D> {
        let max = Vector::<D>::from_fn(|d, _| cells[d] as f64 * 0.5);
        Grid::new(Vector::<D>::zeros(), max, cells, degree)
    }

    /// The active nodes of a body covering the cells with index < `body[d]`
    /// (and the nodes of those cells), N components per node, the
    /// displacements' (components < D) prescribed on the base y = 0 if
    /// `fixed_base` (a further scalar component is free there), and a few
    /// nodes on the body's top tied (to arbitrary masters: only their having no
    /// unknowns matters here).
    fn body<const D: usize, const N: usize>(
        g: &Grid<D>,
        body: [usize; D],
        fixed_base: bool,
    ) -> (Vec<u32>, Dofs) {
        let p = g.degree;
        let active: Vec<u32> = (0..g.node_count())
            .filter(|&k| {
                let ijk = g.node_ijk(k);
                (0..D).all(|d| ijk[d] < body[d] + p)
            })
            .map(|k| k as u32)
            .collect();
        let ties: Vec<Option<Tie>> = active
            .iter()
            .map(|&k| {
                let ijk = g.node_ijk(k as usize);
                let top = ijk[D - 1] == body[D - 1] + p - 1;
                (top && ijk[0] % 3 == 1).then_some(Tie {
                    master: [0, 1],
                    coef: [2.0, -1.0],
                })
            })
            .collect();
        let fixed = active.iter().map(|&k| {
            let ijk = g.node_ijk(k as usize);
            std::array::from_fn(|c| fixed_base && ijk[1] == 0 && c < D)
        });
        let dofs = Dofs::with_ties::<N>(fixed, ties);
        (active, dofs)
    }

    /// A linear field, component d (zero on y = 0 when `vanish`).
    fn field<const D: usize>(x: [f64; D], d: usize, vanish: bool) -> f64 {
        let slope: f64 = (0..D).map(|e| (0.3 + 0.1 * (d + e) as f64) * x[e]).sum();
        if vanish {
            (1.0 + d as f64) * x[1] * 0.7
        } else {
            1.5 - 0.5 * d as f64 + slope
        }
    }

    /// The linear field sampled at the unknowns of a level (its coefficients:
    /// Σ N_I X_I = x), the displacements vanishing on y = 0 if `vanish`.
    fn sample<const D: usize>(g: &Grid<D>, level: &Level<D>, vanish: bool) -> Vec<f64> {
        let mut v = vec![f64::NAN; level.unknowns];
        for k in 0..level.nodes.len() {
            let x = level.position(g, k);
            for c in 0..level.components {
                if let Some(u) = level.unknown(k, c) {
                    v[u] = field(x, c, vanish && c < D);
                }
            }
        }
        v
    }

    fn check_linear_fields<const D: usize, const N: usize>(
        cells: [usize; D],
        body_cells: [usize; D],
    ) {
        for degree in 1..=3 {
            for fixed_base in [false, true] {
                let g = grid(cells, degree);
                let (active, dofs) = body::<D, N>(&g, body_cells, fixed_base);
                let h = hierarchy(&g, &active, &dofs, 8);
                assert!(h.levels.len() >= 3, "{} levels", h.levels.len());
                for (l, t) in h.transfers.iter().enumerate() {
                    let coarse = sample(&g, &h.levels[l + 1], fixed_base);
                    let fine = sample(&g, &h.levels[l], fixed_base);
                    let mut prolonged = vec![0.0; fine.len()];
                    t.prolongation.apply(&coarse, &mut prolonged);
                    let worst = fine
                        .iter()
                        .zip(&prolonged)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    assert!(
                        worst < 1e-12,
                        "{D}D, {N} components, degree {degree}, fixed base {fixed_base}, \
                         level {l} → {}: largest error {worst:.1e}",
                        l + 1
                    );
                }
            }
        }
    }

    /// P reproduces linear fields exactly on every level, for the hats (linear,
    /// GIMP, CPDI grids) and the quadratic and cubic B-splines, over a body that
    /// covers part of the grid (odd and even cell counts), with tied nodes on
    /// its top and with a prescribed base (fields vanishing there); with D
    /// components per node, and with D + 1 (the further component free on the
    /// base: it keeps the coarse unknowns there that the displacements lose).
    #[test]
    fn prolongation_reproduces_linear_fields_on_every_level() {
        check_linear_fields::<2, 2>([21, 14], [13, 9]);
        check_linear_fields::<2, 3>([21, 14], [13, 9]);
        check_linear_fields::<3, 3>([9, 8, 7], [7, 5, 6]);
        check_linear_fields::<3, 4>([9, 8, 7], [7, 5, 6]);
    }

    /// The vector Laplacian of bilinear elements on `n`×`n` cells, prescribed on
    /// y = 0, conductivity `c_top` above y = n/2 and 1 below: its matrix over the
    /// unknowns of `dofs` (node by node) as full CSR, built as dense triplets.
    fn laplacian(g: &Grid<2>, active: &[u32], dofs: &Dofs, c_top: f64) -> Csr {
        let n = g.cells[0];
        // Element matrix of the unit square (bilinear): 2/3 diagonal, −1/6 along
        // edges, −1/3 across.
        let ke = |a: usize, b: usize| -> f64 {
            if a == b {
                2.0 / 3.0
            } else if a ^ b == 3 {
                -1.0 / 3.0
            } else {
                -1.0 / 6.0
            }
        };
        let local: std::collections::HashMap<u32, usize> =
            active.iter().enumerate().map(|(a, &k)| (k, a)).collect();
        let mut rows: Vec<std::collections::BTreeMap<u32, f64>> =
            vec![Default::default(); dofs.free];
        for cj in 0..n {
            for ci in 0..n {
                let c = if cj >= n / 2 { c_top } else { 1.0 };
                let corners = [(ci, cj), (ci + 1, cj), (ci, cj + 1), (ci + 1, cj + 1)];
                for (a, &(ia, ja)) in corners.iter().enumerate() {
                    for (b, &(ib, jb)) in corners.iter().enumerate() {
                        let na = local[&(g.node_index([ia, ja]) as u32)];
                        let nb = local[&(g.node_index([ib, jb]) as u32)];
                        for d in 0..2 {
                            if let (Some(r), Some(s)) = (dofs.of(na, d), dofs.of(nb, d)) {
                                *rows[r].entry(s as u32).or_default() += c * ke(a, b);
                            }
                        }
                    }
                }
            }
        }
        let mut m = Csr {
            rows: dofs.free,
            cols: dofs.free,
            row_ptr: vec![0],
            ..Default::default()
        };
        for row in rows {
            for (c, v) in row {
                m.col.push(c);
                m.val.push(v);
            }
            m.row_ptr.push(m.col.len());
        }
        m
    }

    /// PCG iterations to 1e-8 with the multigrid V-cycle on the vector Laplacian
    /// of `n`×`n` bilinear cells.
    fn pcg_iterations(n: usize, c_top: f64) -> usize {
        let g = grid([n, n], 1);
        let (active, _) = body::<2, 2>(&g, [n, n], true);
        let dofs = Dofs::with_ties::<2>(
            active.iter().map(|&k| [g.node_ijk(k as usize)[1] == 0; 2]),
            Vec::new(),
        );
        let a = laplacian(&g, &active, &dofs, c_top);
        let h = hierarchy(&g, &active, &dofs, 200);
        let mut mg = Multigrid::new(h.transfers);
        mg.refresh(a.clone(), true).unwrap();
        let b: Vec<f64> = (0..dofs.free).map(|i| (0.37 * i as f64).sin()).collect();
        let mut x = vec![0.0; dofs.free];
        let settings = Settings {
            tolerance: 1e-8,
            max_iterations: 200,
            restart: 0,
        };
        let out = cg(
            |v: &[f64], y: &mut [f64]| -> Result<(), ()> {
                a.apply(v, y);
                Ok(())
            },
            &mg,
            &b,
            &mut x,
            &settings,
        )
        .unwrap();
        assert!(out.converged, "{out:?}");
        out.iterations
    }

    /// Multigrid-preconditioned CG on the Laplacian: the iteration count does not
    /// grow as h halves (16² to 128² cells, 544 to 33,024 unknowns: within ±30 %
    /// of the first and at most 20), also with a 10³ jump of the coefficient
    /// (at most 30).
    #[test]
    fn pcg_iterations_do_not_grow_as_h_halves() {
        for (c_top, limit) in [(1.0, 20), (1e3, 30)] {
            let counts: Vec<usize> = [16, 32, 64, 128]
                .iter()
                .map(|&n| pcg_iterations(n, c_top))
                .collect();
            println!("contrast {c_top}: PCG iterations {counts:?}");
            let first = counts[0] as f64;
            for &c in &counts {
                assert!(c <= limit, "{counts:?}");
                assert!((c as f64 - first).abs() <= 0.3 * first + 1.0, "{counts:?}");
            }
        }
    }
}
