//! Artificial bulk viscosity for shocks (explicit solver): a viscous pressure
//! q that spreads a shock over a few cells and damps the ringing behind it
//! (von Neumann & Richtmyer 1950; the linear + quadratic form of Wilkins 1980 and
//! LS-DYNA's *CONTROL_BULK_VISCOSITY):
//!
//!   q = ρ l (C_Q l ε̇_v² − C_L c ε̇_v)  for ε̇_v = tr D < 0,  q = 0 otherwise,
//!
//! with ρ = m_p/V_p, c the particle's wave speed, l the cell size and
//! ε̇_v = tr L_p, L_p = Σ_I v_I ⊗ ∇S_Ip the velocity gradient of the grid velocity
//! at the start of the step (so a restarted run computes the same q). The force
//! uses σ − q I: f_I += Σ_p q_p V_p ∇S_Ip. q is not part of the stored stress, so
//! the constitutive models never see it. Standard coefficients: C_Q = 1.5,
//! C_L = 0.06. The stable step shrinks to l/(Q + √(Q² + c²)),
//! Q = C_L c + C_Q l |ε̇_v| (`critical_dt`).

use crate::dim::Vector;
use crate::material::Material;
use crate::model::particles::Particles;
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{gradient, NodeMap};
use rayon::prelude::*;

/// The coefficients; `None` in the solver when the scene asks for none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BulkViscosity {
    /// C_Q, the quadratic coefficient.
    pub quadratic: f64,
    /// C_L, the linear coefficient.
    pub linear: f64,
}

impl BulkViscosity {
    /// q for density ρ, wave speed c, cell size l and volumetric rate ε̇_v.
    pub fn pressure(&self, rho: f64, c: f64, l: f64, rate: f64) -> f64 {
        if rate >= 0.0 {
            return 0.0;
        }
        rho * l * (self.quadratic * l * rate * rate - self.linear * c * rate)
    }

    /// The stable step l/(Q + √(Q² + c²)) with Q = C_L c + C_Q l |ε̇_v|.
    pub fn stable_dt(&self, c: f64, l: f64, rate: f64) -> f64 {
        let q = self.linear * c + self.quadratic * l * rate.min(0.0).abs();
        l / (q + (q * q + c * c).sqrt())
    }

    /// q_p V_p of particle q at the volumetric rate `rate`, l the cell size:
    /// what its viscous pressure gives a node per unit ∇S_Ip.
    pub fn pressure_volume<const D: usize>(
        &self,
        p: &Particles<D>,
        materials: &[Box<dyn Material>],
        q: usize,
        l: f64,
        rate: f64,
    ) -> f64 {
        let material = &materials[p.material[q] as usize];
        let rho = p.mass[q] / p.volume[q];
        let c = material.wave_speed(p.f.get(q).determinant(), p.history.get(q));
        self.pressure(rho, c, l, rate) * p.volume[q]
    }

    /// ε̇_v = tr L_p of every particle under the nodal velocities `v` (in
    /// axisymmetric mode with the hoop rate v_r/r_p = Σ_I v_Ir S_Ip/r_p).
    pub fn volumetric_rates<const D: usize>(
        map: &NodeMap,
        st: &Stencils<D>,
        n: usize,
        v: &[Vector<D>],
    ) -> Vec<f64> {
        let axisymmetric = !st.hoop.is_empty();
        (0..n)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| {
                let hoop = match axisymmetric {
                    true => st
                        .range(q)
                        .map(|e| v[map.local_of(st, e)][0] * st.hoop[e])
                        .sum(),
                    false => 0.0,
                };
                gradient(map, st, q, v).trace() + hoop
            })
            .collect()
    }

    /// Adds Σ_p q_p V_p ∇S_Ip to the nodal forces; q from the nodal velocities
    /// `v` at the start of the step, l the cell size.
    #[allow(clippy::too_many_arguments)]
    pub fn add_force<const D: usize>(
        &self,
        map: &NodeMap,
        st: &Stencils<D>,
        p: &Particles<D>,
        materials: &[Box<dyn Material>],
        v: &[Vector<D>],
        l: f64,
        force: &mut [Vector<D>],
    ) {
        let rates = Self::volumetric_rates(map, st, p.len(), v);
        let qv: Vec<f64> = (0..p.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|q| self.pressure_volume(p, materials, q, l, rates[q]))
            .collect();
        // −(−q I) : ∇S V, with the hoop part q V S_Ip/r_p on the radial component.
        let viscous = map.gather(st.stride, Vector::<D>::zeros(), |q, e| {
            let mut f = st.grad(e) * qv[q];
            if let Some(h) = st.hoop.get(e) {
                f[0] += h * qv[q];
            }
            f
        });
        for (f, dv) in force.iter_mut().zip(&viscous) {
            *f += dv;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viscous_pressure_acts_in_compression_only() {
        let v = BulkViscosity {
            quadratic: 1.5,
            linear: 0.06,
        };
        assert_eq!(v.pressure(1000.0, 100.0, 0.1, 2.0), 0.0);
        // ρ l (C_Q l ε̇² + C_L c |ε̇|) = 1000·0.1·(1.5·0.1·4 + 0.06·100·2).
        let q = v.pressure(1000.0, 100.0, 0.1, -2.0);
        assert!((q - 1000.0 * 0.1 * (0.6 + 12.0)).abs() < 1e-9, "{q}");
        // Without viscosity the stable step is l/c.
        let none = BulkViscosity {
            quadratic: 0.0,
            linear: 0.0,
        };
        assert!((none.stable_dt(100.0, 0.1, -5.0) - 1e-3).abs() < 1e-15);
        assert!(v.stable_dt(100.0, 0.1, -5.0) < 1e-3);
    }
}
