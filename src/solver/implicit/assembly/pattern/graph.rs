//! The node graph of the step's tangent: per active node, the nodes it
//! couples to (a tied node counting as its masters), and the stencil entries
//! each node takes terms from through the ties ([`sources`]).

use super::super::Dofs;
use crate::physics::kinematics::fbar::Cells;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::implicit::stress_gradient::LeastSquares;
use crate::solver::linear::node_pattern::NodeLists;
use rayon::prelude::*;

/// The sources of the nodes that ties touch: `of[b]` is `OWN` for a node
/// that takes only its own entries (coefficient 1), `TIED` for a tied node
/// (it takes none: its masters take its entries), else the number m of its
/// merged list `list[start[m]..start[m + 1]]` (a master). Only the masters'
/// lists are stored: a copy of every node's entries was the largest array of
/// a 2D step with ties (108 MiB at 10⁶ particles).
#[derive(Clone, Debug, Default)]
pub(super) struct TiedSources {
    of: Vec<u32>,
    start: Vec<usize>,
    list: Vec<(u32, f64)>,
}

impl TiedSources {
    const OWN: u32 = u32::MAX;
    const TIED: u32 = u32::MAX - 1;
}

/// The stencil entries a node takes terms from, with their coefficients.
pub(super) enum Sources<'a> {
    Own(std::slice::Iter<'a, u32>),
    Tied(std::slice::Iter<'a, (u32, f64)>),
}

impl Iterator for Sources<'_> {
    type Item = (u32, f64);

    fn next(&mut self) -> Option<(u32, f64)> {
        match self {
            Sources::Own(entries) => entries.next().map(|&e| (e, 1.0)),
            Sources::Tied(list) => list.next().copied(),
        }
    }
}

/// The node graph of the stencils `st` over the active nodes of `map` with
/// the unknowns `dofs` (`Pattern::new`), with the sources of the nodes that
/// ties touch, if any.
pub(super) fn node_lists<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    cells: Option<&Cells>,
    fit: Option<&LeastSquares<D>>,
    coupled: &[(u32, u32)],
) -> (NodeLists, Option<TiedSources>) {
    let n = map.len();
    let mut first = Vec::with_capacity(n + 1);
    first.push(0);
    for a in 0..n {
        let count = (0..dofs.per_node())
            .filter(|&c| dofs.of(a, c).is_some())
            .count();
        first.push(first[a] + count);
    }
    debug_assert_eq!(first[n], dofs.free);
    let tied = dofs.ties.iter().any(Option::is_some);
    let tied_sources = tied.then(|| tied_sources(map, dofs));
    let sources_of = |b: usize| sources(tied_sources.as_ref(), map, b);
    let (neighbour_start, neighbours) = if let Some(fit) = fit {
        assert!(cells.is_none(), "F-bar with a linear domain stress");
        let each: Vec<u32> = (0..st.count.len() as u32).collect();
        node_graph(
            n,
            st.stride,
            &sources_of,
            |q, out| {
                for &p in std::iter::once(&(q as u32)).chain(fit.neighbours(q)) {
                    out.extend(st.range(p as usize).map(|e| map.local_of(st, e)));
                }
            },
            &each,
            dofs,
        )
    } else if let Some(cells) = cells {
        node_graph(
            n,
            st.stride,
            &sources_of,
            |q, out| {
                for &p in cells.members(cells.of[q] as usize) {
                    out.extend(st.range(p as usize).map(|e| map.local_of(st, e)));
                }
            },
            &cells.of,
            dofs,
        )
    } else {
        node_graph(
            n,
            st.stride,
            &sources_of,
            |q, out| {
                out.extend(st.range(q).map(|e| map.local_of(st, e)));
            },
            &stencil_groups(st),
            dofs,
        )
    };
    let (neighbour_start, neighbours) = with_pairs(neighbour_start, neighbours, coupled, dofs);
    let lists = NodeLists {
        start: neighbour_start,
        adjacency: neighbours,
        first,
    };
    (lists, tied_sources)
}

/// Per master of a tie, the stencil entries it takes terms from: its own
/// (coefficient 1) and those of the nodes tied to it (the tie's coefficient),
/// in increasing entry order; which nodes are tied.
fn tied_sources(map: &NodeMap, dofs: &Dofs) -> TiedSources {
    let n = map.len();
    let mut tied_to: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    let mut of = vec![TiedSources::OWN; n];
    for (t, tie) in dofs.ties.iter().enumerate() {
        if let Some(tie) = tie {
            of[t] = TiedSources::TIED;
            for (m, c) in tie.master.iter().zip(tie.coef) {
                tied_to[*m].push((t, c));
            }
        }
    }
    let mut start = vec![0];
    let mut list: Vec<(u32, f64)> = Vec::new();
    for (a, tied) in tied_to.iter().enumerate() {
        if tied.is_empty() {
            continue;
        }
        let from = list.len();
        if of[a] == TiedSources::OWN {
            list.extend(map.node_entries(a).iter().map(|&e| (e, 1.0)));
        }
        for &(t, c) in tied {
            list.extend(map.node_entries(t).iter().map(|&e| (e, c)));
        }
        list[from..].sort_by_key(|&(e, _)| e);
        of[a] = (start.len() - 1) as u32;
        start.push(list.len());
    }
    TiedSources { of, start, list }
}

/// The sources of node b: its own entries of the node map with coefficient
/// 1, unless ties touch it (`TiedSources`).
pub(super) fn sources<'a>(
    tied: Option<&'a TiedSources>,
    map: &'a NodeMap,
    b: usize,
) -> Sources<'a> {
    let own = Sources::Own(map.node_entries(b).iter());
    let Some(t) = tied else { return own };
    match t.of[b] {
        TiedSources::OWN => own,
        TiedSources::TIED => Sources::Tied([].iter()),
        m => Sources::Tied(t.list[t.start[m as usize]..t.start[m as usize + 1]].iter()),
    }
}

/// Particles with the same stencil nodes, numbered: `group[q]` for particle q.
/// Particles sorted by their stencil's node list (ties by index, so the
/// numbering does not depend on the thread count); equal lists share a number.
fn stencil_groups<const D: usize>(st: &Stencils<D>) -> Vec<u32> {
    let nodes = |q: u32| &st.node[st.range(q as usize)];
    let mut order: Vec<u32> = (0..st.count.len() as u32).collect();
    order.par_sort_unstable_by(|&p, &q| nodes(p).cmp(nodes(q)).then(p.cmp(&q)));
    let mut group = vec![0u32; order.len()];
    let mut g = 0;
    for (i, &q) in order.iter().enumerate() {
        if i > 0 && nodes(order[i - 1]) != nodes(q) {
            g += 1;
        }
        group[q as usize] = g;
    }
    group
}

/// The node graph: per node b, the owners (masters for tied nodes) of every
/// node that `nodes_of(q, …)` lists for a particle q of b's sources, ascending.
/// Particles of one group (`group[q]`: the same stencil nodes, or the same
/// cell with F-bar) list the same nodes, so each group is visited once per node.
fn node_graph<'s, F, S>(
    n: usize,
    stride: usize,
    sources_of: &S,
    nodes_of: F,
    group: &[u32],
    dofs: &Dofs,
) -> (Vec<usize>, Vec<u32>)
where
    F: Fn(usize, &mut Vec<usize>) + Sync,
    S: Fn(usize) -> Sources<'s> + Sync,
{
    let count = group.iter().max().map_or(0, |&g| g as usize + 1);
    let lists: Vec<Vec<u32>> = (0..n)
        .into_par_iter()
        .with_min_len(64)
        .map_init(
            // Per task: which nodes and groups node b has met (marked with b).
            || {
                (
                    vec![u32::MAX; n],
                    vec![u32::MAX; count],
                    Vec::new(),
                    Vec::new(),
                )
            },
            |(seen, visited, scratch, out), b| {
                out.clear();
                for (e, _) in sources_of(b) {
                    let q = e as usize / stride;
                    let g = group[q] as usize;
                    if visited[g] == b as u32 {
                        continue;
                    }
                    visited[g] = b as u32;
                    scratch.clear();
                    nodes_of(q, scratch);
                    for &a in scratch.iter() {
                        for (o, _) in dofs.owners(a) {
                            if seen[o] != b as u32 {
                                seen[o] = b as u32;
                                out.push(o as u32);
                            }
                        }
                    }
                }
                out.sort_unstable();
                out.clone()
            },
        )
        .collect();
    let mut start = Vec::with_capacity(n + 1);
    start.push(0);
    for l in &lists {
        start.push(start.last().unwrap() + l.len());
    }
    (start, lists.concat())
}

/// The node graph (`start`, `adjacency`) with every pair of `coupled` nodes
/// (their owners) joined both ways.
fn with_pairs(
    start: Vec<usize>,
    adjacency: Vec<u32>,
    coupled: &[(u32, u32)],
    dofs: &Dofs,
) -> (Vec<usize>, Vec<u32>) {
    if coupled.is_empty() {
        return (start, adjacency);
    }
    let n = start.len() - 1;
    let mut lists: Vec<Vec<u32>> = (0..n)
        .map(|b| adjacency[start[b]..start[b + 1]].to_vec())
        .collect();
    for &(a, b) in coupled {
        for (oa, _) in dofs.owners(a as usize) {
            for (ob, _) in dofs.owners(b as usize) {
                lists[oa].push(ob as u32);
                lists[ob].push(oa as u32);
            }
        }
    }
    let mut out_start = Vec::with_capacity(n + 1);
    out_start.push(0);
    for l in &mut lists {
        l.sort_unstable();
        l.dedup();
        out_start.push(out_start.last().unwrap() + l.len());
    }
    (out_start, lists.concat())
}
