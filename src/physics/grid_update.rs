//! Rules of the explicit grid update that both transfer paths apply
//! (`solver::explicit`, `solver::explicit_scatter`): local damping of the nodal
//! force, and no acceleration on nodes too light to carry one.

use crate::dim::Vector;

/// Nodes lighter than this fraction of the lightest particle get no acceleration:
/// f_I/m_I is ill-conditioned there (f_I need not vanish with m_I), while the
/// velocity p_I/m_I, a mass-weighted average of particle velocities, is always kept.
pub const TINY_MASS_FRACTION: f64 = 1e-9;

/// Local (non-viscous) damping of a nodal force: f − α |f| sign(v), component by
/// component, with sign(0) = 0.
pub fn local_damping<const D: usize>(f: &Vector<D>, v: &Vector<D>, alpha: f64) -> Vector<D> {
    let sign = |x: f64| {
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    Vector::<D>::from_fn(|d, _| f[d] - alpha * f[d].abs() * sign(v[d]))
}
