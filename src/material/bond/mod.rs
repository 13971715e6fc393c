//! The bond laws of peridynamic bodies: the constitutive models of their bonds,
//! one per file, as the other files of `material/` are of continua. Each law
//! gives its constants from the body's E, ν and horizon δ, its pairwise force
//! per unit volume squared and its bond energy; the bonds themselves (which
//! pairs, intact or broken) are the model's state (`model::peridynamics`) and
//! their forces on the particles are summed by `physics::peridynamics`.
//!
//! - `pmb`: bond-based prototype microelastic brittle (one micromodulus, one ν);
//! - `beam`: beam-based, an axial and a tangential micromodulus (any ν up to
//!   PMB's);
//! - `correspondence`: non-ordinary state-based, the stress of the body's own
//!   material carried by the bonds, with a zero-energy control;
//! - `short_range`: the repulsion of particles that no intact bond joins
//!   (fragments of a body, two bodies).

pub mod beam;
pub mod correspondence;
pub mod pmb;
pub mod short_range;
mod space;

pub use space::{critical_stretch, Space, SAFETY};

use beam::Beam;
use correspondence::Correspondence;
use pmb::Pmb;

/// The bond law of a peridynamic body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BondLaw {
    Pmb(Pmb),
    Beam(Beam),
    Correspondence(Correspondence),
}

impl BondLaw {
    pub fn horizon(&self) -> f64 {
        match self {
            BondLaw::Pmb(p) => p.horizon,
            BondLaw::Beam(b) => b.horizon,
            BondLaw::Correspondence(c) => c.horizon,
        }
    }

    /// Critical stretch s0 (infinite: no fracture).
    pub fn critical_stretch(&self) -> f64 {
        match self {
            BondLaw::Pmb(p) => p.critical_stretch,
            BondLaw::Beam(b) => b.critical_stretch,
            BondLaw::Correspondence(c) => c.critical_stretch,
        }
    }

    /// The PMB micromodulus of the law's bonds: c (PMB), the axial c1 (beam),
    /// PMB's c of the material's P-wave modulus (correspondence).
    pub fn micromodulus(&self) -> f64 {
        match self {
            BondLaw::Pmb(p) => p.micromodulus,
            BondLaw::Beam(b) => b.axial,
            BondLaw::Correspondence(c) => c.micromodulus,
        }
    }

    /// The bond's spring constant times |ξ| for the Silling–Askari step: c
    /// (PMB), max(c1, c2) (beam), c (1 + G) (correspondence: PMB's c of the
    /// same P-wave modulus, stiffened by the zero-energy control and, for a
    /// Gaussian influence, by `Influence::stiffening`).
    pub fn stiffness(&self) -> f64 {
        match self {
            BondLaw::Pmb(p) => p.micromodulus,
            BondLaw::Beam(b) => b.stiffness(),
            BondLaw::Correspondence(c) => {
                c.micromodulus * (1.0 + c.zero_energy_control) * c.influence.stiffening()
            }
        }
    }

    /// SAFETY × √(2ρ / Σ_j V_j c/|ξ|) (Silling & Askari 2005, eq. 29), given
    /// `stiffness` = Σ_j V_j c/|ξ| over the particle's bonds.
    pub fn stable_dt(rho: f64, stiffness: f64) -> f64 {
        SAFETY * (2.0 * rho / stiffness).sqrt()
    }
}
