//! Scene files: TOML, read with serde, unknown keys rejected.
//!
//! `Scene::load` reads a file, applies `--set KEY=VALUE` overrides (dotted TOML
//! paths, values in TOML syntax), deserialises, and validates physical ranges.
//! Every error names the file and the key path and, where the TOML gives it, the
//! line and column; an error that a `--set` override causes names the override
//! instead (`error.rs`). The keys are documented in `docs/scene.md`. What each
//! body is (its `kind`, or the old form of a rigid body) is read in
//! `body_kind.rs`.

mod body_kind;
mod config;
pub mod contact;
pub mod curve;
mod error;
pub(crate) mod expr;
mod grid;
mod material;
pub(crate) mod overrides;
pub mod region;
mod solver;
pub mod staging;
#[cfg(test)]
pub(crate) mod testing;
pub(crate) mod validate;

pub use config::*;
pub use curve::TimeHistory;
pub use error::{blame, SceneError, Source};
pub use grid::*;
pub use material::MaterialConfig;
pub use solver::*;

use std::path::Path;

/// A parsed and validated scene, with the text it was parsed from.
#[derive(Clone, Debug)]
pub struct Scene {
    pub file: String,
    pub config: SceneConfig,
    /// The text after overrides (to locate keys in errors found after parsing).
    pub text: String,
    /// The file's text and the overrides applied to it.
    pub original: String,
    pub overrides: Vec<String>,
}

impl Scene {
    /// Read, override, parse and validate a scene file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = read_text(&file, path)?;
        Scene::parse(&file, &text, overrides)
    }

    /// Parse scene text (`file` names it in errors); an error that an override
    /// causes names the override (`error::blame`).
    pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        Scene::parse_as_given(file, text, overrides)
            .map_err(|e| error::blame(e, overrides, |o| Scene::parse_as_given(file, text, o)))
    }

    /// Parse scene text, an error at a key naming an override only if it set the key.
    fn parse_as_given(file: &str, text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let applied = overrides::apply(file, text, overrides)?;
        let source = Source::new(file, text, &applied, overrides);
        let config: SceneConfig = source.deserialize()?;
        let mut config = config;
        validate::validate(&config).map_err(|(path, msg)| source.at_key(&path, msg))?;
        curve::read_files(config.time_histories_mut(), &source)?;
        Ok(Scene {
            file: file.to_string(),
            config,
            text: applied,
            original: text.to_string(),
            overrides: overrides.to_vec(),
        })
    }

    /// An error at a dotted key path of this scene (found after parsing).
    pub fn at_key(&self, path: &str, message: impl Into<String>) -> SceneError {
        Source::new(&self.file, &self.original, &self.text, &self.overrides).at_key(path, message)
    }

    /// `e`, an error that `check` found in this scene, naming the override that
    /// causes it (`error::blame`: `check` is replayed on the scene with fewer
    /// overrides).
    pub fn blame<T>(
        &self,
        e: SceneError,
        check: impl Fn(&Scene) -> Result<T, SceneError>,
    ) -> SceneError {
        error::blame(e, &self.overrides, |o| {
            Scene::parse_as_given(&self.file, &self.original, o).and_then(|s| check(&s))
        })
    }
}

/// A scene file's text; a file that is not UTF-8 is refused at the byte offset
/// of its first bad byte.
pub fn read_text(file: &str, path: &Path) -> Result<String, SceneError> {
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::plain(file, format!("cannot read the scene file: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let (line, col) =
            error::line_col(&String::from_utf8_lossy(&e.as_bytes()[..offset]), offset);
        SceneError {
            position: Some((line, col)),
            ..SceneError::plain(
                file,
                format!("the file is not UTF-8 text: invalid byte at byte offset {offset}"),
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::de::{value::StrDeserializer, DeserializeOwned, IntoDeserializer};
    use strum::IntoEnumIterator;

    /// Every value's `name()` (strum) is the name serde reads for it.
    fn names_agree<T>()
    where
        T: IntoEnumIterator + DeserializeOwned + PartialEq + std::fmt::Debug + Copy,
        &'static str: From<T>,
    {
        for v in T::iter() {
            let name: &'static str = v.into();
            let d: StrDeserializer<serde::de::value::Error> = name.into_deserializer();
            assert_eq!(T::deserialize(d), Ok(v), "`{name}`");
        }
    }

    #[test]
    fn enum_names_are_the_scene_names() {
        names_agree::<ShapeFunction>();
        names_agree::<BodyShape>();
        names_agree::<BodyKindName>();
        names_agree::<BondModel>();
        names_agree::<Plane>();
        names_agree::<Condition>();
        names_agree::<LoadKind>();
        names_agree::<SolverKind>();
        names_agree::<Scheme>();
        names_agree::<Integrator>();
        names_agree::<MassMatrix>();
        names_agree::<LinearSolver>();
        names_agree::<PreconditionerKind>();
        names_agree::<DirectOrdering>();
        names_agree::<LinearSystems>();
        names_agree::<ReferenceKind>();
        names_agree::<Beam>();
    }
}
