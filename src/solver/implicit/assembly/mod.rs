//! The consistent tangent K = ∂r/∂u of the implicit step over its unknowns
//! (thesis 2-40…2-42), in the configuration at the start of the step (updated
//! Lagrangian).
//!
//! The unknowns are the free components of the active nodes ([`Dofs`]); a tied
//! node (`super::ties`) has none and enters through its masters, u = T ũ, so every
//! nodal entry is spread onto the unknowns ([`push_terms`]). Each term of K couples
//! the nodes of one particle's stencil, and [`push_stencil_pairs`] is that loop:
//! - [`stiffness`]: Σ_p V_p ∇S_Ip A_p ∇S_Jp with A_p = ∂P/∂ΔF, material (2-41)
//!   and geometric (2-42) parts;
//! - [`fbar`]: the same with F-bar, which also couples the particles of a cell;
//! - [`mass`]: the inertia M/(βΔt²) of 2-40, lumped or consistent;
//! - [`absorbing`]: the dashpots and springs of absorbing faces (2-63).

pub mod absorbing;
pub mod fbar;
pub mod mass;
pub mod stiffness;

use crate::dim::Vector;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;

/// A weakly supported node slaved to two others on a grid line through it:
/// u_a = c₀ u_m₀ + c₁ u_m₁ (linear extrapolation, so linear fields stay exact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tie {
    pub master: [usize; 2],
    pub coef: [f64; 2],
}

/// Global numbering of the unknowns: one per free component of each active node.
/// Prescribed components and the components of tied nodes have no equation.
#[derive(Clone, Debug, Default)]
pub struct Dofs {
    /// index[a·D + d]: equation number, or `NONE`.
    pub index: Vec<u32>,
    pub free: usize,
    /// Per active node: its tie, if any (empty when no node is tied).
    pub ties: Vec<Option<Tie>>,
}

/// Up to two (equation, coefficient) pairs: how one nodal component enters the
/// unknowns (one pair if free, one per free master component if tied).
#[derive(Clone, Copy, Debug)]
pub struct Terms {
    items: [(usize, f64); 2],
    len: usize,
}

impl Terms {
    pub fn as_slice(&self) -> &[(usize, f64)] {
        &self.items[..self.len]
    }
}

impl Dofs {
    pub const NONE: u32 = u32::MAX;

    /// Numbering where tied nodes (`ties[a]` is `Some`) carry no unknowns; their
    /// masters must be untied nodes.
    pub fn with_ties<const D: usize>(
        fixed: impl Iterator<Item = [bool; D]>,
        ties: Vec<Option<Tie>>,
    ) -> Dofs {
        let mut index = Vec::new();
        let mut free = 0;
        for (a, f) in fixed.enumerate() {
            let tied = ties.get(a).is_some_and(|t| t.is_some());
            for fixed_d in f {
                let unknown = !fixed_d && !tied;
                index.push(if unknown { free as u32 } else { Self::NONE });
                free += usize::from(unknown);
            }
        }
        Dofs { index, free, ties }
    }

    /// Equation of component d of node a, if it is an unknown.
    pub fn of(&self, a: usize, d: usize, dim: usize) -> Option<usize> {
        match self.index[a * dim + d] {
            Self::NONE => None,
            i => Some(i as usize),
        }
    }

    fn tie(&self, a: usize) -> Option<&Tie> {
        self.ties.get(a).and_then(|t| t.as_ref())
    }

    /// How component d of node a depends on the unknowns (u = T ũ, one row of T).
    pub fn terms(&self, a: usize, d: usize, dim: usize) -> Terms {
        let mut t = Terms {
            items: [(0, 0.0); 2],
            len: 0,
        };
        match self.tie(a) {
            None => {
                if let Some(i) = self.of(a, d, dim) {
                    t.items[0] = (i, 1.0);
                    t.len = 1;
                }
            }
            Some(tie) => {
                for (m, c) in tie.master.iter().zip(tie.coef) {
                    if let Some(i) = self.of(*m, d, dim) {
                        t.items[t.len] = (i, c);
                        t.len += 1;
                    }
                }
            }
        }
        t
    }

    /// Tᵀ r: nodal forces summed onto the unknowns (a tied node's force goes to
    /// its masters).
    pub fn reduce<const D: usize>(&self, r: &[Vector<D>]) -> Vec<f64> {
        let mut out = vec![0.0; self.free];
        for (a, ra) in r.iter().enumerate() {
            for d in 0..D {
                for &(i, c) in self.terms(a, d, D).as_slice() {
                    out[i] += c * ra[d];
                }
            }
        }
        out
    }

    /// The unknowns' current values (components that are unknowns only).
    pub fn values<const D: usize>(&self, u: &[Vector<D>]) -> Vec<f64> {
        let mut out = vec![0.0; self.free];
        for (a, ua) in u.iter().enumerate() {
            for d in 0..D {
                if let Some(i) = self.of(a, d, D) {
                    out[i] = ua[d];
                }
            }
        }
        out
    }

    /// u_free += length · du, then the tied nodes follow their masters.
    pub fn apply_correction<const D: usize>(&self, u: &mut [Vector<D>], du: &[f64], length: f64) {
        for (a, ua) in u.iter_mut().enumerate() {
            for d in 0..D {
                if let Some(i) = self.of(a, d, D) {
                    ua[d] += length * du[i];
                }
            }
        }
        self.follow_ties(u);
    }

    /// u_a = Σ c u_m for every tied node a.
    pub fn follow_ties<const D: usize>(&self, u: &mut [Vector<D>]) {
        for (a, tie) in self.ties.iter().enumerate() {
            if let Some(t) = tie {
                u[a] = u[t.master[0]] * t.coef[0] + u[t.master[1]] * t.coef[1];
            }
        }
    }
}

/// (row, column, value) entries of a sparse matrix.
pub type Triplets = Vec<(usize, usize, f64)>;

/// Adds v · T_row ⊗ T_col (v at one nodal component pair, spread onto the unknowns).
pub fn push_terms(out: &mut Triplets, rows: &Terms, cols: &Terms, v: f64) {
    for &(r, cr) in rows.as_slice() {
        for &(c, cc) in cols.as_slice() {
            out.push((r, c, v * cr * cc));
        }
    }
}

/// Which component pairs (i, k) of two nodes a term of the tangent couples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Components {
    /// Every pair: a full D×D block (stiffness).
    All,
    /// i = k only: a diagonal block (mass, dashpots, springs).
    Diagonal,
}

/// The term of one particle q: for every pair (e1, e2) of its stencil entries
/// and every component pair (i, k) that `components` couples, adds
/// `value(e1, e2, i, k)` at (node of e1, component i) × (node of e2, component k),
/// spread onto the unknowns. Pairs in the order e1, e2, i, k (deterministic);
/// `value` is not called where a row or a column has no unknown.
pub fn push_stencil_pairs<const D: usize>(
    out: &mut Triplets,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    q: usize,
    components: Components,
    value: impl Fn(usize, usize, usize, usize) -> f64,
) {
    for e1 in st.range(q) {
        let n1 = map.local_of(st, e1);
        for e2 in st.range(q) {
            let n2 = map.local_of(st, e2);
            for i in 0..D {
                let rows = dofs.terms(n1, i, D);
                if rows.as_slice().is_empty() {
                    continue;
                }
                let coupled = match components {
                    Components::All => 0..D,
                    Components::Diagonal => i..i + 1,
                };
                for k in coupled {
                    let cols = dofs.terms(n2, k, D);
                    if cols.as_slice().is_empty() {
                        continue;
                    }
                    push_terms(out, &rows, &cols, value(e1, e2, i, k));
                }
            }
        }
    }
}
