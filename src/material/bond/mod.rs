//! The bond laws of peridynamic bodies: the constitutive models of their bonds,
//! one per file, as the other files of `material/` are of continua. Each law
//! gives its constants from the body's E, ν and horizon δ, its pairwise force
//! per unit volume squared and its bond energy; the bonds themselves (which
//! pairs, intact or broken) are the model's state (`model::peridynamics`) and
//! their forces on the particles are summed by `physics::peridynamics`.
//!
//! - `pmb`: bond-based prototype microelastic brittle (one micromodulus).

pub mod pmb;

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
