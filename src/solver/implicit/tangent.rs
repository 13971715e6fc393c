//! Internal force and consistent tangent of the implicit step, in the
//! configuration at the start of the step (updated Lagrangian).
//!
//! With ΔF_p = I + Σ_I u_I ⊗ ∇S_Ip (gradients at the step-start positions) and the
//! relative first Piola-Kirchhoff stress P = J σ ΔF⁻ᵀ (J = det ΔF), the internal
//! force is f_Ii = Σ_p V_p P_ij ∂S_Ip/∂X_j (thesis 2-21 pulled back), and its
//! derivative is K_(Ii)(Jk) = Σ_p V_p ∂S_Ip/∂X_j A_ijkl ∂S_Jp/∂X_l with
//! A = ∂P/∂ΔF. A holds both the material part (from the exact derivative of the
//! stress update, 2-41) and the geometric part (2-42).

use crate::dim::{restrict, Mat3, Tensor, Vector};
use crate::material::StressDerivative;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::absorbing::AbsorbingStep;
use crate::physics::fbar::{scale_factor, FBarState};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use nalgebra::SMatrix;
use rayon::prelude::*;

/// ∂P_ij/∂ΔF_kl, row 3i + j, column 3k + l.
pub type Pk1Derivative = SMatrix<f64, 9, 9>;

/// P = J σ ΔF⁻ᵀ.
pub fn relative_pk1(df: &Mat3, sigma: &Mat3) -> Mat3 {
    let inv_t = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    sigma * inv_t * df.determinant()
}

/// A_ijkl = ∂P_ij/∂ΔF_kl = J [G_kl (σG)_ij + (∂σ_im/∂ΔF_kl) G_mj − (σG)_il G_kj],
/// G = ΔF⁻ᵀ (from ∂J/∂ΔF = J G and ∂G_mj/∂ΔF_kl = −G_ml G_kj).
pub fn pk1_derivative(df: &Mat3, sigma: &Mat3, dsigma: &StressDerivative) -> Pk1Derivative {
    let j = df.determinant();
    let g = df.try_inverse().unwrap_or_else(Mat3::zeros).transpose();
    let sg = sigma * g;
    Pk1Derivative::from_fn(|row, col| {
        let (i, jj, k, l) = (row / 3, row % 3, col / 3, col % 3);
        let material: f64 = (0..3).map(|m| dsigma[(3 * i + m, col)] * g[(m, jj)]).sum();
        j * (g[(k, l)] * sg[(i, jj)] + material - sg[(i, l)] * g[(k, jj)])
    })
}

/// Internal force at the active nodes: f_I = Σ_p V_p P_p ∇S_Ip.
pub fn internal_force<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    pk1: &[Mat3],
) -> Vec<Vector<D>> {
    map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
        let p: Tensor<D> = restrict::<D>(&pk1[q]);
        p * st.grad[e] * volume[q]
    })
}

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

    pub fn new<const D: usize>(fixed: impl Iterator<Item = [bool; D]>) -> Dofs {
        Self::with_ties(fixed, Vec::new())
    }

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

/// Triplets of Σ_p V_p ∇S_I A_p ∇S_J over the free unknowns, particle by particle
/// in order (deterministic). Also reports whether every A_p has major symmetry
/// (A_ijkl = A_klij), i.e. whether the assembled matrix is symmetric.
pub fn stiffness_triplets<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    a: &[Pk1Derivative],
) -> (Triplets, bool) {
    let per_particle: Vec<(Triplets, bool)> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 8)
        .map(|q| {
            let ap = &a[q];
            let symmetric =
                (ap - ap.transpose()).amax() <= 1e-10 * ap.amax().max(f64::MIN_POSITIVE);
            let mut out = Vec::new();
            for e1 in st.range(q) {
                let n1 = map.local[st.node[e1] as usize] as usize;
                for e2 in st.range(q) {
                    let n2 = map.local[st.node[e2] as usize] as usize;
                    for i in 0..D {
                        let rows = dofs.terms(n1, i, D);
                        if rows.as_slice().is_empty() {
                            continue;
                        }
                        for k in 0..D {
                            let cols = dofs.terms(n2, k, D);
                            if cols.as_slice().is_empty() {
                                continue;
                            }
                            let mut v = 0.0;
                            for j in 0..D {
                                for l in 0..D {
                                    v += st.grad[e1][j]
                                        * ap[(3 * i + j, 3 * k + l)]
                                        * st.grad[e2][l];
                                }
                            }
                            push_terms(&mut out, &rows, &cols, v * volume[q]);
                        }
                    }
                }
            }
            (out, symmetric)
        })
        .collect();
    let symmetric = per_particle.iter().all(|(_, s)| *s);
    (
        per_particle.into_iter().flat_map(|(t, _)| t).collect(),
        symmetric,
    )
}

/// Adds v · T_row ⊗ T_col (v at one nodal component pair, spread onto the unknowns).
pub fn push_terms(out: &mut Triplets, rows: &Terms, cols: &Terms, v: f64) {
    for &(r, cr) in rows.as_slice() {
        for &(c, cc) in cols.as_slice() {
            out.push((r, c, v * cr * cc));
        }
    }
}

/// Consistent tangent of the F-bar internal force f_Ii = Σ_p V_p P̄_ij(ΔF̄_p) ∂S_Ip/∂X_j
/// over the free unknowns (particles in order, then cells in order: deterministic).
///
/// With g_q^J = ΔF_q⁻ᵀ ∇S_Jq (so ∂ΔJ_q/∂u_Jk = ΔJ_q g_qk^J) and w_q = V_q / Σ_{c} V,
///   ∂ΔF̄_p,ab/∂u_Jk = β_p [δ_ak ∇S_Jp,b − ΔF_p,ab g_pk^J / n]
///                   + β_p ΔF_p,ab / (n ΔJ̄_c) Σ_{q∈c} w_q ΔJ_q g_qk^J,
/// so with M_p = A_p : ΔF_p (A = ∂P/∂ΔF at ΔF̄_p) the tangent is the standard
/// one with Ã_p,ijkl = β_p (A_p,ijkl − M_p,ij (ΔF_p⁻ᵀ)_kl / n), plus, per cell, the
/// outer product a_c ⊗ h_c of
///   a_c(I)_i = Σ_{p∈c} V_p β_p / (n ΔJ̄_c) ∇S_Ip,j M_p,ij,
///   h_c(J)_k = Σ_{q∈c} w_q ΔJ_q g_qk^J,
/// which couples each particle to the nodes of every particle in its cell.
pub fn fbar_triplets<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    state: &FBarState,
    a: &[Pk1Derivative],
) -> Triplets {
    let n = D as f64;
    let cells = &state.cells;
    let dj = &state.dj;
    let beta: Vec<f64> = (0..volume.len())
        .map(|q| scale_factor::<D>(state.dj_bar[cells.of[q] as usize], dj[q]))
        .collect();
    let inv_t: Vec<Mat3> = state
        .df
        .iter()
        .map(|f| f.try_inverse().unwrap_or_else(Mat3::zeros).transpose())
        .collect();
    // M_p,ij = Σ_{a,b<D} A_p,ijab ΔF_p,ab.
    let m: Vec<Mat3> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            Mat3::from_fn(|i, j| {
                let mut s = 0.0;
                for a2 in 0..D {
                    for b in 0..D {
                        s += a[q][(3 * i + j, 3 * a2 + b)] * state.df[q][(a2, b)];
                    }
                }
                s
            })
        })
        .collect();
    let a_tilde: Vec<Pk1Derivative> = (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            Pk1Derivative::from_fn(|row, col| {
                let (i, j, k, l) = (row / 3, row % 3, col / 3, col % 3);
                let local = if k < D && l < D {
                    m[q][(i, j)] * inv_t[q][(k, l)] / n
                } else {
                    0.0
                };
                beta[q] * (a[q][(row, col)] - local)
            })
        })
        .collect();
    let (mut triplets, _) = stiffness_triplets(map, st, dofs, volume, &a_tilde);

    let node = |e: usize| map.local[st.node[e] as usize] as usize;
    // Adds v at `node` of a short list of (node, vector) pairs.
    fn add<const D: usize>(list: &mut Vec<(usize, Vector<D>)>, node: usize, v: Vector<D>) {
        match list.iter_mut().find(|(a, _)| *a == node) {
            Some((_, x)) => *x += v,
            None => list.push((node, v)),
        }
    }
    let per_cell: Vec<Triplets> = (0..cells.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 16)
        .map(|c| {
            let members = cells.members(c);
            let v_cell: f64 = members.iter().map(|&q| volume[q as usize]).sum();
            let dj_bar = state.dj_bar[c];
            let mut a_c: Vec<(usize, Vector<D>)> = Vec::new();
            let mut h_c: Vec<(usize, Vector<D>)> = Vec::new();
            for &q in members {
                let q = q as usize;
                let coef_a = volume[q] * beta[q] / (n * dj_bar);
                let coef_h = volume[q] / v_cell * dj[q];
                for e in st.range(q) {
                    let grad = &st.grad[e];
                    let av = Vector::<D>::from_fn(|i, _| {
                        (0..D).map(|j| grad[j] * m[q][(i, j)]).sum::<f64>() * coef_a
                    });
                    let hv = Vector::<D>::from_fn(|k, _| {
                        (0..D).map(|l| inv_t[q][(k, l)] * grad[l]).sum::<f64>() * coef_h
                    });
                    add(&mut a_c, node(e), av);
                    add(&mut h_c, node(e), hv);
                }
            }
            let mut out = Triplets::new();
            for (n1, av) in &a_c {
                for i in 0..D {
                    let rows = dofs.terms(*n1, i, D);
                    if rows.as_slice().is_empty() {
                        continue;
                    }
                    for (n2, hv) in &h_c {
                        for k in 0..D {
                            let cols = dofs.terms(*n2, k, D);
                            push_terms(&mut out, &rows, &cols, av[i] * hv[k]);
                        }
                    }
                }
            }
            out
        })
        .collect();
    triplets.extend(per_cell.into_iter().flatten());
    triplets
}

/// Tangent of `AbsorbingStep::add_residual`: Σ_p S_Ip S_Jp (rate C_p + K_p),
/// diagonal in the components, onto the unknowns (tied nodes through their
/// masters; symmetric, positive semi-definite).
pub fn absorbing_triplets<const D: usize>(
    step: &AbsorbingStep<D>,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    t: &mut Triplets,
) {
    for lp in &step.layer {
        let coefficient = lp.damping * step.rate + lp.stiffness;
        for e1 in st.range(lp.q) {
            let n1 = map.local[st.node[e1] as usize] as usize;
            for e2 in st.range(lp.q) {
                let n2 = map.local[st.node[e2] as usize] as usize;
                let w = st.weight[e1] * st.weight[e2];
                for d in 0..D {
                    let (rows, cols) = (dofs.terms(n1, d, D), dofs.terms(n2, d, D));
                    push_terms(t, &rows, &cols, w * coefficient[d]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::neo_hookean::NeoHookean;
    use crate::material::{Increment, Material};

    /// A = ∂P/∂ΔF against central differences of P(ΔF) = J σ(ΔF) ΔF⁻ᵀ.
    #[test]
    fn pk1_derivative_matches_finite_differences() {
        let m = NeoHookean::new(1000.0, 1.0e6, 0.3);
        let f_old = Mat3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.02);
        let df = Mat3::new(1.02, 0.05, 0.01, -0.03, 0.97, 0.02, 0.01, -0.02, 1.01);
        let stress_old = m.cauchy(&f_old);
        let pk1 = |df: &Mat3| {
            let inc = Increment {
                f_old,
                df: *df,
                dt: 0.0,
                stress_old,
                history_old: &[],
            };
            relative_pk1(df, &m.update(&inc, &mut []))
        };
        let inc = Increment {
            f_old,
            df,
            dt: 0.0,
            stress_old,
            history_old: &[],
        };
        let a = pk1_derivative(
            &df,
            &m.update(&inc, &mut []),
            &m.stress_derivative(&inc).unwrap(),
        );
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for col in 0..9 {
            let mut dp = df;
            let mut dm = df;
            dp[(col / 3, col % 3)] += h;
            dm[(col / 3, col % 3)] -= h;
            let fd = (pk1(&dp) - pk1(&dm)) / (2.0 * h);
            for row in 0..9 {
                worst = worst.max((fd[(row / 3, row % 3)] - a[(row, col)]).abs());
            }
        }
        assert!(
            worst < 1e-6 * a.amax(),
            "max |A − A_fd| = {worst:.3e} (scale {:.3e})",
            a.amax()
        );
    }
}
