//! The tangent of the internal force with a stress linear within each particle
//! domain (`solver::implicit::stress_gradient`):
//!
//!   f_I += Σ_p V_p Σ_k ∂_kP_p M_Ip,k·,  ∂_kP_p = Σ_{q∈n(p)} c_pq,k (P_q − P_p),
//!
//! so with ∂P_q/∂u_J = A_q ∇S_Jq,
//!
//!   K_IJ += Σ_q Σ_jm L_Iq,j A_q,ijlm ∂S_Jq/∂X_m,
//!   L_Iq = Σ_{p∈n(q)} V_p M_Ipᵀ c_pq − [I ∈ q's stencil] V_q M_Iqᵀ Σ_{r∈n(q)} c_qr,
//!
//! (the neighbour relation is symmetric): the stiffness of particle q with the
//! nodes of its neighbours' stencils as rows. Unsymmetric.

use super::stiffness::ParticleTangents;
use super::{Dofs, Pattern, Tangent};
use crate::dim::Vector;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::Stencils;
use crate::physics::transfer::NodeMap;
use crate::solver::implicit::stress_gradient::LinearStress;
use rayon::prelude::*;

/// Adds the linear domain stress's part of the tangent to `k` (stored whole).
#[allow(clippy::too_many_arguments)]
pub fn add_linear_stress_stiffness<const D: usize>(
    k: &mut Tangent,
    pattern: &Pattern,
    map: &NodeMap,
    st: &Stencils<D>,
    dofs: &Dofs,
    volume: &[f64],
    a: &ParticleTangents<D>,
    linear: &LinearStress<D>,
) {
    let rows = left_rows(map, st, volume, linear);
    let at = ParticleTangents::<D>::at;
    let storage = k.storage;
    pattern.add_listed_terms(&mut k.values, storage, map, st, dofs, |q, e2, out| {
        let (aq, g2) = (a.of(q), &st.grad(e2));
        for (node, l) in &rows[q] {
            let mut block = [0.0; 9];
            for i in 0..D {
                for kk in 0..D {
                    let mut v = 0.0;
                    for j in 0..D {
                        for m in 0..D {
                            v += l[j] * aq[at(i, j, kk, m)] * g2[m];
                        }
                    }
                    block[i * D + kk] = v;
                }
            }
            out.push((*node, block));
        }
    });
}

/// L_Iq of every particle q: (active node, vector), one entry per node,
/// in a fixed order.
fn left_rows<const D: usize>(
    map: &NodeMap,
    st: &Stencils<D>,
    volume: &[f64],
    linear: &LinearStress<D>,
) -> Vec<Vec<(usize, Vector<D>)>> {
    let (fit, moments) = (&linear.fit, &linear.moments);
    (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN / 16)
        .map(|q| {
            let mut rows: Vec<(usize, Vector<D>)> = Vec::new();
            let mut add =
                |node: usize, v: Vector<D>| match rows.iter_mut().find(|(n, _)| *n == node) {
                    Some((_, x)) => *x += v,
                    None => rows.push((node, v)),
                };
            for &p in fit.neighbours(q) {
                let p = p as usize;
                let c = fit.coefficient(p, q as u32);
                for e in st.range(p) {
                    add(map.local_of(st, e), moments[e].transpose() * c * volume[p]);
                }
            }
            let own: Vector<D> = fit.coefficients(q).iter().sum();
            for e in st.range(q) {
                add(
                    map.local_of(st, e),
                    -(moments[e].transpose() * own) * volume[q],
                );
            }
            rows
        })
        .collect()
}
