//! Penalty contact in the implicit solver (quasi-static and Newmark), as two
//! terms of the step (`super::StepTerm`):
//!
//! - [`rigid`]: deformable particles against rigid bodies with a prescribed
//!   motion, at the particles' centres or their contact points ([`points`]);
//! - [`bodies`]: two deformable bodies, each on nodes of its own where they
//!   meet, a penalty between their displacements at the meetings.
//!
//! Both use the penalty law of [`penalty`] (normal penalty, Coulomb-regularised
//! tangential force and their derivative) and carry what [`state`] describes
//! from step to step (tangential forces, contact points, the meetings' gaps)
//! and into checkpoints and contact.csv. What the contact asks of the grid (a
//! rigid body's particles off it, deformable bodies on split nodes) is the
//! step's grid, `super::super::grid::StepGrid`, set up here with the terms.

pub(crate) mod bodies;
pub(crate) mod penalty;
pub(crate) mod points;
pub(crate) mod rigid;
pub(crate) mod state;

use crate::model::Model;
use crate::physics::rigid::surface::rigid_surfaces;
use crate::solver::implicit::grid::StepGrid;
use bodies::BodyContact;
use rigid::RigidContact;

/// The implicit contact of a model: the grid it asks for and its terms.
pub struct Contact<const D: usize> {
    pub grid: StepGrid,
    pub rigid: Option<RigidContact<D>>,
    pub bodies: Option<BodyContact<D>>,
}

/// The contact of model m, or None without a pair in contact (a scene
/// without `[[contact]]`, or whose rigid bodies meet no deformable body and
/// whose deformable bodies meet none of each other).
pub fn of<const D: usize>(m: &Model<D>) -> Option<Contact<D>> {
    let plan = m.contact.as_ref()?;
    let p = &m.particles;
    let field: Vec<u32> = (p.body.iter())
        .map(|&b| plan.field_of_body[b as usize])
        .collect();
    let paired = |k: usize| (0..plan.fields).any(|j| plan.law(k as u32, j as u32).is_some());
    let surfaces = rigid_surfaces(plan, m, &field, &paired);
    let rigid = RigidContact::new(m, plan, &field, surfaces);
    let bodies = BodyContact::new(plan);
    if rigid.is_none() && bodies.is_none() {
        return None;
    }
    Some(Contact {
        grid: StepGrid::for_contact(m, plan, bodies.is_some()),
        rigid,
        bodies,
    })
}
