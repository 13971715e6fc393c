//! The tangent of the F-bar internal force (Coombs et al. 2018, `physics::fbar`):
//! each particle follows ΔF̄_p = (ΔJ̄_c / ΔJ_p)^{1/n} ΔF_p, so it couples to the
//! nodes of every particle in its cell.

use super::pattern::slot;
use super::stiffness::{add_stiffness, indices, ParticleTangents};
use super::{Dofs, Pattern, Tangent};
use crate::dim::{Mat3, Vector};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::fbar::{scale_factor, FBarState};
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use rayon::prelude::*;

/// Adds the consistent tangent of the F-bar internal force
/// f_Ii = Σ_p V_p P̄_ij(ΔF̄_p) ∂S_Ip/∂X_j to `k` (stored whole: it is not
/// symmetric); the cell terms are added cell by cell in order (deterministic).
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
#[allow(clippy::too_many_arguments)]
pub fn add_fbar_stiffness<const D: usize>(
    k: &mut Tangent,
    pattern: &Pattern,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    state: &FBarState,
    a: &ParticleTangents<D>,
) {
    let at = ParticleTangents::<D>::at;
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
                if i >= D || j >= D {
                    return s; // A has no such components in D dimensions.
                }
                for a2 in 0..D {
                    for b in 0..D {
                        s += a.of(q)[at(i, j, a2, b)] * state.df[q][(a2, b)];
                    }
                }
                s
            })
        })
        .collect();
    let mut a_tilde = ParticleTangents::<D>::zeros(volume.len(), false);
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
    add_stiffness(k, pattern, map, st, dofs, volume, &a_tilde);

    // Adds v at `node` of a short list of (node, vector) pairs.
    fn add<const D: usize>(list: &mut Vec<(usize, Vector<D>)>, node: usize, v: Vector<D>) {
        match list.iter_mut().find(|(a, _)| *a == node) {
            Some((_, x)) => *x += v,
            None => list.push((node, v)),
        }
    }
    type Outer<const D: usize> = (Vec<(usize, Vector<D>)>, Vec<(usize, Vector<D>)>);
    let per_cell: Vec<Outer<D>> = (0..cells.len())
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
                    add(&mut a_c, map.local_of(st, e), av);
                    add(&mut h_c, map.local_of(st, e), hv);
                }
            }
            (a_c, h_c)
        })
        .collect();
    // k += a_c ⊗ h_c, spread onto the unknowns.
    for (a_c, h_c) in &per_cell {
        for (n1, av) in a_c {
            for i in 0..D {
                let rows = dofs.terms(*n1, i, D);
                for (n2, hv) in h_c {
                    for kk in 0..D {
                        for &(r, cr) in rows.as_slice() {
                            for &(c, cc) in dofs.terms(*n2, kk, D).as_slice() {
                                let s = slot(k.pattern, r, c).expect("cell entry in the pattern");
                                k.values[s] += av[i] * hv[kk] * cr * cc;
                            }
                        }
                    }
                }
            }
        }
    }
}
