//! The unknowns of the implicit step: one per free component of each active
//! node; a tied node (`super::super::ties`) has none and follows its masters,
//! u = T ũ, in every component.
//!
//! A node carries `per_node` components, which the problem gives: the D
//! displacement components 0..D, then any further scalar fields (a pore
//! pressure would be component D). The numbering, the ties and the nodal
//! reductions below read only `per_node`; which components a term of the
//! tangent couples is said by the term (`super::pattern::Coupling`).

use crate::dim::Vector;

/// A weakly supported node slaved to two others on a grid line through it:
/// u_a = c₀ u_m₀ + c₁ u_m₁ (linear extrapolation, so linear fields stay exact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tie {
    pub master: [usize; 2],
    pub coef: [f64; 2],
}

/// Global numbering of the unknowns: one per free component of each active node.
/// Prescribed components and the components of tied nodes have no equation.
/// Unknowns are numbered node by node, a node's in the order of its components.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dofs {
    /// index[a·n + c] (n = `per_node`): equation number of component c of
    /// node a, or `NONE`.
    pub index: Vec<u32>,
    pub free: usize,
    /// Per active node: its tie, if any (may be empty when no node is tied).
    pub ties: Vec<Option<Tie>>,
    /// Components per node n: D displacements, then the scalar fields.
    per_node: usize,
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

/// The nodes that one node's terms go to ([`Dofs::owners`]): itself with
/// coefficient 1, or the two masters of its tie with theirs. (A plain struct:
/// it is built for every stencil entry of every assembly.)
pub struct Owners<'a> {
    node: usize,
    tie: Option<&'a Tie>,
    next: usize,
}

impl Iterator for Owners<'_> {
    type Item = (usize, f64);

    fn next(&mut self) -> Option<(usize, f64)> {
        let i = self.next;
        self.next += 1;
        match self.tie {
            None if i == 0 => Some((self.node, 1.0)),
            Some(t) if i < 2 => Some((t.master[i], t.coef[i])),
            _ => None,
        }
    }
}

impl Dofs {
    pub const NONE: u32 = u32::MAX;

    /// Numbering of nodes of N components (`fixed`: which are prescribed, per
    /// active node), where tied nodes (`ties[a]` is `Some`) carry no unknowns;
    /// their masters must be untied nodes.
    pub fn with_ties<const N: usize>(
        fixed: impl Iterator<Item = [bool; N]>,
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
        Dofs {
            index,
            free,
            ties,
            per_node: N,
        }
    }

    /// Components per node: D displacements, then the scalar fields.
    pub fn per_node(&self) -> usize {
        self.per_node
    }

    /// Equation of component c of node a, if it is an unknown.
    pub fn of(&self, a: usize, c: usize) -> Option<usize> {
        debug_assert!(c < self.per_node, "component {c} of {}", self.per_node);
        Self::equation(self.index[a * self.per_node + c])
    }

    /// The equations of the N components `first..first + N` of node a, if
    /// they are unknowns (one look-up for a block of components).
    pub fn block<const N: usize>(&self, a: usize, first: usize) -> [Option<usize>; N] {
        debug_assert!(
            first + N <= self.per_node,
            "components {first}.. of {}",
            self.per_node
        );
        let at = a * self.per_node + first;
        let index: &[u32; N] = self.index[at..at + N].try_into().expect("N components");
        index.map(Self::equation)
    }

    /// The equation of an entry of `index`, if it is an unknown.
    fn equation(i: u32) -> Option<usize> {
        match i {
            Self::NONE => None,
            i => Some(i as usize),
        }
    }

    /// The nodes whose unknowns node a's terms go to, with their coefficients:
    /// a itself, or its masters if it is tied.
    pub fn owners(&self, a: usize) -> Owners<'_> {
        Owners {
            node: a,
            tie: self.tie(a),
            next: 0,
        }
    }

    fn tie(&self, a: usize) -> Option<&Tie> {
        self.ties.get(a).and_then(|t| t.as_ref())
    }

    /// How component c of node a depends on the unknowns (u = T ũ, one row of T).
    pub fn terms(&self, a: usize, c: usize) -> Terms {
        let mut t = Terms {
            items: [(0, 0.0); 2],
            len: 0,
        };
        match self.tie(a) {
            None => {
                if let Some(i) = self.of(a, c) {
                    t.items[0] = (i, 1.0);
                    t.len = 1;
                }
            }
            Some(tie) => {
                for (m, coef) in tie.master.iter().zip(tie.coef) {
                    if let Some(i) = self.of(*m, c) {
                        t.items[t.len] = (i, coef);
                        t.len += 1;
                    }
                }
            }
        }
        t
    }

    /// Tᵀ r: nodal residuals (N = `per_node` components a node) summed onto
    /// the unknowns (a tied node's goes to its masters).
    pub fn reduce<const N: usize>(&self, r: &[Vector<N>]) -> Vec<f64> {
        self.check_components(N);
        let mut out = vec![0.0; self.free];
        for (a, ra) in r.iter().enumerate() {
            for d in 0..N {
                for &(i, c) in self.terms(a, d).as_slice() {
                    out[i] += c * ra[d];
                }
            }
        }
        out
    }

    /// The unknowns' current values (components that are unknowns only).
    pub fn values<const N: usize>(&self, u: &[Vector<N>]) -> Vec<f64> {
        self.check_components(N);
        let mut out = vec![0.0; self.free];
        for (a, ua) in u.iter().enumerate() {
            for d in 0..N {
                if let Some(i) = self.of(a, d) {
                    out[i] = ua[d];
                }
            }
        }
        out
    }

    /// u_free += length · du, then the tied nodes follow their masters.
    pub fn apply_correction<const N: usize>(&self, u: &mut [Vector<N>], du: &[f64], length: f64) {
        self.check_components(N);
        for (a, ua) in u.iter_mut().enumerate() {
            for d in 0..N {
                if let Some(i) = self.of(a, d) {
                    ua[d] += length * du[i];
                }
            }
        }
        self.follow_ties(u);
    }

    /// Nodal arrays of `n` components a node are this numbering's (any
    /// when there are no nodes).
    fn check_components(&self, n: usize) {
        let per_node = self.per_node;
        assert!(
            n == per_node || self.index.is_empty(),
            "nodal values of {n} components, nodes of {per_node}"
        );
    }

    /// u_a = Σ c u_m for every tied node a (all its components).
    pub fn follow_ties<const N: usize>(&self, u: &mut [Vector<N>]) {
        self.check_components(N);
        for (a, tie) in self.ties.iter().enumerate() {
            if let Some(t) = tie {
                u[a] = u[t.master[0]] * t.coef[0] + u[t.master[1]] * t.coef[1];
            }
        }
    }
}
