//! Weakly supported nodes of the implicit system.
//!
//! A particle that has just entered a cell touches the far nodes of its new
//! stencil with weights ~ξ² and gradients ~ξ (ξ its penetration in cells). Such a
//! node is seen by few quadrature points with tiny weights: its stiffness rows are
//! nearly (often exactly, up to round-off) zero-energy modes, and a quasi-static
//! tangent has no mass term to lift them. The remedy here follows the extended
//! B-splines of the implicit MPM literature: a node whose particle support
//! Σ_p V_p S_Ip is below a fraction of a cell volume is no unknown of its own; its
//! displacement is linearly extrapolated from two well-supported nodes on a grid
//! line through it, u_a = c₀ u_J + c₁ u_K. Every particle's shape functions
//! stay a partition of unity and keep reproducing linear fields exactly, and the
//! tangent stays the exact derivative of the (constrained) residual.
//!
//! Cubic B-splines also get the natural end condition u'' = 0 (along the face
//! normal) at every face with a prescribed velocity: the space of the odd mirror
//! extension of the basis across the face (ghost control points u_−k = 2 u_w − u_k,
//! the symmetric extension at a symmetry or roller plane). On the clamped knot
//! vector 0,0,0,0,1,2,… (cell units) u''(0) = 6 c₀ − 9 c₁ + 3 c₂, so the third
//! control point of each grid line follows the first two, c₂ = 3 c₁ − 2 c₀ (Piegl
//! & Tiller, The NURBS Book, eq. 3.9 for the end derivatives). Without it the
//! particle quadrature fails the constant-stress patch test at the face (the
//! clamped functions' second derivatives do not vanish there) and the stress of
//! the first particles is off by O(1), however fine the grid (docs/accuracy.md).

use super::assembly::Tie;
use crate::dim::Vector;
use crate::model::conditions::FaceCondition;
use crate::model::grid::Grid;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::scene::Face;

/// The field (body group, `physics::contact::field_split`) of every active node, with
/// contact between deformable bodies: a grid node they share holds one node
/// per field, and a node's neighbours for a tie are those of its own field (a
/// tie across fields would glue the bodies together).
#[derive(Clone, Debug)]
pub struct NodeFields {
    of: Vec<u32>,
    /// (grid node, field, active node), ascending.
    by_grid: Vec<(u32, u32, u32)>,
}

impl NodeFields {
    /// Field of active node a.
    pub fn field(&self, a: usize) -> u32 {
        self.of[a]
    }

    /// The active node of `field` at grid node g, if any.
    pub fn active(&self, g: usize, field: u32) -> Option<usize> {
        let key = (g as u32, field);
        let i = self
            .by_grid
            .binary_search_by_key(&key, |&(g, k, _)| (g, k))
            .ok()?;
        Some(self.by_grid[i].2 as usize)
    }

    /// From the field of every active node of `map`.
    pub fn new(map: &NodeMap, of: Vec<u32>) -> Self {
        let mut by_grid: Vec<(u32, u32, u32)> = (0..map.len())
            .map(|a| (map.grid_node(a) as u32, of[a], a as u32))
            .collect();
        by_grid.sort_unstable();
        NodeFields { of, by_grid }
    }
}

/// The active node at grid node `target` that can stand beside active node
/// `from`: the grid node's own, or with `fields` the one of `from`'s field.
fn active_at(
    map: &NodeMap,
    fields: Option<&NodeFields>,
    from: usize,
    target: usize,
) -> Option<usize> {
    match fields {
        None => match map.local[target] {
            NodeMap::NONE => None,
            a => Some(a as usize),
        },
        Some(f) => {
            let key = (target as u32, f.of[from]);
            let i = f
                .by_grid
                .binary_search_by_key(&key, |&(g, k, _)| (g, k))
                .ok()?;
            Some(f.by_grid[i].2 as usize)
        }
    }
}

/// Σ_p V_p S_Ip / (cell volume) at every active node.
pub fn nodal_support<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    cell_volume: f64,
) -> Vec<f64> {
    map.gather(st.stride, 0.0, |q, e| {
        volume[q] * st.weight(e) / cell_volume
    })
}

/// Ties for the free active nodes whose support is below `threshold` (cells).
/// Masters: the pair J = a + s, K = a + 2s (s a grid direction, axes first, then
/// diagonals) with the largest smaller support, both at or above the threshold.
/// A weak node with no such pair, or with a prescribed component, stays an
/// unknown. `fixed[a]`: which of the N components of node a are prescribed
/// (the unknowns' components, `Dofs::per_node`; a tie binds them all).
/// Returns no ties at all when none are needed.
pub fn ties<const D: usize, const N: usize>(
    grid: &Grid<D>,
    map: &NodeMap,
    fields: Option<&NodeFields>,
    support: &[f64],
    fixed: &[[bool; N]],
    threshold: f64,
) -> Vec<Option<Tie>> {
    let weak = |a: usize| support[a] < threshold;
    let free = |a: usize| !fixed[a].iter().any(|&f| f);
    // A split node (one body's node where two bodies meet) on a face with a
    // prescribed component is tied too, to masters on that face with the same
    // prescribed components: the other body no longer shares its stiffness,
    // and its free components would be nearly singular.
    let may_tie = |a: usize| free(a) || map.is_split(a);
    if threshold <= 0.0 || !(0..map.len()).any(|a| weak(a) && may_tie(a)) {
        return Vec::new();
    }
    let directions = directions::<D>();
    let position = |b: usize| grid.node_position(grid.node_ijk(map.grid_node(b)));
    (0..map.len())
        .map(|a| {
            if !weak(a) || !may_tie(a) {
                return None;
            }
            let same_face = |b: usize| fixed[b] == fixed[a];
            let ijk = grid.node_ijk(map.grid_node(a));
            let mut best: Option<(usize, f64, usize, usize)> = None; // (|s|², score, J, K)
            for s in &directions {
                let order = s.iter().map(|c| (c * c) as usize).sum::<usize>();
                if best.is_some_and(|b| b.0 < order) {
                    break; // a shorter direction already works
                }
                let (Some(j), Some(k)) = (
                    neighbour(grid, map, fields, a, ijk, s, 1),
                    neighbour(grid, map, fields, a, ijk, s, 2),
                ) else {
                    continue;
                };
                let prescribed_alike = same_face(j) && same_face(k);
                if !(free(a) || prescribed_alike) {
                    continue;
                }
                let score = support[j].min(support[k]);
                if weak(j) || weak(k) || best.is_some_and(|b| b.1 >= score) {
                    continue;
                }
                // B-spline control points (Greville abscissae) are not evenly
                // spaced next to the grid boundary: a diagonal may bend.
                if !collinear(&position(a), &position(j), &position(k), grid.h_min()) {
                    continue;
                }
                best = Some((order, score, j, k));
            }
            let (_, _, j, k) = best?;
            Some(extrapolation(
                &position(a),
                j,
                &position(j),
                k,
                &position(k),
            ))
        })
        .collect()
}

/// The natural end ties of a cubic B-spline grid (module docs): node a in the
/// third layer from a face whose first-layer node on the same grid line has a
/// prescribed component follows that line's first two nodes, u_a = 3 u₁ − 2 u₀.
/// Only along axes of at least 3 cells (the lines' ends are then distinct), and
/// not at nodes in the third layer of two axes (a corner would need four masters).
pub fn natural_end_ties<const D: usize>(
    grid: &Grid<D>,
    faces: &[FaceCondition<D>],
    map: &NodeMap,
    fields: Option<&NodeFields>,
) -> Vec<(usize, Tie)> {
    if grid.degree != 3 {
        return Vec::new();
    }
    let mut out = Vec::new();
    for a in 0..map.len() {
        let ijk = grid.node_ijk(map.grid_node(a));
        let ends: Vec<Face> = (0..D)
            .filter(|&d| grid.cells[d] >= 3)
            .flat_map(|axis| [false, true].map(|upper| Face { axis, upper }))
            .filter(|&face| layer(grid, ijk, face) == 2 && prescribed(grid, faces, ijk, face))
            .collect();
        let [face] = ends[..] else { continue };
        let line = |k: usize| {
            let mut n = ijk;
            n[face.axis] = if face.upper {
                grid.nodes[face.axis] - 1 - k
            } else {
                k
            };
            active_at(map, fields, a, grid.node_index(n))
        };
        if let (Some(first), Some(second)) = (line(0), line(1)) {
            let tie = Tie {
                master: [second, first],
                coef: [3.0, -2.0],
            };
            out.push((a, tie));
        }
    }
    out
}

/// Layer of node ijk counted from `face` (0 on the face).
fn layer<const D: usize>(grid: &Grid<D>, ijk: [usize; D], face: Face) -> usize {
    let i = ijk[face.axis];
    if face.upper {
        grid.nodes[face.axis] - 1 - i
    } else {
        i
    }
}

/// Does a face condition prescribe a component at the node of `face` on the grid
/// line of ijk along the face normal?
fn prescribed<const D: usize>(
    grid: &Grid<D>,
    faces: &[FaceCondition<D>],
    ijk: [usize; D],
    face: Face,
) -> bool {
    let mut on_face = ijk;
    on_face[face.axis] = if face.upper {
        grid.nodes[face.axis] - 1
    } else {
        0
    };
    faces.iter().any(|fc| {
        fc.face == face && fc.constraint.fixed.iter().any(|&f| f) && fc.acts_on(grid, on_face)
    })
}

/// Weak-support ties and natural end ties together: a natural tie is kept unless
/// its node or one of its masters is weakly tied or its node is a weak master
/// (masters stay untied).
pub fn merge(weak: Vec<Option<Tie>>, natural: Vec<(usize, Tie)>, nodes: usize) -> Vec<Option<Tie>> {
    if natural.is_empty() {
        return weak;
    }
    let mut all = if weak.is_empty() {
        vec![None; nodes]
    } else {
        weak
    };
    let mut master = vec![false; nodes];
    for t in all.iter().flatten() {
        t.master.iter().for_each(|&m| master[m] = true);
    }
    for (a, tie) in natural {
        let free = |n: usize| all[n].is_none();
        if free(a) && !master[a] && tie.master.iter().all(|&m| free(m)) {
            tie.master.iter().for_each(|&m| master[m] = true);
            all[a] = Some(tie);
        }
    }
    all
}

/// Linear extrapolation along the line through x_J and x_K:
/// u(x) = t u_J + (1 − t) u_K with t = (x − x_K)·(x_J − x_K)/|x_J − x_K|².
fn extrapolation<const D: usize>(
    x: &Vector<D>,
    j: usize,
    xj: &Vector<D>,
    k: usize,
    xk: &Vector<D>,
) -> Tie {
    let line = xj - xk;
    let t = (x - xk).dot(&line) / line.norm_squared();
    Tie {
        master: [j, k],
        coef: [t, 1.0 - t],
    }
}

/// Is x on the line through x_J and x_K (to round-off, relative to h)?
fn collinear<const D: usize>(x: &Vector<D>, xj: &Vector<D>, xk: &Vector<D>, h: f64) -> bool {
    let tie = extrapolation(x, 0, xj, 1, xk);
    (xj * tie.coef[0] + xk * tie.coef[1] - x).norm() <= 1e-12 * h
}

/// Grid directions {−1, 0, 1}^D without 0, ordered by length (axes first).
fn directions<const D: usize>() -> Vec<[i64; D]> {
    let mut out: Vec<[i64; D]> = (0..3usize.pow(D as u32))
        .map(|mut code| {
            std::array::from_fn(|_| {
                let c = (code % 3) as i64 - 1;
                code /= 3;
                c
            })
        })
        .filter(|s: &[i64; D]| s.iter().any(|&c| c != 0))
        .collect();
    out.sort_by_key(|s| s.iter().map(|c| c * c).sum::<i64>());
    out
}

/// Active index of node ijk + m·s, if it is on the grid and active.
fn neighbour<const D: usize>(
    grid: &Grid<D>,
    map: &NodeMap,
    fields: Option<&NodeFields>,
    from: usize,
    ijk: [usize; D],
    s: &[i64; D],
    m: i64,
) -> Option<usize> {
    let mut target = [0usize; D];
    for d in 0..D {
        let i = ijk[d] as i64 + m * s[d];
        if i < 0 || i >= grid.nodes[d] as i64 {
            return None;
        }
        target[d] = i as usize;
    }
    active_at(map, fields, from, grid.node_index(target))
}
