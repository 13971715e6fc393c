//! A rigid body: it keeps the velocity it starts with (a footing, a pile, a plate,
//! a projectile at constant speed) and carries no stress. It meets deformable
//! bodies only through contact (`crate::physics::contact`, where it acts as a
//! field of infinite mass), so a scene check requires a `[[contact]]` between it and
//! every other body, and the explicit solver. Its density gives the particles a
//! mass for the outputs; the reaction the contact exerts on it is in contact.csv.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material};
use crate::dim::Mat3;

#[derive(Clone, Debug)]
pub struct Rigid {
    density: f64,
}

impl FromParameters for Rigid {
    const NAME: &'static str = "rigid";
    const KEYS: &'static [&'static str] = &[];
    const EXAMPLE: &'static str = "";

    fn from_parameters(density: f64, _p: &Parameters) -> Result<Self, KeyError> {
        Ok(Rigid { density })
    }
}

impl Material for Rigid {
    fn model(&self) -> &'static str {
        Self::NAME
    }

    fn density(&self) -> f64 {
        self.density
    }

    fn update(&self, _inc: &Increment, _history_new: &mut [f64]) -> Mat3 {
        Mat3::zeros()
    }

    /// No waves cross a rigid body: it does not limit the time step.
    fn p_wave_modulus(&self) -> f64 {
        0.0
    }

    fn strain_energy_density(&self, _f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        0.0
    }
}
