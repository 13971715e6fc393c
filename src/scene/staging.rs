//! Staged construction in a scene (docs/staging.md): the bodies by name, those
//! that start inactive and those the stages activate up to a stage
//! (`model::staging` applies the changes; the keys are `SolverConfig`'s, the
//! regions `region::RegionConfig`).

use crate::scene::{BodyKindName, SceneConfig};

impl SceneConfig {
    /// Whether the scene stages its construction: a body starts inactive or a
    /// stage changes the model at its start.
    pub fn stages_construction(&self) -> bool {
        self.bodies.iter().any(|b| b.active == Some(false))
            || self.stages.iter().any(|st| st.changes_model())
    }

    /// The bodies named `name` (a name may group several, as for contact).
    pub fn bodies_named(&self, name: &str) -> Vec<usize> {
        (0..self.bodies.len())
            .filter(|&i| self.bodies[i].name.as_deref() == Some(name))
            .collect()
    }

    /// The bodies that start inactive (`active = false`).
    pub fn inactive_bodies(&self) -> Vec<usize> {
        (0..self.bodies.len())
            .filter(|&i| self.bodies[i].active == Some(false))
            .collect()
    }

    /// The bodies activated by stages 0..=k (validated names).
    pub fn activated_by_stage(&self, k: usize) -> Vec<usize> {
        (self.stages.iter().take(k + 1))
            .flat_map(|st| st.activate.iter().flatten())
            .flat_map(|name| self.bodies_named(name))
            .collect()
    }

    /// Whether body i is a continuum body (the kind staging applies to).
    pub fn is_continuum(&self, i: usize) -> bool {
        self.body_kind(i) == BodyKindName::Continuum
    }
}
