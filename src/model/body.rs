//! The bodies of the model: each is a geometry, filled with particles
//! (`build.rs`), and a kind, which says what the solvers do with those
//! particles. A kind declares, for the solvers to ask:
//!
//! - how its particles are advanced over a step (`BodyKind::advance`): by the
//!   grid (G2P), at their own velocity (a prescribed rigid motion), or as one
//!   rigid body by Newton–Euler (`physics::rigid::newton_euler`);
//! - how they meet the grid (`BodyKind::meets_grid`): integrated (their mass,
//!   momentum, stress and internal force go to the nodes), or through contact
//!   only. A rigid body's particles mark out a velocity field of its own whose
//!   nodes move with the body and have infinite mass in the contact
//!   (`solver::explicit::contact`), or they stay off the grid and the body's
//!   geometry is the master surface of a penalty (`solver::implicit::terms::contact`).
//!
//! | kind              | advanced           | meets the grid |
//! |-------------------|--------------------|----------------|
//! | continuum         | by the grid        | integrated     |
//! | rigid, prescribed | at its velocity    | contact only   |
//! | rigid, free       | by Newton–Euler    | contact only   |
//! | peridynamic       | by its bonds       | contact only   |
//!
//! A peridynamic body (`physics::peridynamics`) is advanced by the forces of
//! its bonds, gravity and loads, by central differences, in the explicit step
//! (`NodeMapStep::advance_bodies`); its particles carry the zero-stress
//! `Rigid` with its material's density, so the grid adds no internal force to
//! them. In this slice it is alone in its scene, on explicit stages
//! (`scene::validate::peridynamic`), so it meets no other body; its particles'
//! mass and momentum still go to the nodes, which nothing reads back.
//!
//! The scene gives the kind: `[[body]] kind` and `motion`, or the old form, a
//! material with `model = "rigid"` (`SceneConfig::body_kind`, `rigid_motion`).
//! The particles of a rigid body carry the zero-stress
//! `material::rigid::Rigid` with the density of the body's material
//! (`SceneConfig::particle_materials`), so every transfer works on them unchanged.
//! The contact plan's per-field flags (`ContactPlan::rigid`, `free`) come from
//! the same kinds; a rigid body has a velocity field of its own.
//!
//! A new kind (a peridynamic body, say: advanced by its own bond forces,
//! meeting the grid through contact) adds, in this order:
//! 1. its name in `scene::BodyKindName` and its keys: read in
//!    `SceneConfig::body_kind`, checked in `scene::validate::grid_bodies::kind`,
//!    documented in docs/scene.md;
//! 2. its variant of `BodyKind`, built in `BodyKind::of`;
//! 3. its answers to `advance` and `meets_grid`, with a new `Advance` or
//!    `GridCoupling` where no existing one says what it does;
//! 4. its work at each solver's one site that hands every kind its work (the
//!    explicit step after G2P, `NodeMapStep::advance_bodies` and
//!    `takes_load_work` in `solver/explicit/gather.rs`; the implicit step at
//!    commit, `StepGrid::advance_off_grid`), which match on `Advance`
//!    exhaustively, and at the sites that ask how it meets the grid (the
//!    implicit step's particles off the grid, `StepGrid::for_contact`; the
//!    contact fields: `ContactPlan::rigid` and `free`, filled from the kinds,
//!    read in `solver::explicit::contact`, `solver::implicit::terms::contact`
//!    and `physics::rigid`);
//! 5. the material its particles carry, where its table's constitutive model
//!    should not act (`SceneConfig::particle_materials`), and whether it
//!    carries stress (`carries_stress`: K0 states).

use crate::material::rigid::Motion;
use crate::model::geometry::Geometry;
use crate::scene::{BodyKindName, SceneConfig};

/// One body: its geometry (by `Particles::body`) and its kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub geometry: Geometry,
    pub kind: BodyKind,
}

impl Body {
    /// Body i of a validated scene, with its geometry (from its keys or its
    /// file: `model::import::body_geometry`).
    pub fn of(c: &SceneConfig, i: usize, geometry: Geometry) -> Body {
        Body {
            geometry,
            kind: BodyKind::of(c, i),
        }
    }
}

/// What a body is, for the solvers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// Deformable, with its material's constitutive model, integrated
    /// through the grid.
    Continuum,
    /// Rigid, meeting the other bodies through contact only.
    Rigid { motion: Motion },
    /// Bond-based peridynamic (`physics::peridynamics`).
    Peridynamic,
}

/// How a kind's particles are advanced over a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Advance {
    /// By the grid: G2P from the nodal velocities and accelerations.
    ByGrid,
    /// At their own velocity, x += v Δt (a prescribed rigid motion: the
    /// body's nodes move at it, so the explicit G2P keeps it; the work done on
    /// the body is the motion's, not counted).
    AtOwnVelocity,
    /// As one rigid body under the contact impulses, gravity and loads
    /// (`physics::rigid::newton_euler`).
    NewtonEuler,
    /// By the forces of their bonds, gravity and loads, by central
    /// differences (`physics::peridynamics::advance`).
    ByBonds,
}

/// How a kind's particles meet the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridCoupling {
    /// Mass, momentum, stress and internal force go to the nodes.
    Integrated,
    /// Through contact only: a velocity field of its own moving with the body
    /// (explicit), or off the grid as a penalty's master surface (implicit).
    ContactOnly,
}

impl BodyKind {
    /// The kind of body i of a validated scene.
    pub fn of(c: &SceneConfig, i: usize) -> BodyKind {
        match c.body_kind(i) {
            BodyKindName::Continuum => BodyKind::Continuum,
            BodyKindName::Rigid => BodyKind::Rigid {
                motion: c.rigid_motion(i),
            },
            BodyKindName::Peridynamic => BodyKind::Peridynamic,
        }
    }

    pub fn advance(self) -> Advance {
        match self {
            BodyKind::Continuum => Advance::ByGrid,
            BodyKind::Rigid {
                motion: Motion::Prescribed,
            } => Advance::AtOwnVelocity,
            BodyKind::Rigid {
                motion: Motion::Free,
            } => Advance::NewtonEuler,
            BodyKind::Peridynamic => Advance::ByBonds,
        }
    }

    pub fn meets_grid(self) -> GridCoupling {
        match self {
            BodyKind::Continuum => GridCoupling::Integrated,
            BodyKind::Rigid { .. } | BodyKind::Peridynamic => GridCoupling::ContactOnly,
        }
    }

    /// Whether its particles carry a stress (a K0 state, a stress update): those
    /// integrated through the grid.
    pub fn carries_stress(self) -> bool {
        self.meets_grid() == GridCoupling::Integrated
    }

    pub fn is_rigid(self) -> bool {
        matches!(self, BodyKind::Rigid { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_declares_the_table_of_the_module_doc() {
        let prescribed = BodyKind::Rigid {
            motion: Motion::Prescribed,
        };
        let free = BodyKind::Rigid {
            motion: Motion::Free,
        };
        let declared = |k: BodyKind| {
            (
                k.advance(),
                k.meets_grid(),
                k.carries_stress(),
                k.is_rigid(),
            )
        };
        use {Advance::*, GridCoupling::*};
        assert_eq!(
            declared(BodyKind::Continuum),
            (ByGrid, Integrated, true, false)
        );
        assert_eq!(
            declared(prescribed),
            (AtOwnVelocity, ContactOnly, false, true)
        );
        assert_eq!(declared(free), (NewtonEuler, ContactOnly, false, true));
        assert_eq!(
            declared(BodyKind::Peridynamic),
            (ByBonds, ContactOnly, false, false)
        );
    }
}
