//! The sparsity pattern of the tangent and the scatter of its terms into it.
//!
//! Every term of K couples the nodes of one particle's stencil (with F-bar, of
//! one cell's particles), so the pattern is known once the step's stencils and
//! unknowns are: node b couples to node a when some stencil (cell) holds both,
//! a tied node counting as its masters. [`Pattern::new`] builds that node graph
//! once per step ([`graph`]), and from it the compressed-column pattern of the
//! unknowns, the lower triangle for a symmetric tangent or the whole matrix
//! otherwise ([`layout`], `Pattern::csc`). Each Newton iteration then adds the
//! particles' terms straight into the value array of that pattern
//! ([`scatter`], `Pattern::add_terms`): no triplet list, no sort. The values
//! with their pattern are the [`tangent`].
//!
//! A node couples all its unknowns to all those of its neighbours: n×n blocks,
//! n the components per node that the unknowns carry (`Dofs::per_node`: D
//! displacements, then any scalar fields). A term says which of them it
//! couples ([`scatter::Coupling`]).
//!
//! The scatter runs in parallel over the columns' nodes: the task of node b
//! writes only b's columns, and it visits b's stencil entries (its own, then
//! those of nodes tied to it, in increasing entry order, so in increasing
//! particle order), so every value is the same sum in the same order for any
//! number of threads.

pub(crate) mod graph;
pub(crate) mod layout;
pub(crate) mod scatter;
pub(crate) mod tangent;

use super::Dofs;
use crate::physics::kinematics::fbar::Cells;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::scene::DirectOrdering;
use crate::solver::implicit::stress_gradient::LeastSquares;
use crate::solver::linear::node_pattern::NodeLists;
use crate::solver::linear::ordering::{node_amd, node_metis, NodeGraph};
use crate::solver::linear::Index;
use faer::sparse::SymbolicSparseColMat;
use graph::TiedSources;
use std::sync::{Arc, OnceLock};

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
        (prefix, &dofs.index, dofs.free, dofs.per_node()).hash(&mut h);
        dofs.ties.len().hash(&mut h);
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
        let (lists, tied_sources) = graph::node_lists(map, st, dofs, cells, fit, coupled);
        Pattern {
            lists: Arc::new(lists),
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
    /// factorization (computed on the node graph at the first call, whatever
    /// the unknowns per node; D, the spatial dimension, resolves `auto`).
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
}
