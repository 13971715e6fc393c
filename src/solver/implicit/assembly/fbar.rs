//! The tangent of the F-bar internal force (Coombs et al. 2018, `physics::kinematics::fbar`):
//! each particle follows ΔF̄_p = (ΔJ̄_c / ΔJ_p)^{1/n} ΔF_p, so it couples to the
//! nodes of every particle in its cell. Axisymmetric: n = 3 and the hoop
//! components join every contraction (`assembly::stiffness`).
//!
//! With g_q^J = ΔF_q⁻ᵀ ∇S_Jq (so ∂ΔJ_q/∂u_Jk = ΔJ_q g_qk^J) and w_q = V_q / Σ_{c} V,
//!   ∂ΔF̄_p,ab/∂u_Jk = β_p [δ_ak ∇S_Jp,b − ΔF_p,ab g_pk^J / n]
//!                   + β_p ΔF_p,ab / (n ΔJ̄_c) Σ_{q∈c} w_q ΔJ_q g_qk^J,
//! so with M_p = A_p : ΔF_p (A = ∂P/∂ΔF at ΔF̄_p) the tangent is the standard
//! one with Ã_p,ijkl = β_p (A_p,ijkl − M_p,ij (ΔF_p⁻ᵀ)_kl / n) (`scaled_tangents`),
//! plus, per cell, the outer product a_c ⊗ h_c (`cell_vectors`) of
//!   a_c(I)_i = Σ_{p∈c} V_p β_p / (n ΔJ̄_c) ∇S_Ip,j M_p,ij,
//!   h_c(J)_k = Σ_{q∈c} w_q ΔJ_q g_qk^J,
//! which couples each particle to the nodes of every particle in its cell.

use super::stiffness::{add_stiffness, indices, ParticleTangents};
use super::{Dofs, Tangent};
use crate::dim::{Mat3, Vector};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::kinematics::fbar::{scale_factor, FBarState};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use rayon::prelude::*;

/// Adds the consistent tangent of the F-bar internal force
/// f_Ii = Σ_p V_p P̄_ij(ΔF̄_p) ∂S_Ip/∂X_j to `k` (stored whole: it is not
/// symmetric): the particles' stiffness with Ã_p, then the cells' outer
/// products, cell by cell in order (deterministic).
#[allow(clippy::too_many_arguments)]
pub fn add_fbar_stiffness<const D: usize>(
    k: &mut Tangent,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    state: &FBarState,
    a: &ParticleTangents<D>,
) {
    // Axisymmetric: ΔF_θθ is scaled too (n = 3) and every sum over the gradient's
    // components gains the hoop component (θθ, with the hoop gradient h_J =
    // S_J/R on the radial displacement: ∂ΔF_θθ/∂u_Jk = δ_k0 h_J).
    let axisymmetric = !st.hoop.is_empty();
    let n = if axisymmetric { 3.0 } else { D as f64 };
    let beta = scale_factors::<D>(state, volume.len(), axisymmetric);
    let inv_t: Vec<Mat3> = (state.df.iter())
        .map(|f| f.try_inverse().unwrap_or_else(Mat3::zeros).transpose())
        .collect();
    let m = contractions(a, &state.df, volume.len(), axisymmetric);
    let a_tilde = scaled_tangents(a, &beta, &m, &inv_t, n, axisymmetric);
    add_stiffness(k, map, st, dofs, volume, &a_tilde);
    let cells = CellTerms {
        map,
        st,
        volume,
        state,
        beta: &beta,
        m: &m,
        inv_t: &inv_t,
        n,
    };
    add_cell_products(k, dofs, &cells.vectors());
}

/// β_p = (ΔJ̄_c / ΔJ_p)^{1/n} of each of the `particles`.
fn scale_factors<const D: usize>(
    state: &FBarState,
    particles: usize,
    axisymmetric: bool,
) -> Vec<f64> {
    let (cells, dj) = (&state.cells, &state.dj);
    (0..particles)
        .map(|q| {
            let (dj_bar, dj) = (state.dj_bar[cells.of[q] as usize], dj[q]);
            if axisymmetric {
                scale_factor::<3>(dj_bar, dj)
            } else {
                scale_factor::<D>(dj_bar, dj)
            }
        })
        .collect()
}

/// M_p,ij = Σ_{a,b<D} A_p,ijab ΔF_p,ab (+ A_p,ijθθ ΔF_p,θθ axisymmetric), for
/// i, j < D and (axisymmetric) ij = θθ, of each of the `particles`.
fn contractions<const D: usize>(
    a: &ParticleTangents<D>,
    df: &[Mat3],
    particles: usize,
    axisymmetric: bool,
) -> Vec<Mat3> {
    let at = ParticleTangents::<D>::at;
    (0..particles)
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| {
            let (aq, hq, df) = (a.of(q), a.hoop_of(q), &df[q]);
            Mat3::from_fn(|i, j| {
                let mut s = 0.0;
                if i < D && j < D {
                    for a2 in 0..D {
                        for b in 0..D {
                            s += aq[at(i, j, a2, b)] * df[(a2, b)];
                        }
                    }
                    if axisymmetric {
                        s += hq[D * D + i * D + j] * df[(2, 2)];
                    }
                } else if axisymmetric && i == 2 && j == 2 {
                    for a2 in 0..D {
                        for b in 0..D {
                            s += hq[a2 * D + b] * df[(a2, b)];
                        }
                    }
                    s += hq[2 * D * D] * df[(2, 2)];
                }
                // Otherwise A has no such components in D dimensions.
                s
            })
        })
        .collect()
}

/// Ã_p,ijkl = β_p (A_p,ijkl − M_p,ij (ΔF_p⁻ᵀ)_kl / n); axisymmetric also
/// Ã_θθkl, Ã_ijθθ and Ã_θθθθ by the same rule.
fn scaled_tangents<const D: usize>(
    a: &ParticleTangents<D>,
    beta: &[f64],
    m: &[Mat3],
    inv_t: &[Mat3],
    n: f64,
    axisymmetric: bool,
) -> ParticleTangents<D> {
    let mut a_tilde = ParticleTangents::<D>::zeros(beta.len(), axisymmetric);
    a_tilde
        .values
        .par_chunks_mut(ParticleTangents::<D>::LEN)
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN)
        .for_each(|(q, out)| {
            for (n_ijkl, (i, j, k, l)) in indices::<D>().enumerate() {
                let local = m[q][(i, j)] * inv_t[q][(k, l)] / n;
                out[n_ijkl] = beta[q] * (a.of(q)[n_ijkl] - local);
            }
        });
    if axisymmetric {
        a_tilde
            .hoop
            .par_chunks_mut(ParticleTangents::<D>::HOOP_LEN)
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(q, out)| {
                let (hq, g) = (a.hoop_of(q), &inv_t[q]);
                for k in 0..D {
                    for l in 0..D {
                        out[k * D + l] = beta[q] * (hq[k * D + l] - m[q][(2, 2)] * g[(k, l)] / n);
                        out[D * D + k * D + l] =
                            beta[q] * (hq[D * D + k * D + l] - m[q][(k, l)] * g[(2, 2)] / n);
                    }
                }
                out[2 * D * D] = beta[q] * (hq[2 * D * D] - m[q][(2, 2)] * g[(2, 2)] / n);
            });
    }
    a_tilde
}

/// The vectors a_c and h_c of one cell, as (active node, vector) lists.
type CellVectors<const D: usize> = (Vec<(usize, Vector<D>)>, Vec<(usize, Vector<D>)>);

/// What the cells' outer products are formed from.
struct CellTerms<'a, const D: usize> {
    map: &'a NodeMap,
    st: &'a Stencils<D>,
    volume: &'a [f64],
    state: &'a FBarState,
    beta: &'a [f64],
    m: &'a [Mat3],
    inv_t: &'a [Mat3],
    n: f64,
}

impl<const D: usize> CellTerms<'_, D> {
    /// a_c and h_c of every occupied cell.
    fn vectors(&self) -> Vec<CellVectors<D>> {
        let (cells, axisymmetric) = (&self.state.cells, !self.st.hoop.is_empty());
        let (map, st, volume, n) = (self.map, self.st, self.volume, self.n);
        let (m, inv_t, dj) = (self.m, self.inv_t, &self.state.dj);
        (0..cells.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN / 16)
            .map(|c| {
                let members = cells.members(c);
                let v_cell: f64 = members.iter().map(|&q| volume[q as usize]).sum();
                let dj_bar = self.state.dj_bar[c];
                let mut a_c: Vec<(usize, Vector<D>)> = Vec::new();
                let mut h_c: Vec<(usize, Vector<D>)> = Vec::new();
                for &q in members {
                    let q = q as usize;
                    let coef_a = volume[q] * self.beta[q] / (n * dj_bar);
                    let coef_h = volume[q] / v_cell * dj[q];
                    for e in st.range(q) {
                        let grad = &st.grad(e);
                        let hoop = st.hoop.get(e).copied().unwrap_or(0.0);
                        let av = Vector::<D>::from_fn(|i, _| {
                            let mut s: f64 = (0..D).map(|j| grad[j] * m[q][(i, j)]).sum();
                            if axisymmetric && i == 0 {
                                s += hoop * m[q][(2, 2)];
                            }
                            s * coef_a
                        });
                        let hv = Vector::<D>::from_fn(|k, _| {
                            let mut s: f64 = (0..D).map(|l| inv_t[q][(k, l)] * grad[l]).sum();
                            if axisymmetric && k == 0 {
                                s += inv_t[q][(2, 2)] * hoop;
                            }
                            s * coef_h
                        });
                        add_at(&mut a_c, map.local_of(st, e), av);
                        add_at(&mut h_c, map.local_of(st, e), hv);
                    }
                }
                (a_c, h_c)
            })
            .collect()
    }
}

/// Adds v at `node` of a short list of (node, vector) pairs.
fn add_at<const D: usize>(list: &mut Vec<(usize, Vector<D>)>, node: usize, v: Vector<D>) {
    match list.iter_mut().find(|(a, _)| *a == node) {
        Some((_, x)) => *x += v,
        None => list.push((node, v)),
    }
}

/// k += a_c ⊗ h_c of every cell, in order, spread onto the unknowns.
fn add_cell_products<const D: usize>(k: &mut Tangent, dofs: &Dofs, per_cell: &[CellVectors<D>]) {
    for (a_c, h_c) in per_cell {
        for (n1, av) in a_c {
            for i in 0..D {
                let rows = dofs.terms(*n1, i);
                for (n2, hv) in h_c {
                    for kk in 0..D {
                        for &(r, cr) in rows.as_slice() {
                            for &(c, cc) in dofs.terms(*n2, kk).as_slice() {
                                let s = k.slot(r, c).expect("cell entry in the pattern");
                                k.values[s] += av[i] * hv[kk] * cr * cc;
                            }
                        }
                    }
                }
            }
        }
    }
}
