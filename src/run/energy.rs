//! Energies of the particle state (history.csv, tests of energy balance).

use crate::model::Model;
use crate::parallel::deterministic_sum;

/// Kinetic energy Σ ½ m |v|².
pub fn kinetic_energy<const D: usize>(m: &Model<D>) -> f64 {
    let p = &m.particles;
    deterministic_sum(p.len(), |q| 0.5 * p.mass[q] * p.v[q].norm_squared())
}

/// Stored energy Σ V_p w_p, with the peridynamic bodies' bonds
/// (`physics::peridynamics::energy`).
pub fn strain_energy<const D: usize>(m: &Model<D>) -> f64 {
    let p = &m.particles;
    let continuum = deterministic_sum(p.len(), |q| {
        let mat = &m.materials[p.material[q] as usize];
        p.volume[q] * mat.strain_energy_density(&p.f.get(q), &p.stress.get(q), p.history.get(q))
    });
    match &m.peridynamics {
        Some(pd) => (pd.bodies.iter()).fold(continuum, |sum, b| {
            let y: Vec<_> = b.particles.iter().map(|&q| p.x[q]).collect();
            sum + crate::physics::peridynamics::energy::stored(b, &y)
        }),
        None => continuum,
    }
}
