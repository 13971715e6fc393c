//! The correspondence (non-ordinary state-based) bond law (Silling, Epton,
//! Weckner, Xu & Askari 2007, J. Elasticity 88, §15; seed 004; digest Part 3):
//! a particle's stress comes from the body's own material, as an MPM
//! particle's does, and its bonds carry it. Over i's intact bonds, with
//! ξ = x_j − x_i, Y = y_j − y_i and the influence function ω(|ξ|) (`influence`:
//! constant, or seed 004's Gaussian exp(−|ξ|²/δ²)), written ω = 1 below:
//!
//! - shape tensor K_i = Σ_j ξ⊗ξ V_j, deformation gradient F_i = (Σ_j Y⊗ξ V_j) K_i⁻¹
//!   (`physics::peridynamics::deformation`);
//! - Cauchy stress σ_i from the material's update under ΔF = F_i F_i,old⁻¹
//!   (the update every MPM particle takes, `material::Material::update`), so
//!   every model of `material/` works here (Johnson–Cook, Drucker–Prager, …);
//! - force state T_i⟨ξ⟩ = P_i K_i⁻¹ ξ, P_i = J_i σ_i F_i⁻ᵀ (first Piola–Kirchhoff):
//!   the pair force of bond (i, j) per unit volume squared is
//!   f_ij = (P_i K_i⁻¹ + P_j K_j⁻¹) ξ, on i and the opposite on j
//!   (ρ ü_i = Σ_j (T_i⟨ξ⟩ − T_j⟨−ξ⟩) V_j).
//!
//! **Zero-energy modes.** F_i sees only the affine part of its family's motion,
//! so a motion with no affine part (on a lattice, the checkerboard
//! u_j = ±a e) costs nothing. The control (Silling 2017, J. Elasticity 127,
//! eq. 23's penalty on the non-affine part, in Littlewood's central-force form
//! as Peridigm's "hourglass" force): the departure of the bond from the mean
//! affine motion of its ends, z = Y − ½(F_i + F_j) ξ, is resisted by the
//! central force G c (z·Ŷ)/|ξ| Ŷ per unit volume squared, Ŷ = Y/|Y|, c the
//! PMB micromodulus of the same P-wave modulus (below) and G the coefficient
//! `zero_energy_control` (default 1, as Silling's G is of order one). It
//! vanishes under an affine motion (z = 0 when F_i = F_j = the map), so a
//! homogeneous deformation does not feel it, and it raises the bond stiffness
//! of the stable step to c (1 + G) (twice that with the Gaussian influence,
//! `Influence::stiffening`). Lower values let the zero-energy
//! oscillations break bonds: the notched glass plate
//! (`problems/peridynamic_plate.toml` in plane strain) shatters at its free
//! ends with G = 0 (1,807 damaged particles more than 8 mm from the notch)
//! and G = 0.1, and cracks only from its notch with G = 1 and 3 (none).
//!
//! **The PMB micromodulus of P-wave modulus M** (for the control and the
//! Silling–Askari step): PMB has ν = 1/4 in 3D and plane strain, where
//! M = λ + 2G = 9K/5 (3D) and 6E/5 (plane strain), so c = 18K/(πδ⁴) = 10M/(πδ⁴)
//! and c = 48E/(5πδ³) = 8M/(πδ³). Plane stress is refused: the materials of
//! `material/` are 3D and plane strain.
//!
//! **Fracture.** A bond breaks for good when its stretch passes s0, that of
//! fracture energy G0 for this c (`super::critical_stretch`); broken bonds
//! leave K and F. A particle that has lost more than half its family
//! (damage φ > 1/2, `FAMILY_LOST`) or whose intact bonds no longer span the
//! space has no F: its stress stays as it was and its intact bonds act as PMB
//! bonds of the same c (a family of a few bonds gives an ill-conditioned K,
//! and without the rule a fragment's particles are thrown off: the notched
//! glass plate lost one from the grid after its crack began).

use super::space::{critical_stretch, Space};
use std::f64::consts::PI;

/// Damage past which a particle has no F: its bonds act as PMB bonds.
pub const FAMILY_LOST: f64 = 0.5;

/// Default of `zero_energy_control`.
pub const ZERO_ENERGY_CONTROL: f64 = 1.0;

/// The influence function ω(|ξ|) weighing a particle's bonds in K, N, the
/// force state and the zero-energy control (`influence`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Deserialize,
    strum::IntoStaticStr,
    strum::EnumIter,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Influence {
    /// ω = 1.
    #[default]
    Constant,
    /// ω = exp(−|ξ|²/δ²) (seed 004; digest Part 3).
    Gaussian,
}

impl Influence {
    /// ω of a bond of reference length `length` in a horizon δ.
    pub fn weight(self, length: f64, delta: f64) -> f64 {
        match self {
            Influence::Constant => 1.0,
            Influence::Gaussian => (-(length / delta).powi(2)).exp(),
        }
    }

    /// How much stiffer the shortest bonds are than with ω = 1, for the
    /// stable step: the ratio of the continuum shape tensors ∫ ξ² dV over
    /// ∫ ω ξ² dV, 1.89 in 2D and 2.0 in 3D for the Gaussian (taken as 2).
    pub fn stiffening(self) -> f64 {
        match self {
            Influence::Constant => 1.0,
            Influence::Gaussian => 2.0,
        }
    }
}

/// A body's correspondence constants (its material is the body's own table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correspondence {
    /// Horizon δ.
    pub horizon: f64,
    /// The PMB micromodulus of the material's P-wave modulus.
    pub micromodulus: f64,
    /// G of the zero-energy control.
    pub zero_energy_control: f64,
    /// Critical stretch s0 (infinite: no fracture).
    pub critical_stretch: f64,
    pub influence: Influence,
}

impl Correspondence {
    /// The constants of a body of horizon δ in `space` (3D or plane strain)
    /// whose material has P-wave modulus `m`.
    pub fn new(space: Space, m: f64, delta: f64, zero_energy_control: f64) -> Correspondence {
        let micromodulus = match space {
            Space::ThreeD => 10.0 * m / (PI * delta.powi(4)),
            Space::PlaneStrain => 8.0 * m / (PI * delta.powi(3)),
            Space::PlaneStress => unreachable!("refused by scene::validate::peridynamic"),
        };
        Correspondence {
            horizon: delta,
            micromodulus,
            zero_energy_control,
            critical_stretch: f64::INFINITY,
            influence: Influence::Constant,
        }
    }

    pub fn with_influence(self, influence: Influence) -> Correspondence {
        Correspondence { influence, ..self }
    }

    /// ω of a bond of reference length `length`.
    pub fn weight(&self, length: f64) -> f64 {
        self.influence.weight(length, self.horizon)
    }

    /// With the critical stretch of fracture energy G0.
    pub fn with_fracture_energy(self, space: Space, g0: f64) -> Correspondence {
        self.with_critical_stretch(critical_stretch(space, self.micromodulus, self.horizon, g0))
    }

    pub fn with_critical_stretch(self, s0: f64) -> Correspondence {
        Correspondence {
            critical_stretch: s0,
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::bond::pmb::Pmb;

    /// The micromodulus is PMB's for the E (plane strain) or K (3D) that has
    /// P-wave modulus M at ν = 1/4.
    #[test]
    fn the_micromodulus_is_pmbs_of_the_same_p_wave_modulus() {
        let (e, nu, d) = (70e9, 0.25, 3e-3);
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        for space in [Space::ThreeD, Space::PlaneStrain] {
            let c = Correspondence::new(space, m, d, 0.1).micromodulus;
            let pmb = Pmb::new(space, e, d).micromodulus;
            assert!(
                (c / pmb - 1.0).abs() < 1e-14,
                "{space:?}: {c:e} against {pmb:e}"
            );
        }
    }
}
