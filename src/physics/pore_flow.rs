//! Darcy flow of the excess pore pressure between particles over one explicit
//! step (issue 52 item 3; docs/pore_water.md, "Coupled flow").
//!
//! The storage equation of a saturated point with incompressible grains (Biot
//! coefficient 1; Biot 1941; e.g. Verruijt, *Theory and Problems of
//! Poroelasticity*, 2016, ch. 2) with Darcy's law for the relative discharge w:
//!
//!   (1/K_f) ṗ = −∇·v_s − ∇·w,   w = −(k/γ_w) ∇p,
//!
//! K_f = K_w/n, p the excess pore pressure (over a `[water]` table's
//! hydrostatic one, which is in equilibrium with the water's weight and
//! drives no flow). After the stress update of the step (which leaves p of a
//! coupled point alone, `material::undrained`), forward Euler on the nodes of
//! the step's stencils, with a lumped storage (the weak form with test
//! function S_I; ∇·v_s Δt = Δ ln J):
//!
//!   C_I = Σ_p S_Ip V_p / K_f,p,         P_I = Σ_p S_Ip V_p p_p / K_f,p / C_I,
//!   ∇p_p = Σ_I P_I ∇S_Ip,               w_p = −(k/γ_w)_p ∇p_p,
//!   C_I ΔP_I = −Σ_p S_Ip V_p Δ ln J_p + Δt Σ_p V_p ∇S_Ip · w_p,
//!   Δp_p = Σ_I S_Ip ΔP_I   (the particles take the nodal increments).
//!
//! Both parts of the increment are interpolated from the nodes, so a particle's
//! p stays a field the grid sees: a volumetric part kept at the particle (cell
//! by cell constant for linear shapes) and a flow part interpolated from the
//! nodes would leave a sub-cell pattern that no flow removes (measured on the
//! Terzaghi column: particles of one cell 30 % of q apart). In the undrained
//! limit (k → 0) the increment is the projection of −K_f Δ ln J, a smoothed
//! undrained response.
//!
//! A drained node (`model::drainage`) has P_I = p_D in the gradient (its
//! face's `pore_pressure`, 0 by default), and its increment is the one that
//! takes its projected value there, ΔP_I = p_D − P_I (as a prescribed
//! velocity does in the velocity update). Every other
//! boundary is impermeable (the natural condition of the weak form). Only the
//! particles whose water flows (mobility > 0) take part: a dry or undrained
//! particle stores nothing and passes nothing. The particle's stored stress
//! σ′ − p I follows its new p. Stable for Δt ≤ h²/(2 D c_f), c_f = K_f k/γ_w
//! (`Drainage::stable_dt`).
//!
//! Every nodal sum gathers in particle order (`NodeMap::gather`) and every
//! particle reads only its stencil, so the result does not depend on threads.

use crate::dim::{Mat3, Vector};
use crate::material::PoreFluid;
use crate::model::Model;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{interpolate_scalar, scalar_gradient, NodeMap};
use rayon::prelude::*;

/// Per particle, its pore water if it flows (mobility > 0).
fn flowing<const D: usize>(m: &Model<D>) -> Vec<Option<PoreFluid>> {
    let fluids: Vec<Option<PoreFluid>> = (m.materials.iter())
        .map(|mat| mat.pore_fluid().filter(|f| f.mobility > 0.0))
        .collect();
    (m.particles.material.iter())
        .map(|&k| fluids[k as usize])
        .collect()
}

/// Advance the excess pore pressure of the flowing particles of m by Darcy
/// flow over Δt on the step's stencils `st` and node map `map` (module doc).
pub fn darcy_step<const D: usize>(m: &mut Model<D>, st: &Stencils<D>, map: &NodeMap, dt: f64) {
    let Some(drainage) = &m.drainage else {
        return;
    };
    let fluid = flowing(m);
    let p = &m.particles;
    // p_p, ln J_p and Δ ln J_p since the last flow update.
    let state: Vec<(f64, f64, f64)> = (0..p.len())
        .map(|q| match fluid[q] {
            Some(f) => {
                let h = p.history.get(q);
                let ln_j = p.f.get(q).determinant().ln();
                (h[f.slot], ln_j, ln_j - h[f.slot + 1])
            }
            None => (0.0, 0.0, 0.0),
        })
        .collect();
    // C_I, C_I P_I and the volumetric part −Σ S V Δ ln J (storage-weighted P2G).
    let storage = map.gather(st.stride, Vector::<3>::zeros(), |q, e| match fluid[q] {
        Some(f) => {
            let sv = st.weight_at(q, e) * p.volume[q];
            let c = sv / f.bulk_modulus;
            Vector::<3>::new(c, c * state[q].0, -sv * state[q].2)
        }
        None => Vector::<3>::zeros(),
    });
    let drained: Vec<Option<f64>> = (0..map.len())
        .map(|a| drainage.drains(&m.grid, m.grid.node_ijk(map.grid_node(a))))
        .collect();
    let projected: Vec<f64> = (storage.iter())
        .map(|c| if c[0] > 0.0 { c[1] / c[0] } else { 0.0 })
        .collect();
    let nodal: Vec<f64> = (0..map.len())
        .map(|a| drained[a].unwrap_or(projected[a]))
        .collect();
    // w_p = −(k/γ_w) Σ_I P_I ∇S_Ip.
    let discharge: Vec<Vector<D>> = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| match fluid[q] {
            Some(f) => -scalar_gradient(map, st, q, &nodal) * f.mobility,
            None => Vector::<D>::zeros(),
        })
        .collect();
    let inflow = map.gather(st.stride, 0.0, |q, e| {
        p.volume[q] * st.grad_at(q, e).dot(&discharge[q])
    });
    let increment: Vec<f64> = (0..map.len())
        .map(|a| match (drained[a], storage[a][0] > 0.0) {
            (Some(held), _) => held - projected[a],
            (None, true) => (storage[a][2] + dt * inflow[a]) / storage[a][0],
            (None, false) => 0.0,
        })
        .collect();
    let change: Vec<f64> = (0..p.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| match fluid[q] {
            Some(_) => interpolate_scalar(map, st, q, &increment),
            None => 0.0,
        })
        .collect();
    let p = &mut m.particles;
    for q in (0..p.len()).filter(|&q| fluid[q].is_some()) {
        let f = fluid[q].expect("filtered");
        let o = p.history.offset[q] as usize;
        p.history.data[o + f.slot] += change[q];
        p.history.data[o + f.slot + 1] = state[q].1;
        let stress = p.stress.get(q) - Mat3::identity() * change[q];
        p.stress.set(q, &stress);
    }
}
