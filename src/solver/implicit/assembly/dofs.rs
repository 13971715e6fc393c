//! The unknowns of the implicit step: one per free component of each active
//! node; a tied node (`super::super::ties`) has none and follows its masters,
//! u = T ũ.

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
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dofs {
    /// index[a·D + d]: equation number, or `NONE`.
    pub index: Vec<u32>,
    pub free: usize,
    /// Per active node: its tie, if any (may be empty when no node is tied).
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
