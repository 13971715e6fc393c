//! A region of space in a scene: the shape of an excavation (`[[stage]]
//! excavate`, docs/staging.md), written like a body's shape.

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
