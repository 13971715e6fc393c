//! Finding and building the models a scene may name (`material::MODELS`, the
//! one list a new model is added to).
//!
//! `build` turns a material table (its model's name, density and other keys)
//! into the model, rejecting keys the model does not take; the scene validation
//! calls it to check a table and `Model::build` to construct the material.

use super::parameters::{Entry, KeyError, Parameters};
use super::{undrained, Material, MODELS};
use std::sync::OnceLock;

/// The model of this name.
pub fn find(name: &str) -> Option<&'static Entry> {
    MODELS.iter().find(|m| m.name == name)
}

/// The names of the models.
pub fn names() -> &'static [&'static str] {
    static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
    NAMES.get_or_init(|| MODELS.iter().map(|m| m.name).collect())
}

/// Every key some model takes (a key outside this list is unknown to all).
pub fn all_keys() -> &'static [&'static str] {
    static KEYS: OnceLock<Vec<&'static str>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let mut keys: Vec<&'static str> = Vec::new();
        for k in MODELS.iter().flat_map(|m| m.keys).chain(undrained::KEYS) {
            if !keys.contains(k) {
                keys.push(k);
            }
        }
        keys
    })
}

/// The material of the table at `table` (`material.0`): model `model` with this
/// density and these other keys, undrained when the drainage keys say so
/// (`material::undrained`). An error names the key.
pub fn build(
    table: &str,
    model: &str,
    density: f64,
    values: &toml::Table,
) -> Result<Box<dyn Material>, KeyError> {
    let entry = find(model).ok_or_else(|| {
        (
            format!("{table}.model"),
            format!(
                "unknown model `{model}`; the models are {}",
                names().join(", ")
            ),
        )
    })?;
    let (drainage, own): (toml::Table, toml::Table) = values
        .clone()
        .into_iter()
        .partition(|(k, _)| undrained::KEYS.contains(&k.as_str()));
    if let Some(k) = own.keys().find(|k| !entry.keys.contains(&k.as_str())) {
        return Err((
            format!("{table}.{k}"),
            format!("does not apply to model `{}`", entry.name),
        ));
    }
    let skeleton = (entry.construct)(density, &Parameters::new(table, entry.name, &own))?;
    undrained::wrap(skeleton, &Parameters::new(table, entry.name, &drainage))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_model_names_agree() {
        let mut seen = Vec::new();
        for m in MODELS {
            assert!(!seen.contains(&m.name), "`{}` registered twice", m.name);
            seen.push(m.name);
        }
        for m in MODELS {
            let values: toml::Table = toml::from_str(m.example).unwrap();
            let built = build("material.0", m.name, 1000.0, &values).unwrap();
            assert_eq!(built.model(), m.name, "Material::model of `{}`", m.name);
        }
    }
}
