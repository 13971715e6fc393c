//! The prototype microelastic brittle (PMB) bond of bond-based peridynamics
//! (Silling 2000; Silling & Askari 2005): pairwise force f = c s ŷ per unit
//! volume squared (constant influence), with s = (|y_j − y_i| − |ξ|)/|ξ| the
//! bond stretch and ŷ the unit vector from i to j in the current configuration;
//! the bond breaks for good when s > s0.
//!
//! Micromoduli from strain-energy equivalence (survey-peridynamics.md §2.1,
//! checked there against LAMMPS, Peridigm, PeriLab; digest Part 2 §2.2 for plane
//! stress), with h the thickness. In 2D this code works per unit thickness, as
//! every 2D quantity of the model (volumes are areas, masses per unit
//! thickness): h = 1, and since c V_j ∝ 1/h · h the thickness cancels from the
//! motion, so there is no thickness key (survey §6: Peridigm #381).
//!
//! | space        | c               | ν   | s0 from G0        |
//! |--------------|-----------------|-----|-------------------|
//! | 3D           | 18K/(πδ⁴)       | 1/4 | √(5G0/(9Kδ))      |
//! | plane stress | 9E/(πhδ³)       | 1/3 | √(4πG0/(9Eδ))     |
//! | plane strain | 48E/(5πhδ³)     | 1/4 | √(5πG0/(12Eδ))    |
//!
//! s0 from G0 = energy of the bonds cut by a crack per unit area, each bond
//! storing c s0² |ξ|/2 per unit volume squared: 3D G0 = πcs0²δ⁵/10; 2D
//! G0 = c h s0² δ⁴/4 (= 2∫₀^δ∫_z^δ∫₀^{acos(z/ξ)} (c s0² ξ/2) h ξ dθ dξ dz),
//! which with the c of each plane gives the 2D forms (survey §2.2, derived
//! there and again here).

use super::space::{critical_stretch, Space};
use crate::dim::Vector;
use std::f64::consts::PI;

/// A body's PMB constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pmb {
    /// Horizon δ.
    pub horizon: f64,
    /// Micromodulus c.
    pub micromodulus: f64,
    /// Critical stretch s0 (infinite: no fracture).
    pub critical_stretch: f64,
}

impl Pmb {
    /// The constants of Young's modulus `e` (ν the space's) and horizon δ.
    pub fn new(space: Space, e: f64, delta: f64) -> Pmb {
        let c = match space {
            // 18K/(πδ⁴), K = E/(3(1 − 2ν)) = 2E/3 at ν = 1/4.
            Space::ThreeD => 18.0 * bulk_modulus(e) / (PI * delta.powi(4)),
            Space::PlaneStress => 9.0 * e / (PI * delta.powi(3)),
            Space::PlaneStrain => 48.0 * e / (5.0 * PI * delta.powi(3)),
        };
        Pmb {
            horizon: delta,
            micromodulus: c,
            critical_stretch: f64::INFINITY,
        }
    }

    /// With the critical stretch of fracture energy G0 (module table;
    /// `super::critical_stretch`).
    pub fn with_fracture_energy(self, space: Space, g0: f64) -> Pmb {
        self.with_critical_stretch(critical_stretch(space, self.micromodulus, self.horizon, g0))
    }

    pub fn with_critical_stretch(self, s0: f64) -> Pmb {
        Pmb {
            critical_stretch: s0,
            ..self
        }
    }

    /// f = c s ŷ (per unit volume squared) of the bond from y_i to y_j of
    /// reference length |ξ|.
    #[inline]
    pub fn pair_force<const D: usize>(
        &self,
        yi: &Vector<D>,
        yj: &Vector<D>,
        length: f64,
    ) -> Vector<D> {
        let d = yj - yi;
        let l = d.norm();
        let s = (l - length) / length;
        d * (self.micromodulus * s / l)
    }

    /// Energy c s² |ξ| / 2 per unit volume squared of a bond at stretch s.
    pub fn bond_energy(&self, s: f64, length: f64) -> f64 {
        0.5 * self.micromodulus * s * s * length
    }
}

/// K = E/(3(1 − 2ν)) at the PMB ν = 1/4.
fn bulk_modulus(e: f64) -> f64 {
    e / (3.0 * (1.0 - 2.0 * 0.25))
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: f64 = 70e9;

    #[test]
    fn the_2d_and_3d_critical_stretches_invert_their_fracture_energies() {
        let (g0, d) = (20e3, 3e-3);
        // G0 = c h s0² δ⁴/4 (2D, h = 1) and π c s0² δ⁵/10 (3D).
        for space in [Space::PlaneStress, Space::PlaneStrain] {
            let p = Pmb::new(space, E, d).with_fracture_energy(space, g0);
            let g = p.micromodulus * p.critical_stretch.powi(2) * d.powi(4) / 4.0;
            assert!((g / g0 - 1.0).abs() < 1e-12, "{space:?}");
        }
        let p = Pmb::new(Space::ThreeD, E, d).with_fracture_energy(Space::ThreeD, g0);
        let g = PI * p.micromodulus * p.critical_stretch.powi(2) * d.powi(5) / 10.0;
        assert!((g / g0 - 1.0).abs() < 1e-12);
        // The closed forms of the module table.
        let table = [
            (Space::PlaneStress, (4.0 * PI * g0 / (9.0 * E * d)).sqrt()),
            (Space::PlaneStrain, (5.0 * PI * g0 / (12.0 * E * d)).sqrt()),
            (
                Space::ThreeD,
                (5.0 * g0 / (9.0 * bulk_modulus(E) * d)).sqrt(),
            ),
        ];
        for (space, s0) in table {
            let p = Pmb::new(space, E, d).with_fracture_energy(space, g0);
            assert!((p.critical_stretch / s0 - 1.0).abs() < 1e-14, "{space:?}");
        }
        // 3D: 18K/(πδ⁴) = 12E/(πδ⁴) at ν = 1/4.
        let c = Pmb::new(Space::ThreeD, E, d).micromodulus;
        assert!((c / (12.0 * E / (PI * d.powi(4))) - 1.0).abs() < 1e-14);
    }
}
