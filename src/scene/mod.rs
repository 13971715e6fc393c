//! Scene files: TOML, read with serde, unknown keys rejected.
//!
//! `Scene::load` reads a file, applies `--set KEY=VALUE` overrides (dotted TOML
//! paths, values in TOML syntax), deserialises, and validates physical ranges.
//! Every error names the file and the key and, where the TOML gives it, the line
//! and column. The keys are documented in `docs/scene.md`.

mod config;
mod error;
pub mod expr;
mod grid;
mod material;
pub mod overrides;
pub mod validate;

pub use config::*;
pub use error::SceneError;
pub use grid::*;
pub use material::MaterialConfig;

use std::path::Path;

/// A parsed and validated scene, with the text it was parsed from.
#[derive(Clone, Debug)]
pub struct Scene {
    pub file: String,
    pub config: SceneConfig,
    /// The text after overrides (to locate keys in errors found after parsing).
    pub text: String,
}

impl Scene {
    /// Read, override, parse and validate a scene file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::plain(&file, format!("cannot read the scene file: {e}")))?;
        Scene::parse(&file, &text, overrides)
    }

    /// Parse scene text (`file` names it in errors).
    pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let text = overrides::apply(file, text, overrides)?;
        let config: SceneConfig =
            toml::from_str(&text).map_err(|e| SceneError::from_toml(file, &text, &e))?;
        validate::validate(&config)
            .map_err(|(path, msg)| SceneError::at_key(file, &text, &path, msg))?;
        Ok(Scene {
            file: file.to_string(),
            config,
            text,
        })
    }
}
