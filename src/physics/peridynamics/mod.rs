//! The forces of a peridynamic body's bonds on its particles and the explicit
//! step that advances them (issue 51): each bond's pairwise force from its law
//! (`material::bond`), summed per particle over its intact bonds in the family
//! order of `model::peridynamics::bonds` (so the sums do not depend on the
//! threads), after breaking the bonds stretched past s0.

pub mod correspondence;
pub mod deformation;
pub mod short_range;

use crate::dim::Vector;
use crate::material::bond::BondLaw;
use crate::model::peridynamics::PdBody;
use crate::parallel::MIN_PARALLEL_LEN;
use rayon::prelude::*;

/// The bond force on each particle of body `b` (V_i Σ_j f_ij V_j, f_ij its
/// law's pair force) at positions `y` (its local order), after breaking the bonds
/// stretched past s0. The beam law first finds each particle's rotation
/// (`deformation::rotations`, over the bonds left intact); the correspondence
/// law updates its particles' stresses over the step `dt` (`correspondence`).
pub fn bond_forces<const D: usize>(b: &mut PdBody<D>, y: &[Vector<D>], dt: f64) -> Vec<Vector<D>> {
    b.bonds.break_stretched(y, b.law.critical_stretch());
    let (bonds, v, x) = (&b.bonds, &b.volume, &b.reference);
    let sum = |force: &(dyn Fn(usize, usize, usize) -> Vector<D> + Sync)| -> Vec<Vector<D>> {
        (0..y.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|i| bonds.gather(i, |k, j| force(i, j, k) * (v[i] * v[j])))
            .collect()
    };
    match &b.law {
        BondLaw::Pmb(pmb) => sum(&|i, j, k| pmb.pair_force(&y[i], &y[j], bonds.length[k])),
        BondLaw::Beam(beam) => {
            let r = deformation::rotations(b, y);
            sum(&|i, j, _| beam.pair_force(&y[i], &y[j], &(x[j] - x[i]), &r[i], &r[j]))
        }
        BondLaw::Correspondence(law) => {
            let law = *law;
            let mut state = b
                .stress
                .take()
                .expect("a correspondence body has a stress state");
            let f = correspondence::forces(b, &law, &mut state, y, dt);
            b.stress = Some(state);
            f
        }
    }
}

/// Advance body `b`'s particles over Δt from the step start (`PdBody::begin_step`)
/// by central differences, v_{n+1} = v_n + Δt (f_bond + f_applied + f_short)/m,
/// x_{n+1} = x_n + Δt v_{n+1} (thesis 2-29, 2-30 with the bond force in
/// place of the grid's), replacing what G2P gave them. `applied(q)` is the
/// applied force on global particle q (gravity and loads); `repulsion` the
/// short-range force on each of its particles (`short_range::forces`), if any
/// is pressed.
pub fn advance<const D: usize>(
    b: &mut PdBody<D>,
    x: &mut [Vector<D>],
    v: &mut [Vector<D>],
    mass: &[f64],
    applied: impl Fn(usize) -> Vector<D>,
    repulsion: Option<&[Vector<D>]>,
    dt: f64,
) {
    let y = std::mem::take(&mut b.start_x);
    let bond = bond_forces(b, &y, dt);
    for (i, &q) in b.particles.iter().enumerate() {
        let mut f = bond[i] + applied(q);
        if let Some(r) = repulsion
            .map(|r| r[i])
            .filter(|r| *r != Vector::<D>::zeros())
        {
            f += r;
        }
        v[q] = b.start_v[i] + f * (dt / mass[q]);
        x[q] = y[i] + v[q] * dt;
    }
    b.start_x = y;
}

#[cfg(test)]
mod tests;
