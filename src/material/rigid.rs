//! The material of a rigid body's particles: no stress, no stiffness, no
//! waves, only the density that gives them their mass. What makes a body rigid
//! is its kind (`model::body::BodyKind::Rigid`, `[[body]] kind = "rigid"`), not
//! this material: the model gives every rigid body's particles this material
//! with the density of the body's `[[material]]` table, so every transfer works
//! on them unchanged (zero stress and internal force, no limit on the time step,
//! no strain energy) while the solvers treat the body by its kind.
//!
//! `model = "rigid"` in a `[[material]]` table is the old form of a rigid body,
//! still read: a body with such a material and no `kind` is rigid, with the
//! table's `motion` (`Motion`, checked here) as its motion.

use super::parameters::{FromParameters, KeyError, Parameters};
use super::{Increment, Material, StressDerivative};
use crate::dim::Mat3;
use serde::Deserialize;

/// How a rigid body moves (`[[body]] motion`, or the `motion` of an old-form
/// rigid material).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// At its initial velocity throughout.
    #[default]
    Prescribed,
    /// Translation and rotation under the forces on it (Newton–Euler,
    /// `physics::rigid::newton_euler`).
    Free,
}

impl Motion {
    /// The `motion` key of an old-form rigid material table (checked when the
    /// material is built), if it has one.
    pub fn of(parameters: &toml::Table) -> Option<Motion> {
        (parameters.get("motion")).and_then(|v| Motion::deserialize(v.clone()).ok())
    }
}

#[derive(Clone, Debug)]
pub struct Rigid {
    density: f64,
}

impl Rigid {
    /// The material of a rigid body's particles of density ρ.
    pub fn new(density: f64) -> Rigid {
        Rigid { density }
    }
}

impl FromParameters for Rigid {
    const NAME: &'static str = "rigid";
    const KEYS: &'static [&'static str] = &["motion"];
    const EXAMPLE: &'static str = "";

    /// The old form: the table's `motion` is the body's (`SceneConfig::rigid_motion`),
    /// only checked here.
    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError> {
        p.get::<Motion>("motion")?;
        Ok(Rigid::new(density))
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
