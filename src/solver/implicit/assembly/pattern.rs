//! The sparsity pattern of the tangent and the scatter of its terms into it.
//!
//! Every term of K couples the nodes of one particle's stencil (with F-bar, of
//! one cell's particles), so the pattern is known once the step's stencils and
//! unknowns are: node b couples to node a when some stencil (cell) holds both,
//! a tied node counting as its masters. [`Pattern::new`] builds that node graph
//! once per step, and from it the compressed-column pattern of the unknowns, the
//! lower triangle for a symmetric tangent or the whole matrix otherwise
//! ([`Pattern::csc`]). Each Newton iteration then adds the particles' terms
//! straight into the value array of that pattern ([`Pattern::add_stencil_terms`]):
//! no triplet list, no sort.
//!
//! The scatter runs in parallel over the columns' nodes: the task of node b
//! writes only b's columns, and it visits b's stencil entries (its own, then
//! those of nodes tied to it, in increasing entry order, so in increasing
//! particle order), so every value is the same sum in the same order for any
//! number of threads.

use super::Dofs;
use crate::physics::kinematics::fbar::Cells;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::scene::DirectOrdering;
use crate::solver::implicit::stress_gradient::LeastSquares;
use crate::solver::linear::direct::spmv;
use crate::solver::linear::node_pattern::NodeLists;
use crate::solver::linear::ordering::{node_amd, node_metis, NodeGraph};
use crate::solver::linear::Index;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

/// Which part of the tangent is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// Rows ≥ column only (a symmetric tangent).
    Lower,
    /// Every entry.
    Full,
}

impl Storage {
    /// The lowest row of column c that is stored: c itself in the lower
    /// triangle, 0 in the whole matrix.
    fn lowest(self, c: usize) -> usize {
        match self {
            Storage::Lower => c,
            Storage::Full => 0,
        }
    }
}

/// Which component pairs (i, k) of two nodes a term couples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Components {
    /// Every pair: a full D×D block (stiffness).
    All,
    /// i = k only: a diagonal block (mass, dashpots, springs).
    Diagonal,
}

/// The node graph of one step's tangent and the compressed-column patterns of
/// its unknowns.
#[derive(Clone, Debug, Default)]
pub struct Pattern {
    /// The node graph: per node, the nodes it couples to (masters for tied
    /// nodes), ascending, and its unknowns (numbered node by node); shared with
    /// the multigrid's fine level, which finds the rows through it.
    lists: Arc<NodeLists>,
    /// When some node is tied: the stencil entries each master takes terms
    /// from (its own and those of the nodes tied to it, with the coefficients
    /// of the ties), and which nodes are masters or tied. Other nodes take
    /// their own entries of the node map with coefficient 1, and nothing is
    /// stored for them (see `sources`).
    tied_sources: Option<TiedSources>,
    /// Column pointers of the lower triangle and of the whole matrix.
    lower_cols: OnceLock<Arc<[Index]>>,
    full_cols: OnceLock<Arc<[Index]>>,
    /// The compressed-column patterns with their row indices (only for a
    /// consumer that needs them: the direct solver, an unsymmetric tangent).
    lower: OnceLock<Arc<SymbolicSparseColMat<Index>>>,
    full: OnceLock<Arc<SymbolicSparseColMat<Index>>>,
    amd: OnceLock<Vec<usize>>,
    metis: OnceLock<Vec<usize>>,
    /// What the pattern was built from, to tell whether a later step's fits.
    built_for: BuiltFor,
}

/// The sources of the nodes that ties touch: `of[b]` is `OWN` for a node
/// that takes only its own entries (coefficient 1), `TIED` for a tied node
/// (it takes none: its masters take its entries), else the number m of its
/// merged list `list[start[m]..start[m + 1]]` (a master). Only the masters'
/// lists are stored: a copy of every node's entries was the largest array of
/// a 2D step with ties (108 MiB at 10⁶ particles).
#[derive(Clone, Debug, Default)]
struct TiedSources {
    of: Vec<u32>,
    start: Vec<usize>,
    list: Vec<(u32, f64)>,
}

impl TiedSources {
    const OWN: u32 = u32::MAX;
    const TIED: u32 = u32::MAX - 1;
}

/// The stencil entries a node takes terms from, with their coefficients.
enum Sources<'a> {
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

/// The inputs of a pattern: the stencils' nodes (which also fix the node map),
/// the cells of F-bar and the unknowns with their ties.
#[derive(Clone, Debug, Default, PartialEq)]
struct BuiltFor {
    /// A digest of the stencils' node lists ([`stencil_digest`]).
    stencils: [u64; 2],
    cell_of: Option<Vec<u32>>,
    /// The least-squares neighbour lists (offsets, neighbours).
    neighbours: Option<(Vec<usize>, Vec<u32>)>,
    /// Node pairs coupled beyond the stencils (contact).
    coupled: Vec<(u32, u32)>,
    /// A digest of the unknowns' numbering and ties ([`dofs_digest`]).
    dofs: [u64; 2],
}

impl BuiltFor {
    fn new<const D: usize>(
        st: &Stencils<D>,
        dofs: &Dofs,
        cells: Option<&Cells>,
        fit: Option<&LeastSquares<D>>,
        coupled: &[(u32, u32)],
    ) -> BuiltFor {
        BuiltFor {
            stencils: stencil_digest(st),
            cell_of: cells.map(|c| c.of.clone()),
            neighbours: fit.map(|f| (f.lists().0.to_vec(), f.lists().1.to_vec())),
            coupled: coupled.to_vec(),
            dofs: dofs_digest(dofs),
        }
    }

    fn fits<const D: usize>(
        &self,
        st: &Stencils<D>,
        dofs: &Dofs,
        cells: Option<&Cells>,
        fit: Option<&LeastSquares<D>>,
        coupled: &[(u32, u32)],
    ) -> bool {
        self.coupled == coupled
            && self.stencils == stencil_digest(st)
            && self.cell_of.as_deref() == cells.map(|c| c.of.as_slice())
            && self
                .neighbours
                .as_ref()
                .map(|(o, n)| (o.as_slice(), n.as_slice()))
                == fit.map(|f| f.lists())
            && self.dofs == dofs_digest(dofs)
    }
}

/// A 128-bit digest of the unknowns `dofs`: their numbering and the ties
/// (masters and the bits of the coefficients), as [`stencil_digest`] makes it;
/// a copy took 40 bytes per active node once some node was tied.
fn dofs_digest(dofs: &Dofs) -> [u64; 2] {
    use std::hash::{DefaultHasher, Hash, Hasher};
    let sum = |prefix: u8| {
        let mut h = DefaultHasher::new();
        (prefix, &dofs.index, dofs.free, dofs.ties.len()).hash(&mut h);
        for tie in &dofs.ties {
            tie.map(|t| (t.master, t.coef.map(f64::to_bits)))
                .hash(&mut h);
        }
        h.finish()
    };
    [sum(0), sum(1)]
}

/// A 128-bit digest of the stencils' node lists: two SipHash-1-3 sums
/// (`std`'s `DefaultHasher`, fixed keys) of the counts and nodes after
/// different prefixes. It stands for the lists themselves, whose copy was the
/// pattern's largest array (16 MiB at 409,600 particles in 2D, 4 bytes per
/// stencil entry); two different lists have the same digest with a probability
/// of about 2⁻¹²⁸.
fn stencil_digest<const D: usize>(st: &Stencils<D>) -> [u64; 2] {
    use std::hash::{DefaultHasher, Hash, Hasher};
    let sum = |prefix: u8| {
        let mut h = DefaultHasher::new();
        (prefix, st.stride, &st.count, &st.node).hash(&mut h);
        h.finish()
    };
    let (a, b) = rayon::join(|| sum(0), || sum(1));
    [a, b]
}

impl Pattern {
    /// The node graph of the stencils `st` over the active nodes of `map` with
    /// the unknowns `dofs`; with `cells` (F-bar), every particle also couples to
    /// the nodes of the other particles of its cell; with `fit` (a linear
    /// domain stress), to the nodes of its least-squares neighbours; and each
    /// pair of `coupled` nodes (contact between the nodes of two bodies).
    pub fn new<const D: usize>(
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        cells: Option<&Cells>,
        fit: Option<&LeastSquares<D>>,
        coupled: &[(u32, u32)],
    ) -> Pattern {
        let n = map.len();
        let mut first = Vec::with_capacity(n + 1);
        first.push(0);
        for a in 0..n {
            let count = (0..D).filter(|&d| dofs.of(a, d, D).is_some()).count();
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
        Pattern {
            lists: Arc::new(NodeLists {
                start: neighbour_start,
                adjacency: neighbours,
                first,
            }),
            tied_sources,
            lower_cols: OnceLock::new(),
            full_cols: OnceLock::new(),
            lower: OnceLock::new(),
            full: OnceLock::new(),
            amd: OnceLock::new(),
            metis: OnceLock::new(),
            built_for: BuiltFor::new(st, dofs, cells, fit, coupled),
        }
    }

    /// Whether this pattern (and its ordering) is the one [`Pattern::new`]
    /// would build for these stencils, unknowns and cells: true when no
    /// particle changed its stencil's nodes, no node its constraint or tie.
    pub fn fits<const D: usize>(
        &self,
        st: &Stencils<D>,
        dofs: &Dofs,
        cells: Option<&Cells>,
        fit: Option<&LeastSquares<D>>,
        coupled: &[(u32, u32)],
    ) -> bool {
        self.built_for.fits(st, dofs, cells, fit, coupled)
    }

    /// The node graph with the unknowns of each node.
    pub fn graph(&self) -> NodeGraph<'_> {
        self.lists.graph()
    }

    /// The node graph's arrays, shared.
    pub fn lists(&self) -> &Arc<NodeLists> {
        &self.lists
    }

    /// The fill-reducing ordering `kind` of the unknowns for a Cholesky
    /// factorization (computed on the node graph at the first call).
    pub fn ordering<const D: usize>(&self, kind: DirectOrdering) -> &[usize] {
        match kind.resolved(D) {
            DirectOrdering::Metis => self.metis.get_or_init(|| node_metis(&self.graph())),
            _ => self.amd.get_or_init(|| node_amd(&self.graph())),
        }
    }

    /// Number of active nodes.
    pub fn nodes(&self) -> usize {
        self.lists.nodes()
    }

    /// The nodes coupled to node b (ascending).
    pub fn neighbours(&self, b: usize) -> &[u32] {
        self.lists.neighbours(b)
    }

    /// The unknowns of node b (consecutive).
    pub fn columns(&self, b: usize) -> std::ops::Range<usize> {
        self.lists.columns(b)
    }

    /// The column pointers of the compressed-column pattern of the unknowns
    /// (counted at the first call, in parallel over the nodes): column c of
    /// node b holds the unknowns of b's neighbours, those ≥ c with `Lower`
    /// ([`NodeLists`]). An error if the pattern has more entries than
    /// [`Index`] numbers.
    pub fn col_ptr(&self, storage: Storage) -> Result<&Arc<[Index]>, String> {
        let cell = match storage {
            Storage::Lower => &self.lower_cols,
            Storage::Full => &self.full_cols,
        };
        if let Some(ptr) = cell.get() {
            return Ok(ptr);
        }
        let lengths: Vec<usize> = (0..self.nodes())
            .into_par_iter()
            .with_min_len(256)
            .flat_map_iter(|b| {
                self.columns(b)
                    .map(move |c| self.lists.column_len(b, storage.lowest(c)))
            })
            .collect();
        let total: usize = lengths.iter().sum();
        if total > Index::MAX as usize {
            return Err(format!(
                "the tangent's pattern has {total} entries, more than the 2³² that 32-bit \
                 indices number"
            ));
        }
        let mut col_ptr: Vec<Index> = Vec::with_capacity(lengths.len() + 1);
        col_ptr.push(0);
        for len in lengths {
            col_ptr.push(col_ptr.last().unwrap() + len as Index);
        }
        Ok(cell.get_or_init(|| col_ptr.into()))
    }

    /// The compressed-column pattern with its row indices (built at the first
    /// call), shared: the direct solver keeps a handle to the pattern it
    /// analysed instead of a copy. An error as [`Pattern::col_ptr`].
    pub fn csc(&self, storage: Storage) -> Result<&Arc<SymbolicSparseColMat<Index>>, String> {
        let cell = match storage {
            Storage::Lower => &self.lower,
            Storage::Full => &self.full,
        };
        if let Some(csc) = cell.get() {
            return Ok(csc);
        }
        let csc = self.build_csc(storage)?;
        Ok(cell.get_or_init(|| Arc::new(csc)))
    }

    /// The rows of every column ([`NodeLists::for_each_in_column`]), filled in
    /// parallel over the nodes (each node writes its own columns: the same
    /// result on any number of threads). Rows ascend within each column:
    /// neighbours ascend and unknowns are numbered node by node.
    fn build_csc(&self, storage: Storage) -> Result<SymbolicSparseColMat<Index>, String> {
        let col_ptr = self.col_ptr(storage)?;
        let mut rows: Vec<Index> = vec![0; col_ptr[col_ptr.len() - 1] as usize];
        self.per_node(col_ptr, &mut rows)
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .for_each(|(b, out)| {
                let base = col_ptr[self.columns(b).start] as usize;
                for c in self.columns(b) {
                    let lowest = storage.lowest(c);
                    let from = self.lists.neighbours_from(b, lowest);
                    (self.lists).for_each_in_column(col_ptr, from, c, lowest, |k, i| {
                        out[k - base] = i as Index
                    });
                }
            });
        let n = col_ptr.len() - 1;
        Ok(SymbolicSparseColMat::new_checked(
            n,
            n,
            col_ptr.to_vec(),
            None,
            rows,
        ))
    }

    /// `entries` (a compressed-column array with `col_ptr`) split into the
    /// columns of each node: disjoint slices, in node order.
    fn per_node<'v, T>(&self, col_ptr: &[Index], mut entries: &'v mut [T]) -> Vec<&'v mut [T]> {
        let mut out = Vec::with_capacity(self.nodes());
        for b in 0..self.nodes() {
            let cols = self.columns(b);
            let len = col_ptr[cols.end] - col_ptr[cols.start];
            let (head, tail) = entries.split_at_mut(len as usize);
            out.push(head);
            entries = tail;
        }
        out
    }

    /// Adds the term of every particle q with `column(q, e2, needed, block)` true
    /// to the values of the pattern with `storage` (its column pointers
    /// `col_ptr`, [`Pattern::col_ptr`]): for each stencil
    /// entry e2 of q, `column` fills `block[(e1 − first entry of q)·D² + i·D + k]`
    /// with the term at (node of e1, component i) × (node of e2, component k) for
    /// every entry e1 of q with `needed[e1 − first entry of q]` (the others are
    /// not read: with `Lower`, the entries all of whose owners, the node or the
    /// masters of its tie, come before the column's node, so that their rows
    /// lie above the diagonal); `components` says which (i, k) it sets. Spread onto the
    /// unknowns through the ties; rows below the diagonal only with `Lower`.
    #[allow(clippy::too_many_arguments)]
    pub fn add_stencil_terms<const D: usize>(
        &self,
        values: &mut [f64],
        col_ptr: &[Index],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        components: Components,
        column: impl Fn(usize, usize, &[bool], &mut [f64]) -> bool + Sync,
    ) {
        self.per_node(col_ptr, values)
            .into_par_iter()
            .enumerate()
            .with_min_len(16)
            .for_each_init(
                || {
                    (
                        Vec::new(),
                        vec![false; st.stride],
                        vec![0.0; st.stride * D * D],
                    )
                },
                |(offsets, needed, block), (b, vals)| {
                    self.add_column_terms(
                        b, vals, col_ptr, storage, map, st, dofs, components, &column, offsets,
                        needed, block,
                    )
                },
            );
    }

    /// Adds terms that couple a particle's stencil to nodes beyond it: for each
    /// stencil entry e2 of particle q (node J), `rows(q, e2, out)` lists
    /// (node I, block) with block[i·D + k] the term at (I, component i) ×
    /// (J, component k), for any active nodes I that the pattern couples to J.
    /// Spread onto the unknowns through the ties; the whole matrix only
    /// (`Storage::Full`). In parallel over the columns' nodes, each visiting its
    /// sources in order: the same sums for any number of threads.
    #[allow(clippy::too_many_arguments)]
    pub fn add_listed_terms<const D: usize>(
        &self,
        values: &mut [f64],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        rows: impl Fn(usize, usize, &mut Vec<(usize, [f64; 9])>) + Sync,
    ) {
        assert_eq!(storage, Storage::Full, "listed terms need the whole matrix");
        let csc = &**self
            .csc(storage)
            .expect("counted by the tangent's column pointers");
        let col_ptr = csc.col_ptr();
        self.per_node(col_ptr, values)
            .into_par_iter()
            .enumerate()
            .with_min_len(16)
            .for_each_init(Vec::new, |out, (b, vals)| {
                let cols = self.columns(b);
                if cols.is_empty() {
                    return;
                }
                let base = col_ptr[cols.start] as usize;
                let col_of: [Option<usize>; D] = std::array::from_fn(|k| dofs.of(b, k, D));
                for (e2, cc) in sources(self.tied_sources.as_ref(), map, b) {
                    out.clear();
                    rows(e2 as usize / st.stride, e2 as usize, out);
                    for (n1, block) in out.iter() {
                        for (a, cr) in dofs.owners(*n1) {
                            for i in 0..D {
                                let Some(r) = dofs.of(a, i, D) else { continue };
                                for (k, c) in col_of.iter().enumerate() {
                                    let Some(c) = *c else { continue };
                                    let at = slot(csc.as_ref(), r, c)
                                        .expect("listed entry in the pattern");
                                    vals[at - base] += block[i * D + k] * cr * cc;
                                }
                            }
                        }
                    }
                }
            });
    }

    /// The terms of node b's columns (`vals`, from `col_ptr[first column]` on).
    /// Row r of node a (a neighbour of b) sits in column c at
    /// `offsets[k][j] + r − max(first[a], c)`, j the position of a among b's
    /// neighbours and `offsets[k][j]` the rows of the neighbours before it.
    #[allow(clippy::too_many_arguments)]
    fn add_column_terms<const D: usize>(
        &self,
        b: usize,
        vals: &mut [f64],
        col_ptr: &[Index],
        storage: Storage,
        map: &NodeMap,
        st: &Stencils<D>,
        dofs: &Dofs,
        components: Components,
        column: &impl Fn(usize, usize, &[bool], &mut [f64]) -> bool,
        offsets: &mut Vec<usize>,
        needed: &mut [bool],
        block: &mut [f64],
    ) {
        let cols = self.columns(b);
        if cols.is_empty() {
            return;
        }
        let base = col_ptr[cols.start] as usize;
        let neighbours = self.neighbours(b);
        let m = neighbours.len();
        // Rows of column c: the unknowns first[a]..first[a + 1] of each
        // neighbour a in order, those < c dropped when only the lower
        // triangle is stored (`NodeLists::rows_of`).
        let lowest = |c: usize| storage.lowest(c);
        offsets.clear();
        offsets.resize(D * m, usize::MAX);
        let mut col_of = [usize::MAX; D];
        for k in 0..D {
            let Some(c) = dofs.of(b, k, D) else { continue };
            col_of[k] = c;
            let mut at = col_ptr[c] as usize - base;
            for (j, &a) in neighbours.iter().enumerate() {
                offsets[k * m + j] = at;
                at += self.lists.rows_of(a as usize, lowest(c)).len();
            }
            debug_assert_eq!(at, col_ptr[c + 1] as usize - base);
        }
        for (e2, cc) in sources(self.tied_sources.as_ref(), map, b) {
            let e2 = e2 as usize;
            let q = e2 / st.stride;
            // With `Lower`, an entry whose owners all come before b (their
            // unknowns all above b's columns) takes no term in b's columns.
            let needed = &mut needed[..st.range(q).len()];
            if storage == Storage::Full {
                needed.fill(true);
            } else {
                for (flag, e1) in needed.iter_mut().zip(st.range(q)) {
                    let n1 = map.local_of(st, e1);
                    *flag = dofs.owners(n1).any(|(a, _)| a >= b);
                }
            }
            if !column(q, e2, needed, block) {
                continue;
            }
            // The stencil's nodes ascend, so each is found by a short scan on
            // from the previous one (ties may point back: then a search).
            let mut hint = 0;
            for (local, e1) in st.range(q).enumerate() {
                if !needed[local] {
                    continue;
                }
                let n1 = map.local_of(st, e1);
                for (a, cr) in dofs.owners(n1) {
                    let Some(j) = position(neighbours, a as u32, hint) else {
                        continue;
                    };
                    hint = j;
                    let lo = self.lists.first[a];
                    for i in 0..D {
                        let Some(r) = dofs.of(a, i, D) else { continue };
                        let coupled = match components {
                            Components::All => 0..D,
                            Components::Diagonal => i..i + 1,
                        };
                        for k in coupled {
                            let c = col_of[k];
                            if c == usize::MAX || r < lowest(c) {
                                continue;
                            }
                            let slot = offsets[k * m + j] + r - lo.max(lowest(c));
                            vals[slot] += block[local * D * D + i * D + k] * cr * cc;
                        }
                    }
                }
            }
        }
    }
}

/// Position of `a` in the ascending `sorted`, scanning on from `from` first.
fn position(sorted: &[u32], a: u32, from: usize) -> Option<usize> {
    let mut j = from;
    while j < sorted.len() && sorted[j] < a {
        j += 1;
    }
    if j < sorted.len() && sorted[j] == a {
        Some(j)
    } else {
        sorted.binary_search(&a).ok()
    }
}

/// Position of row r in column c of `csc`, if the pattern has it.
pub fn slot(csc: SymbolicSparseColMatRef<Index>, r: usize, c: usize) -> Option<usize> {
    let (start, end) = (csc.col_ptr()[c] as usize, csc.col_ptr()[c + 1] as usize);
    csc.row_idx()[start..end]
        .binary_search(&(r as Index))
        .ok()
        .map(|s| start + s)
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
fn sources<'a>(tied: Option<&'a TiedSources>, map: &'a NodeMap, b: usize) -> Sources<'a> {
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

/// The assembled tangent of one Newton iterate: values in the step's pattern.
pub struct Tangent<'a> {
    /// The step's pattern.
    pub pattern: &'a Pattern,
    /// Its column pointers for `storage` ([`Pattern::col_ptr`]).
    pub col_ptr: &'a Arc<[Index]>,
    pub values: Vec<f64>,
    /// `Lower` when the tangent is symmetric (only rows ≥ column stored).
    pub storage: Storage,
}

impl Tangent<'_> {
    /// The tangent as a compressed-column matrix (its row indices built at
    /// the first call of the step, [`Pattern::csc`]).
    pub fn matrix(&self) -> SparseColMatRef<'_, Index, f64> {
        let csc = (self.pattern.csc(self.storage)).expect("counted by the column pointers");
        SparseColMatRef::new((**csc).as_ref(), &self.values)
    }

    pub fn symmetric(&self) -> bool {
        self.storage == Storage::Lower
    }

    /// y = K x (both triangles when only the lower one is stored).
    pub fn apply(&self, x: &[f64]) -> Vec<f64> {
        spmv(self.matrix(), self.symmetric(), x, false)
    }

    /// The position of entry (r, c) among the values, if the pattern holds
    /// it: a symmetric tangent finds it through the node graph (the multigrid
    /// never builds its row indices), an unsymmetric one, whose rows every
    /// solver builds, by a search in column c (F-bar asks for many entries).
    pub fn slot(&self, r: usize, c: usize) -> Option<usize> {
        if self.storage == Storage::Full {
            return slot(self.matrix().symbolic(), r, c);
        }
        let lists = &self.pattern.lists;
        let (a, b) = (lists.node_of(r), lists.node_of(c));
        lists.position(self.col_ptr, (a, r), (b, c), self.storage.lowest(c))
    }
}
