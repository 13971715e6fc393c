//! The `[[material]]` table: `name`, `model` and `density`, and the model's own
//! keys, kept as TOML values for the model to check and read
//! (`material::registry`, `material::parameters`).
//!
//! The table is deserialised by hand, key by key, rather than with serde's
//! `flatten` or an internally tagged enum: those buffer the table and lose the
//! position of a bad value (toml-rs/toml#535, #802). Here an unknown model is an
//! error at its value and a key no model takes an error at the key, each with its
//! line and column; the model's checks name their key and are located from it.

use crate::material::parameters::{KeyError, Parameters};
use crate::material::{registry, Material};
use serde::de::{self, Deserialize, Deserializer, MapAccess, Visitor};
use std::fmt;
use std::sync::OnceLock;

#[derive(Clone, Debug)]
pub struct MaterialConfig {
    pub name: String,
    /// A name in `material::MODELS`.
    pub model: String,
    /// Reference mass density ρ0.
    pub density: f64,
    /// The other keys of the table: the model's parameters.
    pub parameters: toml::Table,
}

impl MaterialConfig {
    /// The material of the table `material.{i}`, its parameters checked; an error
    /// names the key.
    pub fn build(&self, i: usize) -> Result<Box<dyn Material>, KeyError> {
        let table = format!("material.{i}");
        registry::build(&table, &self.model, self.density, &self.parameters)
    }

    /// The parameters of the table `table` (e.g. `material.0`), to read one key.
    pub fn parameters<'a>(&'a self, table: &'a str) -> Parameters<'a> {
        Parameters::new(table, &self.model, &self.parameters)
    }
}

/// Every key a material table may have: name, model, density and the keys of
/// all models.
fn fields() -> &'static [&'static str] {
    static FIELDS: OnceLock<Vec<&'static str>> = OnceLock::new();
    FIELDS.get_or_init(|| {
        let mut fields = vec!["name", "model", "density"];
        fields.extend(registry::all_keys());
        fields
    })
}

/// A key of the table.
enum Key {
    Name,
    Model,
    Density,
    Parameter(String),
}

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct KeyVisitor;
        impl Visitor<'_> for KeyVisitor {
            type Value = Key;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a material key")
            }
            fn visit_str<E: de::Error>(self, k: &str) -> Result<Key, E> {
                match k {
                    "name" => Ok(Key::Name),
                    "model" => Ok(Key::Model),
                    "density" => Ok(Key::Density),
                    _ if registry::all_keys().contains(&k) => Ok(Key::Parameter(k.into())),
                    _ => Err(E::unknown_field(k, fields())),
                }
            }
        }
        d.deserialize_identifier(KeyVisitor)
    }
}

/// The value of `model`: a registered model's name.
struct ModelName(String);

impl<'de> Deserialize<'de> for ModelName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct NameVisitor;
        impl Visitor<'_> for NameVisitor {
            type Value = ModelName;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("the name of a material model")
            }
            fn visit_str<E: de::Error>(self, name: &str) -> Result<ModelName, E> {
                match registry::find(name) {
                    Some(_) => Ok(ModelName(name.into())),
                    None => Err(E::unknown_variant(name, registry::names())),
                }
            }
        }
        d.deserialize_str(NameVisitor)
    }
}

impl<'de> Deserialize<'de> for MaterialConfig {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct TableVisitor;
        impl<'de> Visitor<'de> for TableVisitor {
            type Value = MaterialConfig;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a [[material]] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<MaterialConfig, A::Error> {
                let (mut name, mut model, mut density) = (None, None, None);
                let mut parameters = toml::Table::new();
                while let Some(key) = map.next_key()? {
                    match key {
                        Key::Name => name = Some(map.next_value()?),
                        Key::Model => model = Some(map.next_value::<ModelName>()?.0),
                        Key::Density => density = Some(map.next_value()?),
                        Key::Parameter(k) => {
                            parameters.insert(k, map.next_value()?);
                        }
                    }
                }
                Ok(MaterialConfig {
                    name: name.ok_or_else(|| de::Error::missing_field("name"))?,
                    model: model.ok_or_else(|| de::Error::missing_field("model"))?,
                    density: density.ok_or_else(|| de::Error::missing_field("density"))?,
                    parameters,
                })
            }
        }
        d.deserialize_map(TableVisitor)
    }
}
