//! The staged-construction keys of a `[[stage]]`: the bodies it activates and
//! deactivates by name, the regions it excavates and its displacement reset
//! (`model::staging` applies them; docs/staging.md), and the bodies active at
//! each stage's start.

use crate::scene::{BodyKindName, SceneConfig};
use serde::Deserialize;
use strum::IntoStaticStr;

/// A region of space: its continuum particles leave the model at the stage's
/// start (`excavate`).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RegionConfig {
    pub shape: RegionShape,
    pub min: Option<Vec<f64>>,
    pub max: Option<Vec<f64>>,
    pub centre: Option<Vec<f64>>,
    pub radius: Option<f64>,
    pub vertices: Option<Vec<Vec<f64>>>,
}

/// The shapes a region takes: those of the bodies given by corners, a centre
/// and radius, or vertices.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, IntoStaticStr)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum RegionShape {
    /// 2D, `min` and `max` corners.
    Rectangle,
    /// 3D, `min` and `max` corners.
    Box,
    /// 2D, `centre` and `radius`.
    Disk,
    /// 3D, `centre` and `radius`.
    Sphere,
    /// 2D, `vertices` of a simple polygon in order.
    Polygon,
}

impl SceneConfig {
    /// Whether the scene stages its construction: a body starts inactive or a
    /// stage changes the model at its start.
    pub fn stages_construction(&self) -> bool {
        self.bodies.iter().any(|b| b.active == Some(false))
            || self.stages.iter().any(|st| st.changes_model())
    }

    /// The bodies named `name` (a name may group several, as for contact).
    pub fn bodies_named(&self, name: &str) -> Vec<usize> {
        (0..self.bodies.len())
            .filter(|&i| self.bodies[i].name.as_deref() == Some(name))
            .collect()
    }

    /// The bodies that start inactive (`active = false`).
    pub fn inactive_bodies(&self) -> Vec<usize> {
        (0..self.bodies.len())
            .filter(|&i| self.bodies[i].active == Some(false))
            .collect()
    }

    /// The bodies activated by stages 0..=k (validated names).
    pub fn activated_by_stage(&self, k: usize) -> Vec<usize> {
        (self.stages.iter().take(k + 1))
            .flat_map(|st| st.activate.iter().flatten())
            .flat_map(|name| self.bodies_named(name))
            .collect()
    }

    /// Whether body i is a continuum body (the kind staging applies to).
    pub fn is_continuum(&self, i: usize) -> bool {
        self.body_kind(i) == BodyKindName::Continuum
    }
}

impl crate::scene::SolverConfig {
    /// Whether this stage changes the model at its start.
    pub fn changes_model(&self) -> bool {
        self.activate.as_ref().is_some_and(|v| !v.is_empty())
            || self.deactivate.as_ref().is_some_and(|v| !v.is_empty())
            || self.excavate.as_ref().is_some_and(|v| !v.is_empty())
            || self.reset_displacement == Some(true)
    }
}
