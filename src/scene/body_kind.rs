//! What each `[[body]]` is (`BodyKindName`): its `kind`, or the old form of a
//! rigid body (a material with `model = "rigid"`), its motion, the key that
//! makes it what it is (for messages), and the materials its particles carry
//! (a rigid body takes only the density of its material). The model builds its
//! bodies' kinds from these (`model::body`); the validation checks the keys
//! (`validate::grid_bodies`).

use super::{BodyKindName, MaterialConfig, SceneConfig};
use crate::material::parameters::FromParameters;
use crate::material::rigid::{Motion, Rigid};
use crate::material::Material;

impl SceneConfig {
    /// The kind of body i: its `kind`, else rigid when its material is an
    /// old-form rigid material (`model = "rigid"`), else continuum.
    pub fn body_kind(&self, i: usize) -> BodyKindName {
        let old_form = self.old_form_rigid(i).is_some();
        match self.bodies[i].kind {
            Some(kind) => kind,
            None if old_form => BodyKindName::Rigid,
            None => BodyKindName::Continuum,
        }
    }

    /// The key that makes body i what it is, for messages about its kind:
    /// `body.i.kind`, or `body.i.material` for the old form of a rigid body.
    pub fn body_kind_key(&self, i: usize) -> String {
        match self.bodies[i].kind {
            None if self.old_form_rigid(i).is_some() => format!("body.{i}.material"),
            _ => format!("body.{i}.kind"),
        }
    }

    /// The motion of rigid body i: its `motion`, else its old-form rigid
    /// material's, else prescribed.
    pub fn rigid_motion(&self, i: usize) -> Motion {
        let old_form = self
            .old_form_rigid(i)
            .and_then(|m| Motion::of(&m.parameters));
        (self.bodies[i].motion).or(old_form).unwrap_or_default()
    }

    /// Body i's material when it is an old-form rigid material
    /// (`model = "rigid"`, `material::rigid`): the one place the scene reads
    /// rigidity from a material.
    pub fn old_form_rigid(&self, i: usize) -> Option<&MaterialConfig> {
        let name = &self.bodies[i].material;
        (self.materials.iter()).find(|m| &m.name == name && m.model == Rigid::NAME)
    }

    /// The materials the particles carry, one per table, from the tables' own
    /// (`built`): the table of a rigid body gives the zero-stress `Rigid` with
    /// its density instead, whatever its model (only its density acts on a
    /// rigid body; the validation refuses a table shared by a rigid and a
    /// continuum body).
    pub fn particle_materials(&self, mut built: Vec<Box<dyn Material>>) -> Vec<Box<dyn Material>> {
        for i in (0..self.bodies.len()).filter(|&i| self.body_kind(i) == BodyKindName::Rigid) {
            let table = (self.materials.iter()).position(|m| m.name == self.bodies[i].material);
            if let Some(k) = table {
                built[k] = Box::new(Rigid::new(self.materials[k].density));
            }
        }
        built
    }
}
