//! The optional terms of a model's implicit step, in the order they add into
//! r and K: the one place that names them all. A new term is a type that
//! implements `StepTerm`, and a line here.

use super::absorbing::AbsorbingFaces;
use super::contact;
use super::linear_stress::LinearDomainStress;
use super::StepTerm;
use crate::model::Model;
use crate::solver::implicit::grid::StepGrid;

/// The terms of model m (set up once per stage; each step begins them anew)
/// and the step's grid: the linear domain stress (part of the internal
/// force), the absorbing faces, then the contact with rigid bodies and
/// between deformable bodies.
pub fn step_terms<const D: usize>(m: &Model<D>) -> (StepGrid, Vec<Box<dyn StepTerm<D>>>) {
    let mut terms: Vec<Box<dyn StepTerm<D>>> = Vec::new();
    if let Some(linear) = LinearDomainStress::new(m) {
        terms.push(Box::new(linear));
    }
    if let Some(absorbing) = AbsorbingFaces::new(m) {
        terms.push(Box::new(absorbing));
    }
    let Some(contact) = contact::of(m) else {
        return (StepGrid::default(), terms);
    };
    if let Some(rigid) = contact.rigid {
        terms.push(Box::new(rigid));
    }
    if let Some(bodies) = contact.bodies {
        terms.push(Box::new(bodies));
    }
    (contact.grid, terms)
}
