//! Reference solutions: scene-specific error measures that read a finished run's
//! outputs (`particles_final.csv`, `history.csv`). A scene declares its reference
//! with a `[reference]` table (`kind = "column" | "vibrating_bar" | "cantilever" |
//! "displacement_field"`,
//! docs/scene.md); the parameters (lengths, density, moduli, gravity, load) come
//! from the scene itself, so refining or overriding the scene keeps the reference
//! consistent. `mpm bench` fills its `error` column with these; the tests use the
//! same functions.

pub mod bar;
pub(crate) mod cantilever;
pub mod column;
pub mod displacement_field;
pub mod elastica;
pub(crate) mod measure;

pub use measure::{ErrorMeasure, KeyError};

use crate::scene::{ReferenceKind, Scene, SceneConfig, SceneError};

/// The error measure the scene declares, if any; an error names the scene key that
/// makes the reference inapplicable. Files the reference names are relative to
/// the folder of `scene_file`.
pub fn from_scene(
    s: &SceneConfig,
    scene_file: &str,
) -> Result<Option<Box<dyn ErrorMeasure>>, KeyError> {
    let Some(r) = &s.reference else {
        return Ok(None);
    };
    if r.kind != ReferenceKind::Cantilever && r.beam.is_some() {
        return Err((
            "reference.beam".into(),
            "applies only to kind = \"cantilever\"".into(),
        ));
    }
    if r.kind != ReferenceKind::DisplacementField && r.file.is_some() {
        return Err((
            "reference.file".into(),
            "applies only to kind = \"displacement_field\"".into(),
        ));
    }
    Ok(Some(match r.kind {
        ReferenceKind::Column => Box::new(column::Column::from_scene(s)?),
        ReferenceKind::VibratingBar => Box::new(bar::BarPeriod::from_scene(s)?),
        ReferenceKind::Cantilever => Box::new(cantilever::CantileverTip::from_scene(s)?),
        ReferenceKind::DisplacementField => Box::new(
            displacement_field::DisplacementField::from_scene(s, scene_file)?,
        ),
    }))
}

/// A parsed scene whose `[reference]`, if any, fits it (the check that the scene
/// validation cannot make: it needs the reference kinds of this layer). `mpm run`,
/// `mpm check` and `mpm bench` load scenes through it. An error that an override
/// causes names the override (`Scene::blame`).
pub fn checked(scene: Scene) -> Result<Scene, SceneError> {
    match fits(&scene) {
        Ok(()) => Ok(scene),
        Err(e) => Err(scene.blame(e, fits)),
    }
}

/// The scene's `[reference]` fits it; an error names the scene key.
fn fits(scene: &Scene) -> Result<(), SceneError> {
    match from_scene(&scene.config, &scene.file) {
        Ok(_) => Ok(()),
        Err((key, m)) => Err(scene.at_key(&key, m)),
    }
}
