//! A rigid body: it carries no stress and meets deformable bodies only through
//! contact (`crate::solver::explicit::contact`, where it acts as a field of infinite mass
//! within a step), so a scene check requires a `[[contact]]` between it and every
//! other body, and the explicit solver. With `motion = "prescribed"` (the default)
//! it keeps the velocity it starts with (a footing, a pile, a plate, a projectile
//! at constant speed); with `motion = "free"` it translates under the contact
//! impulses, gravity and loads with the mass of its particles (a projectile whose
//! residual velocity is wanted, a falling block; no rotation). Its density gives
//! the particles their mass; the reaction the contact exerts on it is in
//! contact.csv.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material, StressDerivative};
use crate::dim::Mat3;
use serde::Deserialize;

/// How a rigid body moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// At its initial velocity throughout.
    #[default]
    Prescribed,
    /// Translation under the forces on it: M dV/dt = J/Δt + Σ f_ext.
    Free,
}

impl Motion {
    /// The motion a rigid material table asks for (its `motion` key, checked
    /// when the material is built).
    pub fn of(parameters: &toml::Table) -> Motion {
        (parameters.get("motion"))
            .and_then(|v| Motion::deserialize(v.clone()).ok())
            .unwrap_or_default()
    }
}

#[derive(Clone, Debug)]
pub struct Rigid {
    density: f64,
    pub motion: Motion,
}

impl FromParameters for Rigid {
    const NAME: &'static str = "rigid";
    const KEYS: &'static [&'static str] = &["motion"];
    const EXAMPLE: &'static str = "";

    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        Ok(Rigid {
            density,
            motion: p.get("motion")?.unwrap_or_default(),
        })
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

    /// No stress, so none changes (the implicit solver keeps a rigid body's
    /// particles off the grid anyway, `solver::implicit::grid`).
    fn stress_derivative(&self, _inc: &Increment) -> Option<StressDerivative> {
        Some(StressDerivative::zeros())
    }

    /// No waves cross a rigid body: it does not limit the time step.
    fn p_wave_modulus(&self) -> f64 {
        0.0
    }

    fn strain_energy_density(&self, _f: &Mat3, _stress: &Mat3, _history: &[f64]) -> f64 {
        0.0
    }
}
