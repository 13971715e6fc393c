//! Fill-reducing orderings of a tangent whose unknowns come in nodes.
//!
//! The tangent of a grid method couples whole nodes: all the unknowns of node a
//! couple to all those of node b, so the fill of a Cholesky factor is decided by
//! the node graph, and ordering that graph (D times smaller, D² times fewer
//! edges) gives the same fill as ordering the scalar matrix at a fraction of the
//! cost. The unknowns of a node then follow each other. Two orderings of the
//! node graph:
//! - [`node_amd`]: approximate minimum degree (faer's AMD on the node graph);
//! - [`nested_dissection`]: geometric nested dissection of the grid nodes
//!   (George 1973): split the nodes at a median plane across their longest
//!   extent, by a separator as thick as the longest coupling across it, order
//!   both halves first (recursively) and the separator last; halves of at most
//!   [`LEAF_NODES`] nodes are ordered by minimum degree. On a structured grid
//!   this is what a graph partitioner (METIS) finds, without one: no crate
//!   serves a geometric dissection, and METIS would add a C library.
//!
//! Both return the permutation of the unknowns as faer takes it (`perm[new] =
//! old`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

/// Halves of at most this many nodes are not dissected further.
pub const LEAF_NODES: usize = 256;

/// A graph of nodes in compressed rows: the neighbours of node a (itself may be
/// among them) are `adjacency[start[a]..start[a + 1]]`, ascending; node a owns
/// the unknowns `first[a]..first[a + 1]`.
#[derive(Clone, Copy, Debug)]
pub struct NodeGraph<'a> {
    pub start: &'a [usize],
    pub adjacency: &'a [u32],
    pub first: &'a [usize],
}

impl NodeGraph<'_> {
    fn nodes(&self) -> usize {
        self.first.len() - 1
    }

    fn neighbours(&self, a: usize) -> &[u32] {
        &self.adjacency[self.start[a]..self.start[a + 1]]
    }

    /// The permutation of the unknowns that numbers the nodes in `order`
    /// (nodes without unknowns contribute none).
    fn expand(&self, order: &[u32]) -> Vec<usize> {
        let mut perm = Vec::with_capacity(self.first[self.nodes()]);
        for &a in order {
            perm.extend(self.first[a as usize]..self.first[a as usize + 1]);
        }
        perm
    }

    /// The subgraph of the nodes that own unknowns (renumbered in order) and
    /// their original numbers.
    fn with_unknowns(&self) -> (Vec<usize>, Vec<u32>, Vec<u32>) {
        let n = self.nodes();
        let mut new_of = vec![u32::MAX; n];
        let mut old: Vec<u32> = Vec::new();
        for a in 0..n {
            if self.first[a + 1] > self.first[a] {
                new_of[a] = old.len() as u32;
                old.push(a as u32);
            }
        }
        let mut start = vec![0];
        let mut adjacency = Vec::new();
        for &a in &old {
            adjacency.extend(
                self.neighbours(a as usize)
                    .iter()
                    .map(|&b| new_of[b as usize])
                    .filter(|&b| b != u32::MAX),
            );
            start.push(adjacency.len());
        }
        (start, adjacency, old)
    }
}

/// Minimum-degree order of the nodes `start`/`adjacency` (a symmetric graph,
/// rows ascending), as node numbers.
fn amd_order(start: &[usize], adjacency: &[u32]) -> Vec<u32> {
    let n = start.len() - 1;
    if n == 0 {
        return Vec::new();
    }
    let col_ptr: Vec<u32> = start.iter().map(|&s| s as u32).collect();
    let graph = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, adjacency);
    let (mut perm, mut inv) = (vec![0u32; n], vec![0u32; n]);
    let mut mem = MemBuffer::new(amd::order_scratch::<u32>(n, adjacency.len()));
    match amd::order(
        &mut perm,
        &mut inv,
        graph,
        amd::Control::default(),
        MemStack::new(&mut mem),
    ) {
        Ok(_) => perm,
        // Index overflow only (more than 2³¹ entries): keep the natural order.
        Err(_) => (0..n as u32).collect(),
    }
}

/// METIS' nested dissection (`METIS_NodeND`, default options) on the node
/// graph, each node weighted by its unknowns.
pub fn node_metis(g: &NodeGraph) -> Vec<usize> {
    let (start, adjacency, old) = g.with_unknowns();
    let n = old.len();
    // METIS takes the graph without self-loops, 32-bit indices.
    let mut xadj: Vec<i32> = Vec::with_capacity(n + 1);
    let mut adjncy: Vec<i32> = Vec::with_capacity(adjacency.len());
    xadj.push(0);
    for a in 0..n {
        adjncy.extend(
            adjacency[start[a]..start[a + 1]]
                .iter()
                .filter(|&&b| b as usize != a)
                .map(|&b| b as i32),
        );
        xadj.push(adjncy.len() as i32);
    }
    let mut weight: Vec<i32> = old
        .iter()
        .map(|&a| (g.first[a as usize + 1] - g.first[a as usize]) as i32)
        .collect();
    let (mut perm, mut iperm) = (vec![0i32; n], vec![0i32; n]);
    let mut nvtxs = n as i32;
    let fits = n > 0 && i32::try_from(adjncy.len()).is_ok();
    // SAFETY: the arrays are a valid METIS graph of nvtxs vertices (xadj has
    // nvtxs + 1 offsets into adjncy, every index < nvtxs), vwgt and the outputs
    // have nvtxs entries, and a null options array asks for the defaults.
    let status = if fits {
        unsafe {
            metis_sys::METIS_NodeND(
                &mut nvtxs,
                xadj.as_mut_ptr(),
                adjncy.as_mut_ptr(),
                weight.as_mut_ptr(),
                std::ptr::null_mut(),
                perm.as_mut_ptr(),
                iperm.as_mut_ptr(),
            )
        }
    } else {
        0
    };
    let order: Vec<u32> = if status == metis_sys::rstatus_et_METIS_OK {
        perm.iter().map(|&a| old[a as usize]).collect()
    } else {
        // METIS failed (out of memory) or nothing to order: minimum degree.
        amd_order(&start, &adjacency)
            .into_iter()
            .map(|a| old[a as usize])
            .collect()
    };
    g.expand(&order)
}

/// Approximate minimum degree on the node graph.
pub fn node_amd(g: &NodeGraph) -> Vec<usize> {
    let (start, adjacency, old) = g.with_unknowns();
    let order: Vec<u32> = amd_order(&start, &adjacency)
        .into_iter()
        .map(|a| old[a as usize])
        .collect();
    g.expand(&order)
}

/// Geometric nested dissection of the node graph, `ijk(a)` the grid indices of
/// node a.
pub fn nested_dissection<const D: usize>(
    g: &NodeGraph,
    ijk: impl Fn(usize) -> [i64; D],
) -> Vec<usize> {
    let (start, adjacency, old) = g.with_unknowns();
    let coords: Vec<[i64; D]> = old.iter().map(|&a| ijk(a as usize)).collect();
    // The separator across axis d must be as thick as the longest coupling along d.
    let mut reach = [1i64; D];
    for a in 0..coords.len() {
        for &b in &adjacency[start[a]..start[a + 1]] {
            for d in 0..D {
                reach[d] = reach[d].max((coords[a][d] - coords[b as usize][d]).abs());
            }
        }
    }
    let mut nodes: Vec<u32> = (0..coords.len() as u32).collect();
    let mut order = Vec::with_capacity(nodes.len());
    dissect(&mut nodes, &coords, &reach, &start, &adjacency, &mut order);
    let order: Vec<u32> = order.into_iter().map(|a| old[a as usize]).collect();
    g.expand(&order)
}

/// Orders `nodes`: both sides of a separator, then the separator.
fn dissect<const D: usize>(
    nodes: &mut [u32],
    coords: &[[i64; D]],
    reach: &[i64; D],
    start: &[usize],
    adjacency: &[u32],
    order: &mut Vec<u32>,
) {
    if nodes.len() <= LEAF_NODES {
        order.extend(leaf_order(nodes, start, adjacency));
        return;
    }
    // The longest extent of the nodes, split at its median.
    let (mut lo, mut hi) = ([i64::MAX; D], [i64::MIN; D]);
    for &a in nodes.iter() {
        for d in 0..D {
            lo[d] = lo[d].min(coords[a as usize][d]);
            hi[d] = hi[d].max(coords[a as usize][d]);
        }
    }
    let axis = (0..D).max_by_key(|&d| (hi[d] - lo[d], D - d)).unwrap_or(0);
    if hi[axis] - lo[axis] < reach[axis] + 1 {
        // Too thin to split by a separator: order as one leaf.
        order.extend(leaf_order(nodes, start, adjacency));
        return;
    }
    nodes.sort_by_key(|&a| (coords[a as usize][axis], a));
    let median = coords[nodes[nodes.len() / 2] as usize][axis];
    let mid = median.clamp(lo[axis] + 1, hi[axis] - reach[axis]);
    // Left: x < mid; separator: mid ≤ x < mid + reach; right: the rest.
    let left = nodes.partition_point(|&a| coords[a as usize][axis] < mid);
    let right = nodes.partition_point(|&a| coords[a as usize][axis] < mid + reach[axis]);
    let (left_nodes, rest) = nodes.split_at_mut(left);
    let (separator, right_nodes) = rest.split_at_mut(right - left);
    dissect(left_nodes, coords, reach, start, adjacency, order);
    dissect(right_nodes, coords, reach, start, adjacency, order);
    order.extend_from_slice(separator);
}

/// Minimum-degree order of a few nodes (their induced subgraph).
fn leaf_order(nodes: &[u32], start: &[usize], adjacency: &[u32]) -> Vec<u32> {
    let mut sorted = nodes.to_vec();
    sorted.sort_unstable();
    let local = |b: u32| sorted.binary_search(&b).ok();
    let mut sub_start = vec![0];
    let mut sub_adj: Vec<u32> = Vec::new();
    for &a in &sorted {
        sub_adj.extend(
            adjacency[start[a as usize]..start[a as usize + 1]]
                .iter()
                .filter_map(|&b| local(b).map(|i| i as u32)),
        );
        sub_start.push(sub_adj.len());
    }
    amd_order(&sub_start, &sub_adj)
        .into_iter()
        .map(|i| sorted[i as usize])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D grid of nx × ny nodes, each coupled to the nodes within `reach`
    /// (uGIMP and quadratic B-splines: 2), two unknowns per node.
    fn grid(nx: i64, ny: i64, reach: i64) -> (Vec<usize>, Vec<u32>, Vec<usize>) {
        let id = |i: i64, j: i64| (j * nx + i) as u32;
        let (mut start, mut adjacency) = (vec![0], Vec::new());
        for j in 0..ny {
            for i in 0..nx {
                for jj in (j - reach).max(0)..=(j + reach).min(ny - 1) {
                    for ii in (i - reach).max(0)..=(i + reach).min(nx - 1) {
                        adjacency.push(id(ii, jj));
                    }
                }
                start.push(adjacency.len());
            }
        }
        let first = (0..=(nx * ny) as usize).map(|a| 2 * a).collect();
        (start, adjacency, first)
    }

    fn is_permutation(p: &[usize], n: usize) -> bool {
        let mut seen = vec![false; n];
        p.len() == n
            && p.iter()
                .all(|&i| i < n && !std::mem::replace(&mut seen[i], true))
    }

    /// Both orderings number every unknown once, and keep a node's unknowns
    /// together.
    #[test]
    fn orderings_are_permutations_of_whole_nodes() {
        let (start, adjacency, first) = grid(40, 30, 2);
        let g = NodeGraph {
            start: &start,
            adjacency: &adjacency,
            first: &first,
        };
        let nx = 40;
        for perm in [
            node_amd(&g),
            nested_dissection::<2>(&g, |a| [a as i64 % nx, a as i64 / nx]),
        ] {
            assert!(is_permutation(&perm, 2 * 40 * 30));
            for pair in perm.chunks(2) {
                assert_eq!(pair[0] / 2, pair[1] / 2);
                assert_eq!(pair[0] + 1, pair[1]);
            }
        }
    }

    /// Every separator separates: no node ordered before a separator couples
    /// to a node ordered after... is implied by the fill; here the weaker,
    /// checkable property: the last nodes of the order form a full-height line
    /// (the top separator) as thick as the reach.
    #[test]
    fn the_top_separator_cuts_the_longest_extent() {
        let (start, adjacency, first) = grid(64, 16, 2);
        let g = NodeGraph {
            start: &start,
            adjacency: &adjacency,
            first: &first,
        };
        let perm = nested_dissection::<2>(&g, |a| [a as i64 % 64, a as i64 / 64]);
        let last: Vec<usize> = perm[perm.len() - 2 * 2 * 16..]
            .iter()
            .step_by(2)
            .map(|&u| u / 2)
            .collect();
        let xs: std::collections::BTreeSet<usize> = last.iter().map(|a| a % 64).collect();
        assert_eq!(xs.len(), 2, "separator columns {xs:?}");
        assert_eq!(xs.iter().max().unwrap() - xs.iter().min().unwrap(), 1);
    }
}
