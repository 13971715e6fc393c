//! What an error measure is, and the facts of a scene that the measures read
//! (body 0's box and material).

use crate::scene::{BodyShape, SceneConfig};
use std::path::Path;

/// An error measure of one scene against its analytical reference.
pub trait ErrorMeasure {
    /// What is compared with what, in one line.
    fn description(&self) -> String;
    /// The (non-negative) error of the run whose outputs are in `out`.
    fn error(&self, out: &Path) -> Result<f64, String>;
}

/// A scene-validation failure: dotted key path and message.
pub use crate::material::parameters::KeyError;

/// Corners of body 0, which must be a rectangle or box (the references are about a
/// prismatic body).
pub fn body0_box(s: &SceneConfig) -> Result<(Vec<f64>, Vec<f64>), KeyError> {
    let b = s
        .bodies
        .first()
        .ok_or(("body".to_string(), "no body".to_string()))?;
    match (b.shape, &b.min, &b.max) {
        (BodyShape::Rectangle | BodyShape::Box, Some(lo), Some(hi)) => Ok((lo.clone(), hi.clone())),
        _ => Err((
            "body.0.shape".into(),
            "the [reference] needs body 0 to be a rectangle or box".into(),
        )),
    }
}

/// Density, Young's modulus and Poisson's ratio of body 0's material.
pub fn body0_material(s: &SceneConfig) -> Result<(f64, f64, f64), KeyError> {
    let name = &s.bodies[0].material;
    let (i, m) = s
        .materials
        .iter()
        .enumerate()
        .find(|(_, m)| &m.name == name)
        .ok_or((
            "body.0.material".to_string(),
            "unknown material".to_string(),
        ))?;
    let table = format!("material.{i}");
    let p = m.parameters(&table);
    let e = p.get("youngs_modulus")?.ok_or((
        p.key("youngs_modulus"),
        "the [reference] needs the Young's modulus of body 0's material".to_string(),
    ))?;
    Ok((m.density, e, p.get("poisson_ratio")?.unwrap_or(0.0)))
}
