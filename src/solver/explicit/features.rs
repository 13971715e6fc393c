//! What every feature of the explicit step needs of the transfer back-end
//! (`solver::explicit::step`), and the back-end a step takes from that.
//!
//! Each feature declares the back-ends that serve it (`Feature::served_by`)
//! and says whether a step has it (`Feature::in_step`); both are exhaustive
//! matches, so a new feature cannot be added without declaring them. A step
//! runs on the box scatter unless one of its features needs the node map (or
//! the scene asks for the node map: `solver.transfer = "gather"`). The tests
//! run every feature on both back-ends where both serve it and compare them
//! (`tests/solvers/transfers.rs`).

use crate::model::Model;
use crate::scene::{Scheme, ShapeFunction};
use crate::solver::explicit::node_box::NodeBox;
use crate::solver::explicit::step::Step;
use strum::EnumIter;

/// A feature of the explicit step beyond its core (P2G, the grid update with
/// gravity, loads, local damping and the face conditions, G2P with the
/// PIC/FLIP blend, the stress update).
#[derive(Clone, Copy, Debug, PartialEq, Eq, EnumIter)]
pub enum Feature {
    /// Contact between bodies: velocity fields on split nodes
    /// (`solver::explicit::contact`).
    Contact,
    /// Rigid bodies, of prescribed motion or free (Newton–Euler), met through
    /// contact (`physics::rigid`).
    RigidBodies,
    /// F-bar against volumetric locking (`physics::kinematics::fbar`).
    Fbar,
    /// Artificial bulk viscosity (`solver::explicit::bulk_viscosity`).
    BulkViscosity,
    /// Absorbing faces (`physics::boundary::absorbing`).
    AbsorbingFaces,
    /// The hoop terms of the axisymmetric mode (`physics::shape::hoop`).
    Axisymmetry,
    /// Shape functions that are no tensor product of 1D factors (CPDI).
    NonSeparableShape,
    /// Particles removed from the transfers: eroded, or outside the grid.
    RemovedParticles,
    /// The mirror of cubic and domain B-splines at faces with prescribed
    /// velocities (`solver::explicit::mirror`).
    Mirror,
    /// USF with a family that reads F (cpGIMP, domain B-splines): its force
    /// scatter, after the stress update, must see the step-start domains.
    UsfReadingF,
    /// APIC (`solver::explicit::apic`).
    Apic,
    /// Rough rigid faces with Coulomb friction (`physics::boundary::conditions`).
    FrictionFaces,
    /// Peridynamic bodies, advanced by their bonds (`physics::peridynamics`).
    PeridynamicBodies,
    /// Darcy flow of coupled pore water between particles (`physics::pore_flow`).
    PoreFlow,
}

/// The transfer back-ends that serve a feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Serves {
    /// The node map and the box scatter.
    Both,
    /// The node map only.
    NodeMap,
}

impl Feature {
    /// The back-ends that serve the feature, and why not the scatter.
    pub fn served_by(self) -> Serves {
        match self {
            // Split nodes: a grid node holds one velocity per field, which a
            // box of one value per grid node cannot.
            Feature::Contact | Feature::RigidBodies => Serves::NodeMap,
            // The box's stencils are tensor products of 1D factors.
            Feature::NonSeparableShape => Serves::NodeMap,
            // Lines of nodes normal to a face, through the node map's indices.
            Feature::Mirror => Serves::NodeMap,
            // The box evaluates the stencils again for the force after the
            // stress update: they would see the updated F.
            Feature::UsfReadingF => Serves::NodeMap,
            // Advanced at the one site that hands each body kind its work,
            // `NodeMapStep::advance_bodies`.
            Feature::PeridynamicBodies => Serves::NodeMap,
            // Its nodal sums gather through the node map's stored stencils
            // after the stress update; the box keeps no stencils.
            Feature::PoreFlow => Serves::NodeMap,
            Feature::Fbar
            | Feature::BulkViscosity
            | Feature::AbsorbingFaces
            | Feature::Axisymmetry
            | Feature::RemovedParticles
            | Feature::Apic
            | Feature::FrictionFaces => Serves::Both,
        }
    }

    /// Does the step `s` of model m have the feature?
    pub fn in_step<const D: usize>(self, s: &Step<D>, m: &Model<D>) -> bool {
        match self {
            Feature::Contact => m.contact.is_some(),
            Feature::RigidBodies => m.contact.as_ref().is_some_and(|c| c.rigid.contains(&true)),
            Feature::Fbar => s.fbar,
            Feature::BulkViscosity => s.viscosity.is_some(),
            Feature::AbsorbingFaces => !m.absorbing.faces.is_empty(),
            Feature::Axisymmetry => m.axisymmetric,
            Feature::NonSeparableShape => !NodeBox::<D>::serves(s.shape),
            Feature::RemovedParticles => m.removes_particles(),
            Feature::Mirror => {
                let prescribed = m.faces.iter().any(|fc| fc.constraint.fixed.contains(&true));
                s.shape != ShapeFunction::Bspline2 && (2..=3).contains(&m.grid.degree) && prescribed
            }
            Feature::UsfReadingF => s.scheme == Scheme::Usf && s.shape.reads_deformation(),
            Feature::Apic => s.apic,
            Feature::FrictionFaces => !m.friction.is_empty(),
            Feature::PeridynamicBodies => m.peridynamics.is_some(),
            Feature::PoreFlow => m.drainage.is_some(),
        }
    }
}

/// Does the step `s` of model m need the node map: has it a feature that
/// only the node map serves?
pub fn needs_node_map<const D: usize>(s: &Step<D>, m: &Model<D>) -> bool {
    use strum::IntoEnumIterator;
    Feature::iter().any(|f| f.served_by() == Serves::NodeMap && f.in_step(s, m))
}
