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
//! and P = P_x ⊗ P_y (⊗ P_z), component by component. Every level reproduces
//! any field the coarse space holds, in particular linear fields.
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

/// Coarsening stops once a level has at most this many unknowns (its operator
/// is factorized by the direct solver).
pub const COARSE_UNKNOWNS: usize = 3000;
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
    /// Per node and component: the unknown's number, `PRESCRIBED` or `ABSENT`.
    index: Vec<[u32; D]>,
    pub unknowns: usize,
}

impl<const D: usize> Level<D> {
    /// The unknown of component d of node k, if it is one.
    pub fn unknown(&self, k: usize, d: usize) -> Option<usize> {
        (self.index[k][d] < PRESCRIBED).then_some(self.index[k][d] as usize)
    }

    /// The unknowns of each node that has some.
    fn blocks(&self) -> Vec<Vec<usize>> {
        (0..self.nodes.len())
            .map(|k| {
                (0..D)
                    .filter_map(|d| self.unknown(k, d))
                    .collect::<Vec<_>>()
            })
            .filter(|b| !b.is_empty())
            .collect()
    }
}

/// The grid levels (finest first) and the transfers between them.
pub struct Hierarchy<const D: usize> {
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
    /// Position of node k: its Greville abscissa on the level's knots, from the
    /// grid's min corner.
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
    let index: Vec<[u32; D]> = (0..active.len())
        .map(|a| {
            let tied = dofs.ties.get(a).is_some_and(|t| t.is_some());
            std::array::from_fn(|d| match dofs.of(a, d, D) {
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
    let (mut referenced, mut prescribed) = (vec![[false; D]; total], vec![[false; D]; total]);
    for (k, &node) in fine.nodes.iter().enumerate() {
        let ijk = node_ijk(node, fine_nodes);
        if let Some(j) = coincident(&axes, ijk, coarse_nodes) {
            for d in 0..D {
                if fine.index[k][d] == PRESCRIBED {
                    prescribed[j][d] = true;
                }
            }
        }
        if (0..D).any(|d| fine.unknown(k, d).is_some()) {
            for_each_parent(&axes, ijk, coarse_nodes, |j, _| {
                for d in 0..D {
                    referenced[j][d] |= fine.unknown(k, d).is_some();
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
        index: Vec::new(),
        unknowns: 0,
    };
    let mut position = vec![u32::MAX; total];
    for j in 0..total {
        if !(0..D).any(|d| referenced[j][d] || prescribed[j][d]) {
            continue;
        }
        position[j] = coarse.nodes.len() as u32;
        coarse.nodes.push(j);
        let index = std::array::from_fn(|d| {
            if prescribed[j][d] {
                PRESCRIBED
            } else if referenced[j][d] {
                coarse.unknowns += 1;
                coarse.unknowns as u32 - 1
            } else {
                ABSENT
            }
        });
        coarse.index.push(index);
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
        for d in 0..D {
            let Some(u) = fine.unknown(k, d) else {
                continue;
            };
            debug_assert_eq!(u, next_row, "unknowns numbered node by node");
            next_row += 1;
            row.clear();
            for_each_parent(&axes, ijk, coarse_nodes, |j, w| {
                let c = coarse.index[position[j] as usize][d];
                if c < PRESCRIBED {
                    row.push((c, w));
                }
            });
            row.sort_by_key(|&(c, _)| c);
            for &(c, w) in &row {
                prolongation.col.push(c);
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
