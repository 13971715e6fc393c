//! Analyses built on runs: the strength-reduction search for a factor of safety,
//! analytical reference solutions and their error measures, limit analysis (a
//! separate finite-element program with its own scene format), and `mpm bench`.

pub mod bench;
pub mod limit_analysis;
pub mod reference;
pub mod strength_reduction;

use crate::scene::{Scene, SceneError};

/// The checks of the tables that analyses read, beyond the scene's own
/// validation: a `[reference]` must fit the scene (`reference::from_scene`).
pub fn check(scene: &Scene) -> Result<(), SceneError> {
    reference::from_scene(&scene.config)
        .map(|_| ())
        .map_err(|(key, m)| SceneError::at_key(&scene.file, &scene.text, &key, m))
}
