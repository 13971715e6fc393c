//! The `[[material]]` tables. Density and name are checked here, the model's
//! own keys by the model (`material::registry`).

use super::check::{ensure, KeyError};
use crate::material::Material;
use crate::scene::SceneConfig;

/// The `[[material]]` tables: a positive density, the model's own keys and
/// checks (`material::registry`), a unique name. Returns the materials as the
/// particles carry them (`SceneConfig::particle_materials`).
pub fn materials(s: &SceneConfig) -> Result<Vec<Box<dyn Material>>, KeyError> {
    ensure(
        !s.materials.is_empty(),
        "material",
        "the scene defines no [[material]]",
    )?;
    let mut built = Vec::new();
    for (i, m) in s.materials.iter().enumerate() {
        ensure(
            m.density > 0.0 && m.density.is_finite(),
            format!("material.{i}.density"),
            "must be a positive number",
        )?;
        built.push(m.build(i)?);
        let dup = s.materials[..i].iter().any(|o| o.name == m.name);
        ensure(
            !dup,
            format!("material.{i}.name"),
            format!("material name `{}` is used twice", m.name),
        )?;
    }
    Ok(s.particle_materials(built))
}
