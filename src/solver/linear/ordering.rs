//! Fill-reducing orderings of a tangent whose unknowns come in nodes.
//!
//! The tangent of a grid method couples whole nodes: all the unknowns of node a
//! couple to all those of node b, so the fill of a Cholesky factor is decided by
//! the node graph, and ordering that graph (n times smaller, n² times fewer
//! edges, n the unknowns per node: D, or more with further nodal fields) gives
//! the same fill as ordering the scalar matrix at a fraction of the cost. The unknowns of a node then follow each other. Two orderings of the
//! node graph:
//! - [`node_amd`]: approximate minimum degree (faer's AMD), the same fill as
//!   AMD on the scalar matrix in 3–5× less time;
//! - [`node_metis`]: nested dissection by METIS (`METIS_NodeND`, through the
//!   vendored `metis-sys`), each node weighted by its unknowns: a quarter less
//!   fill than AMD on 3D blocks, about the same in 2D.
//!
//! A geometric nested dissection of the grid nodes (median planes, separators
//! as thick as the longest coupling, minimum degree in the leaves) was measured
//! too and gave 6–10 % more fill than AMD (docs/performance.md). Both
//! orderings return the permutation of the unknowns as faer takes it
//! (`perm[new] = old`).

use crate::scene::DirectOrdering;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

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

    /// The neighbours of node a, ascending.
    pub fn neighbours(&self, a: usize) -> &[u32] {
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
        for (a, new) in new_of.iter_mut().enumerate() {
            if self.first[a + 1] > self.first[a] {
                *new = old.len() as u32;
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

/// The ordering `kind` of the node graph in D dimensions (`auto`:
/// `DirectOrdering::resolved`).
pub fn fill_reducing<const D: usize>(g: &NodeGraph, kind: DirectOrdering) -> Vec<usize> {
    match kind.resolved(D) {
        DirectOrdering::Metis => node_metis(g),
        _ => node_amd(g),
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

#[cfg(test)]
mod tests {
    use super::*;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
    };
    use faer::sparse::SymbolicSparseColMat;
    use faer::Side;

    /// A box of nodes (sides `n`), each coupled to the nodes within `reach`
    /// along every axis (uGIMP and quadratic B-splines: 2), `dofs` unknowns per
    /// node: start, adjacency, first.
    fn grid<const D: usize>(
        n: [i64; D],
        reach: i64,
        dofs: usize,
    ) -> (Vec<usize>, Vec<u32>, Vec<usize>) {
        let count: i64 = n.iter().product();
        let ijk = |mut a: i64| {
            let mut c = [0i64; D];
            for d in 0..D {
                c[d] = a % n[d];
                a /= n[d];
            }
            c
        };
        let (mut start, mut adjacency) = (vec![0], Vec::new());
        for a in 0..count {
            let ca = ijk(a);
            for b in 0..count {
                let cb = ijk(b);
                if (0..D).all(|d| (ca[d] - cb[d]).abs() <= reach) {
                    adjacency.push(b as u32);
                }
            }
            start.push(adjacency.len());
        }
        let first = (0..=count as usize).map(|a| dofs * a).collect();
        (start, adjacency, first)
    }

    /// The lower triangle of the scalar matrix of a node graph.
    fn scalar_lower(g: &NodeGraph) -> SymbolicSparseColMat<usize> {
        let n = g.first[g.nodes()];
        let (mut col_ptr, mut rows) = (vec![0], Vec::new());
        for b in 0..g.nodes() {
            for c in g.first[b]..g.first[b + 1] {
                for &a in g.neighbours(b) {
                    rows.extend((g.first[a as usize]..g.first[a as usize + 1]).filter(|&r| r >= c));
                }
                col_ptr.push(rows.len());
            }
        }
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows)
    }

    /// Stored entries of the Cholesky factor with this ordering (None: faer's AMD).
    fn factor_size(a: &SymbolicSparseColMat<usize>, perm: Option<&[usize]>) -> usize {
        let n = a.nrows();
        let inv: Vec<usize> = perm.map_or(Vec::new(), |p| {
            let mut inv = vec![0; n];
            p.iter().enumerate().for_each(|(new, &old)| inv[old] = new);
            inv
        });
        let ordering = match perm {
            Some(p) => SymmetricOrdering::Custom(PermRef::new_checked(p, &inv, n)),
            None => SymmetricOrdering::Amd,
        };
        factorize_symbolic_cholesky(
            a.as_ref(),
            Side::Lower,
            ordering,
            CholeskySymbolicParams::default(),
        )
        .unwrap()
        .len_val()
    }

    fn is_permutation_of_whole_nodes(p: &[usize], g: &NodeGraph) -> bool {
        let n = g.first[g.nodes()];
        let mut seen = vec![false; n];
        let whole = p
            .chunks(n / g.nodes())
            .all(|c| c.windows(2).all(|w| w[1] == w[0] + 1));
        whole
            && p.len() == n
            && p.iter()
                .all(|&i| i < n && !std::mem::replace(&mut seen[i], true))
    }

    /// Both orderings number every unknown once, a node's unknowns together;
    /// AMD on the node graph gives the fill of AMD on the scalar matrix (to 2 %).
    #[test]
    fn node_orderings_are_whole_node_permutations() {
        let (start, adjacency, first) = grid::<2>([40, 30], 2, 2);
        let g = NodeGraph {
            start: &start,
            adjacency: &adjacency,
            first: &first,
        };
        let a = scalar_lower(&g);
        let scalar = factor_size(&a, None);
        for (name, perm) in [("amd", node_amd(&g)), ("metis", node_metis(&g))] {
            assert!(is_permutation_of_whole_nodes(&perm, &g), "{name}");
            let size = factor_size(&a, Some(&perm));
            println!("2D 40 × 30, {name}: {size} vs scalar AMD {scalar}");
            if name == "amd" {
                assert!(
                    (size as f64 / scalar as f64 - 1.0).abs() < 0.02,
                    "{size} vs {scalar}"
                );
            }
        }
    }

    /// In 3D, METIS' nested dissection stores at least 10 % less than AMD
    /// (measured: about 25 % on the 20³ block, docs/performance.md).
    #[test]
    fn nested_dissection_beats_minimum_degree_in_3d() {
        let (start, adjacency, first) = grid::<3>([14, 14, 14], 2, 3);
        let g = NodeGraph {
            start: &start,
            adjacency: &adjacency,
            first: &first,
        };
        let a = scalar_lower(&g);
        let amd = factor_size(&a, Some(&node_amd(&g)));
        let metis = factor_size(&a, Some(&node_metis(&g)));
        println!("3D 14³ nodes, reach 2: METIS {metis}, AMD {amd}");
        assert!(
            (metis as f64) < 0.9 * amd as f64,
            "METIS {metis} vs AMD {amd}"
        );
    }
}
