//! The elastic energy stored in a peridynamic body, for history.csv's
//! `strain` (`run::energy::strain_energy`):
//! - PMB: Σ over intact bonds of ½ c s² |ξ| V_i V_j (`Pmb::bond_energy`, the
//!   potential of its pair force c s ŷ);
//! - beam: Σ over intact bonds of ½ (w(s, γ_i) + w(s, γ_j)) V_i V_j with
//!   w = ½ (c1 s² + c2 |γ|²) |ξ| (`Beam::bond_energy`), the two ends'
//!   tangential strains as the pair force takes them;
//! - correspondence: Σ_i V_i W(F_i) of its particles' material
//!   (`Material::strain_energy_density`, the same as an MPM particle's);
//!   the zero-energy control's energy is not counted, and a particle that
//!   has lost more than half its bonds (whose intact bonds then act as PMB
//!   bonds) counts W of the state it had when it stopped taking a stress
//!   update.
//!
//! Each bond is stored once, by its lower end, so each counts once; the sums
//! run in particle order (`parallel::deterministic_sum`), independent of the
//! threads.

use super::deformation;
use crate::dim::Vector;
use crate::material::bond::beam::Beam;
use crate::material::bond::BondLaw;
use crate::model::peridynamics::PdBody;
use crate::parallel::deterministic_sum;

/// The energy stored in body `b` at positions `y` (its local order).
pub fn stored<const D: usize>(b: &PdBody<D>, y: &[Vector<D>]) -> f64 {
    let (bonds, v, x) = (&b.bonds, &b.volume, &b.reference);
    let of_lower = |i: usize, w: &(dyn Fn(usize, usize) -> f64 + Sync)| -> f64 {
        let ids = bonds.first[i] as usize..bonds.first[i + 1] as usize;
        ids.filter(|&k| bonds.intact[k])
            .map(|k| {
                let j = bonds.upper[k] as usize;
                w(k, j) * v[i] * v[j]
            })
            .sum()
    };
    match &b.law {
        BondLaw::Pmb(pmb) => deterministic_sum(y.len(), |i| {
            of_lower(i, &|k, j| {
                pmb.bond_energy(bonds.stretch_between(k, i, j, y), bonds.length[k])
            })
        }),
        BondLaw::Beam(beam) => {
            let r = deformation::rotations(b, y);
            deterministic_sum(y.len(), |i| {
                of_lower(i, &|k, j| {
                    let xi = x[j] - x[i];
                    let (s, gi) = Beam::measures(&y[i], &y[j], &xi, &r[i]);
                    let (_, gj) = Beam::measures(&y[i], &y[j], &xi, &r[j]);
                    0.5 * (beam.bond_energy(s, &gi, bonds.length[k])
                        + beam.bond_energy(s, &gj, bonds.length[k]))
                })
            })
        }
        BondLaw::Correspondence(_) => {
            let Some(state) = &b.stress else { return 0.0 };
            let n = state.n_history;
            deterministic_sum(y.len(), |i| {
                let h = &state.history[i * n..(i + 1) * n];
                v[i] * state
                    .material
                    .strain_energy_density(&state.f[i], &state.stress[i], h)
            })
        }
    }
}
