//! The forces of a correspondence body's bonds (`material::bond::correspondence`
//! has the equations): each particle's F over its intact bonds, its stress from
//! the body's material under ΔF = F F_old⁻¹, then each intact bond's pair
//! force ω (P_i K_i⁻¹ + P_j K_j⁻¹) ξ plus the zero-energy control (weighted by
//! the same ω), summed per particle in the order of its family (`Bonds::each_intact`).

use crate::dim::{embed_deformation, restrict, Mat3, Tensor, Vector};
use crate::material::bond::correspondence::{Correspondence, FAMILY_LOST};
use crate::material::bond::pmb::Pmb;
use crate::material::Increment;
use crate::model::peridynamics::state::StressState;
use crate::model::peridynamics::PdBody;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::peridynamics::deformation::weighted_shapes;
use rayon::prelude::*;

/// The bond force on each particle of body `b` (correspondence law `law`, its
/// stress state `state`) at positions `y` (local order) over a step `dt`,
/// updating the state's F, stress and history.
pub fn forces<const D: usize>(
    b: &PdBody<D>,
    law: &Correspondence,
    state: &mut StressState,
    y: &[Vector<D>],
    dt: f64,
) -> Vec<Vector<D>> {
    let (x, v, bonds) = (&b.reference, &b.volume, &b.bonds);
    // A particle that has lost more than half its family (or whose bonds no
    // longer span the space) has no F worth the name: it takes no stress
    // update, and its bonds act as PMB bonds of the same P-wave modulus.
    let omega = |k: usize| law.weight(bonds.length[k]);
    let shape: Vec<_> = (weighted_shapes(b, y, omega).into_iter().enumerate())
        .map(|(i, s)| s.filter(|_| bonds.damage(i, v) <= FAMILY_LOST))
        .collect();
    let a = stress_update(state, &shape, dt);
    let f = |i: usize| shape[i].map(|(_, f)| f);
    let pmb = Pmb {
        horizon: law.horizon,
        micromodulus: law.micromodulus,
        critical_stretch: law.critical_stretch,
    };
    let control = law.zero_energy_control * law.micromodulus;
    (0..y.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|i| {
            bonds.gather(i, |k, j| {
                let (Some(fi), Some(fj)) = (f(i), f(j)) else {
                    return pmb.pair_force(&y[i], &y[j], bonds.length[k]) * (v[i] * v[j]);
                };
                let xi = x[j] - x[i];
                let stress = (a[i] + a[j]) * xi;
                let z = (y[j] - y[i]) - (fi + fj) * xi * 0.5;
                let dir = (y[j] - y[i]).normalize();
                let resist = dir * (control * z.dot(&dir) / bonds.length[k]);
                (stress + resist) * (omega(k) * v[i] * v[j])
            })
        })
        .collect()
}

/// Each particle's stress update under ΔF = F F_old⁻¹ (`shape`: its K⁻¹ and
/// F, None where its bonds do not span the space), in place, and its
/// A_i = P_i K_i⁻¹ with P = J σ F⁻ᵀ (0 without an F, or with det F ≤ 0).
fn stress_update<const D: usize>(
    state: &mut StressState,
    shape: &[Option<(Tensor<D>, Tensor<D>)>],
    dt: f64,
) -> Vec<Tensor<D>> {
    // The material reads the step-start history and writes the new one.
    let mut old = std::mem::take(&mut state.history_old);
    old.clone_from(&state.history);
    let (material, nh) = (state.material.as_ref(), state.n_history);
    let history_old = &old;
    let update = |i: usize, f_old: &mut Mat3, stress: &mut Mat3, h: &mut [f64]| {
        let Some((k_inv, f)) = shape[i] else {
            return Tensor::<D>::zeros();
        };
        let f3 = embed_deformation(&f);
        let j = f3.determinant();
        let (Some(f_inv), Some(f_old_inv)) = (f3.try_inverse(), f_old.try_inverse()) else {
            return Tensor::<D>::zeros();
        };
        // An inverted family (det F ≤ 0) takes no stress update and exerts none.
        if j.is_nan() || j <= 0.0 {
            return Tensor::<D>::zeros();
        }
        let old = &history_old[i * nh..(i + 1) * nh];
        let inc = Increment::new(*f_old, f3 * f_old_inv, dt, *stress, old);
        *stress = material.update(&inc, h);
        *f_old = f3;
        restrict::<D>(&(*stress * f_inv.transpose() * j)) * k_inv
    };
    let (f, stress) = (&mut state.f, &mut state.stress);
    let a = match nh {
        0 => (f.par_iter_mut().zip(stress.par_iter_mut()).enumerate())
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(i, (f, s))| update(i, f, s, &mut []))
            .collect(),
        _ => (f.par_iter_mut().zip(stress.par_iter_mut()))
            .zip(state.history.par_chunks_mut(nh))
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(i, ((f, s), h))| update(i, f, s, h))
            .collect(),
    };
    state.history_old = old;
    a
}
