//! The rules of G2P at one particle, which every transfer back-end applies
//! (`solver::explicit::step`): the PIC/FLIP blend of the particle's velocity
//! and the work the applied forces do on it over the step.

use crate::dim::Vector;

/// The particle's velocity after the step: the FLIP update v + Δt a_p blended
/// with the PIC velocity v_PIC = Σ_I S_Ip v_I by the FLIP fraction (2-27).
#[inline(always)]
pub fn blend<const D: usize>(
    v: &Vector<D>,
    a: &Vector<D>,
    v_pic: &Vector<D>,
    flip: f64,
    dt: f64,
) -> Vector<D> {
    (v + a * dt) * flip + v_pic * (1.0 - flip)
}

/// The work per unit time of the applied force f over the step, by the
/// trapezoidal rule f · (v_old + v_new) / 2; the step's work is Δt times its
/// sum over the particles, in the chunks of `parallel::deterministic_sum`.
#[inline(always)]
pub fn load_power<const D: usize>(
    applied: &Vector<D>,
    v_old: &Vector<D>,
    v_new: &Vector<D>,
) -> f64 {
    applied.dot(&(v_old + v_new)) * 0.5
}
