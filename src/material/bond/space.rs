//! What the bond laws share: the space a body is in, the critical stretch of
//! a fracture energy, the stable step's safety factor.

use std::f64::consts::PI;

/// The space a peridynamic body is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    ThreeD,
    PlaneStress,
    PlaneStrain,
}

impl Space {
    /// The one Poisson ratio of the PMB bond in this space.
    pub fn poisson_ratio(self) -> f64 {
        match self {
            Space::ThreeD | Space::PlaneStrain => 0.25,
            Space::PlaneStress => 1.0 / 3.0,
        }
    }
}

/// Safety factor on the Silling–Askari step (0.7–0.85 in Peridynamics.jl and
/// CabanaPD, survey §2.3).
pub const SAFETY: f64 = 0.8;

/// The critical stretch at which the bonds a straight crack cuts hold G0 per
/// unit area, for an axial micromodulus c: 2D G0 = c h s0² δ⁴/4 (h = 1),
/// 3D G0 = π c s0² δ⁵/10 (`pmb` module doc).
pub fn critical_stretch(space: Space, c: f64, delta: f64, g0: f64) -> f64 {
    match space {
        Space::ThreeD => (10.0 * g0 / (PI * c * delta.powi(5))).sqrt(),
        Space::PlaneStress | Space::PlaneStrain => (4.0 * g0 / (c * delta.powi(4))).sqrt(),
    }
}
