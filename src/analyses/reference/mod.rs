//! Reference solutions: scene-specific error measures that read a finished run's
//! outputs (`particles_final.csv`, `history.csv`). A scene declares its reference
//! with a `[reference]` table (`kind = "column" | "vibrating_bar" | "cantilever"`,
//! docs/scene.md); the parameters (lengths, density, moduli, gravity, load) come
//! from the scene itself, so refining or overriding the scene keeps the reference
//! consistent. `mpm bench` fills its `error` column with these; the tests use the
//! same functions.

pub mod bar;
pub mod cantilever;
pub mod column;
pub mod elastica;

use crate::scene::{BodyShape, ReferenceKind, Scene, SceneConfig, SceneError};
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

/// The error measure the scene declares, if any; an error names the scene key that
/// makes the reference inapplicable.
pub fn from_scene(s: &SceneConfig) -> Result<Option<Box<dyn ErrorMeasure>>, KeyError> {
    let Some(r) = &s.reference else {
        return Ok(None);
    };
    if r.kind != ReferenceKind::Cantilever && r.beam.is_some() {
        return Err((
            "reference.beam".into(),
            "applies only to kind = \"cantilever\"".into(),
        ));
    }
    Ok(Some(match r.kind {
        ReferenceKind::Column => Box::new(column::Column::from_scene(s)?),
        ReferenceKind::VibratingBar => Box::new(bar::BarPeriod::from_scene(s)?),
        ReferenceKind::Cantilever => Box::new(cantilever::CantileverTip::from_scene(s)?),
    }))
}

/// A parsed scene whose `[reference]`, if any, fits it (the check that the scene
/// validation cannot make: it needs the reference kinds of this layer). `mpm run`,
/// `mpm check` and `mpm bench` load scenes through it.
pub fn checked(scene: Scene) -> Result<Scene, SceneError> {
    match from_scene(&scene.config) {
        Ok(_) => Ok(scene),
        Err((key, m)) => Err(SceneError::at_key(&scene.file, &scene.text, &key, m)),
    }
}

/// Corners of body 0, which must be a rectangle or box (the references are about a
/// prismatic body).
fn body0_box(s: &SceneConfig) -> Result<(Vec<f64>, Vec<f64>), KeyError> {
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
fn body0_material(s: &SceneConfig) -> Result<(f64, f64, f64), KeyError> {
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
