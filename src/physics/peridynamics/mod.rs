//! The forces of a peridynamic body's bonds on its particles and the explicit
//! step that advances them (issue 51): each bond's pairwise force from its law
//! (`material::bond`), summed per particle over its intact bonds in the family
//! order of `model::peridynamics::bonds` (so the sums do not depend on the
//! threads), after breaking the bonds stretched past s0.

pub mod correspondence;
pub mod deformation;
pub mod energy;
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

/// This step's forces on the particles of every body of `bodies`, at their
/// step-start positions (`PdBody::begin_step`): the bond forces
/// (`bond_forces`, which breaks the bonds stretched past s0 and updates a
/// correspondence body's stresses over `dt`) and the short-range repulsion
/// (`short_range::forces`), kept for the grid (`grid_force`) and for
/// `advance`. Computed before P2G, so a body that meets continuum bodies
/// through the grid's contact brings them to its nodes.
pub fn step_forces<const D: usize>(bodies: &mut [PdBody<D>], dt: f64) {
    let repulsion = short_range::forces(bodies);
    for (b, r) in bodies.iter_mut().zip(repulsion) {
        let y = std::mem::take(&mut b.start_x);
        b.bond_force = bond_forces(b, &y, dt);
        b.start_x = y;
        b.repulsion = r;
    }
}

/// The force of body `b`'s bonds and repulsion on its particle i this step
/// (`step_forces`): what the grid's contact sees of it.
pub fn grid_force<const D: usize>(b: &PdBody<D>, i: usize) -> Vector<D> {
    match &b.repulsion {
        Some(r) => b.bond_force[i] + r[i],
        None => b.bond_force[i],
    }
}

/// Advance body `b`'s particles over Δt from the step start (`PdBody::begin_step`)
/// by central differences, v_{n+1} = v_n + Δt (f_bond + f_applied + f_short + f_contact)/m,
/// x_{n+1} = x_n + Δt v_{n+1} (thesis 2-29, 2-30 with the bond force in
/// place of the grid's), replacing what G2P gave them. The bond and
/// short-range forces are this step's (`step_forces`); `applied(q)` is the
/// applied force on global particle q (gravity and loads); `contact(q)` the
/// grid contact's force on it (`solver::explicit::contact`), if
/// the body meets continuum bodies.
pub fn advance<const D: usize>(
    b: &mut PdBody<D>,
    x: &mut [Vector<D>],
    v: &mut [Vector<D>],
    mass: &[f64],
    applied: impl Fn(usize) -> Vector<D>,
    contact: Option<&dyn Fn(usize) -> Vector<D>>,
    dt: f64,
) {
    for (i, &q) in b.particles.iter().enumerate() {
        let mut f = b.bond_force[i] + applied(q);
        if let Some(r) = (b.repulsion.as_ref())
            .map(|r| r[i])
            .filter(|r| *r != Vector::<D>::zeros())
        {
            f += r;
        }
        if let Some(c) = contact {
            f += c(q);
        }
        v[q] = b.start_v[i] + f * (dt / mass[q]);
        x[q] = b.start_x[i] + v[q] * dt;
    }
}

#[cfg(test)]
mod tests;
