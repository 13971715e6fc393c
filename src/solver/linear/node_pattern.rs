//! The compressed-column layout of a tangent whose unknowns come in nodes.
//!
//! The step's tangent couples all the unknowns of node b to all those of each
//! neighbour a of b in the node graph, and numbers unknowns node by node (node
//! a owns `first[a]..first[a + 1]`: its components, the D displacements and
//! any scalar fields, fewer where components are prescribed or the node is
//! tied). So column c of node b holds, neighbour
//! after neighbour in ascending order, the rows `first[a]..first[a + 1]`, those
//! below `lowest` dropped (`lowest = c` for a stored lower triangle, 0 for the
//! whole matrix). The row of every entry follows from the graph and the column
//! pointers: a consumer that walks columns needs no row index (4 bytes per
//! entry; the multigrid's fine level does without it).

use super::ordering::NodeGraph;
use super::Index;
use std::ops::Range;

/// The arrays of a node graph ([`NodeGraph`] borrows them), owned: the step's
/// pattern and the multigrid's fine level share them.
#[derive(Clone, Debug, Default)]
pub struct NodeLists {
    /// Node a's neighbours are `adjacency[start[a]..start[a + 1]]`, ascending.
    pub start: Vec<usize>,
    pub adjacency: Vec<u32>,
    /// Node a owns the unknowns `first[a]..first[a + 1]`.
    pub first: Vec<usize>,
}

impl NodeLists {
    pub fn graph(&self) -> NodeGraph<'_> {
        NodeGraph {
            start: &self.start,
            adjacency: &self.adjacency,
            first: &self.first,
        }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.first.len() - 1
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.first[self.nodes()]
    }

    /// The neighbours of node b, ascending.
    pub fn neighbours(&self, b: usize) -> &[u32] {
        &self.adjacency[self.start[b]..self.start[b + 1]]
    }

    /// The unknowns of node b.
    pub fn columns(&self, b: usize) -> Range<usize> {
        self.first[b]..self.first[b + 1]
    }

    /// The node that owns unknown i.
    pub fn node_of(&self, i: usize) -> usize {
        self.first.partition_point(|&u| u <= i) - 1
    }

    /// The rows of neighbour a in a column of the layout: its unknowns, those
    /// below `lowest` dropped.
    pub fn rows_of(&self, a: usize, lowest: usize) -> Range<usize> {
        let (lo, hi) = (self.first[a].max(lowest), self.first[a + 1]);
        lo..hi.max(lo)
    }

    /// The neighbours of node b that have rows ≥ `lowest` (those after
    /// the ones whose unknowns all lie below it).
    pub fn neighbours_from(&self, b: usize, lowest: usize) -> &[u32] {
        let all = self.neighbours(b);
        let skip = if lowest == 0 {
            0
        } else if self.columns(b).contains(&lowest) {
            // A column of b's own (the lower triangle): the neighbours after b.
            all.partition_point(|&a| (a as usize) < b)
        } else {
            all.partition_point(|&a| self.first[a as usize + 1] <= lowest)
        };
        &all[skip..]
    }

    /// Number of rows of a column of node b in the layout (rows ≥ `lowest`).
    pub fn column_len(&self, b: usize, lowest: usize) -> usize {
        (self.neighbours_from(b, lowest).iter())
            .map(|&a| self.rows_of(a as usize, lowest).len())
            .sum()
    }

    /// The neighbours b ≤ a of node a (the nodes whose columns hold a's rows
    /// in the lower triangle).
    pub fn lower_neighbours(&self, a: usize) -> &[u32] {
        let all = self.neighbours(a);
        &all[..all.partition_point(|&b| b as usize <= a)]
    }

    /// Whether node b couples to itself (then its own rows open its columns
    /// in the lower triangle).
    pub fn self_coupled(&self, b: usize) -> bool {
        self.neighbours(b).binary_search(&(b as u32)).is_ok()
    }

    /// f(k, i) for every entry of column c of the layout, k its position
    /// (from `col_ptr[c]` on) and i its row, ascending; `neighbours` are
    /// those of c's node from `neighbours_from(node, lowest)` (the same for
    /// all the columns of a node in the lower triangle).
    pub fn for_each_in_column(
        &self,
        col_ptr: &[Index],
        neighbours: &[u32],
        c: usize,
        lowest: usize,
        mut f: impl FnMut(usize, usize),
    ) {
        let mut k = col_ptr[c] as usize;
        for &a in neighbours {
            for i in self.rows_of(a as usize, lowest) {
                f(k, i);
                k += 1;
            }
        }
        debug_assert_eq!(k, col_ptr[c + 1] as usize);
    }

    /// The last row of a column of the layout, if any (`neighbours` as in
    /// `for_each_in_column`).
    pub fn last_row(&self, neighbours: &[u32], lowest: usize) -> Option<usize> {
        (neighbours.iter().rev())
            .map(|&a| self.rows_of(a as usize, lowest))
            .find(|r| !r.is_empty())
            .map(|r| r.end - 1)
    }

    /// The position of entry (r, c) of the layout (c a column of node b, r an
    /// unknown of node a), if the layout holds it: the rows of b's neighbours
    /// before a, summed, then r's place among a's.
    pub fn position(
        &self,
        col_ptr: &[Index],
        (a, r): (usize, usize),
        (b, c): (usize, usize),
        lowest: usize,
    ) -> Option<usize> {
        let rows = self.rows_of(a, lowest);
        if !rows.contains(&r) {
            return None;
        }
        let neighbours = self.neighbours_from(b, lowest);
        let j = neighbours.binary_search(&(a as u32)).ok()?;
        let before: usize = (neighbours[..j].iter())
            .map(|&n| self.rows_of(n as usize, lowest).len())
            .sum();
        Some(col_ptr[c] as usize + before + r - rows.start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three nodes on a line (0–1–2 coupled to their neighbours and
    /// themselves), node 1 with one unknown, the others with two.
    fn line() -> NodeLists {
        NodeLists {
            start: vec![0, 2, 5, 7],
            adjacency: vec![0, 1, 0, 1, 2, 1, 2],
            first: vec![0, 2, 3, 5],
        }
    }

    /// Column pointers of the layout (rows ≥ c when `lower`).
    fn col_ptr(g: &NodeLists, lower: bool) -> Vec<Index> {
        let mut ptr = vec![0];
        for b in 0..g.nodes() {
            for c in g.columns(b) {
                let len = g.column_len(b, if lower { c } else { 0 });
                ptr.push(ptr.last().unwrap() + len as Index);
            }
        }
        ptr
    }

    #[test]
    fn columns_positions_and_nodes_agree_with_the_written_out_pattern() {
        let g = line();
        assert_eq!(
            (0..5).map(|i| g.node_of(i)).collect::<Vec<_>>(),
            [0, 0, 1, 2, 2]
        );
        // The whole matrix: rows of each column written out by hand.
        let full: [&[usize]; 5] = [
            &[0, 1, 2],
            &[0, 1, 2],
            &[0, 1, 2, 3, 4],
            &[2, 3, 4],
            &[2, 3, 4],
        ];
        let lower: [&[usize]; 5] = [&[0, 1, 2], &[1, 2], &[2, 3, 4], &[3, 4], &[4]];
        for (is_lower, expected) in [(false, full), (true, lower)] {
            let ptr = col_ptr(&g, is_lower);
            for c in 0..5 {
                let (b, lowest) = (g.node_of(c), if is_lower { c } else { 0 });
                let (mut rows, from) = (Vec::new(), g.neighbours_from(b, lowest));
                g.for_each_in_column(&ptr, from, c, lowest, |k, i| rows.push((k, i)));
                let want: Vec<(usize, usize)> = (expected[c].iter())
                    .enumerate()
                    .map(|(t, &i)| (ptr[c] as usize + t, i))
                    .collect();
                assert_eq!(rows, want, "column {c}, lower {is_lower}");
                assert_eq!(g.last_row(from, lowest), expected[c].last().copied());
                for r in 0..5 {
                    let at = g.position(&ptr, (g.node_of(r), r), (b, c), lowest);
                    let want = rows.iter().find(|&&(_, i)| i == r).map(|&(k, _)| k);
                    assert_eq!(at, want, "entry ({r}, {c}), lower {is_lower}");
                }
            }
        }
    }
}
