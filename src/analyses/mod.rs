//! Analyses built on runs: the strength-reduction search for a factor of safety,
//! analytical reference solutions and their error measures, limit analysis (a
//! separate finite-element program with its own scene format), and `mpm bench`.

pub mod bench;
pub mod limit_analysis;
pub mod reference;
pub mod strength_reduction;

use crate::run::{RunError, RunOptions, RunSummary};
use crate::scene::{Scene, SceneError};
use std::path::Path;

/// Run a scene, or the analysis it asks for: with a `[strength_reduction]` table,
/// the search for its factor of safety (which runs the stages once per trial).
pub fn run_scene(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<RunSummary, RunError> {
    if scene.config.strength_reduction.is_some() && opts.strength_factor.is_none() {
        std::fs::create_dir_all(out)?;
        strength_reduction::search(scene, out, opts)
    } else {
        crate::run::run(scene, out, opts)
    }
}

/// The checks of the tables that analyses read, beyond the scene's own
/// validation: a `[reference]` must fit the scene (`reference::from_scene`).
pub fn check(scene: &Scene) -> Result<(), SceneError> {
    reference::from_scene(&scene.config)
        .map(|_| ())
        .map_err(|(key, m)| SceneError::at_key(&scene.file, &scene.text, &key, m))
}
