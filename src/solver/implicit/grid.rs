//! The grid an implicit step is solved on: which particles it carries and
//! which nodes the bodies share.
//!
//! Without contact every particle is on the grid and the bodies share their
//! nodes. With the implicit contact (`terms::contact`):
//! - the particles of a body that meets the grid through contact only (a
//!   rigid body, `model::body::GridCoupling::ContactOnly`) are not part of
//!   the grid problem: their stencils are emptied (they touch no node, carry
//!   no mass and no unknown) and the committed step hands them the work their
//!   kind declares (`StepGrid::advance_off_grid`: a prescribed rigid motion
//!   moves them at their velocity); the contact sees the body through its
//!   `[[body]]` geometry;
//! - with contact between deformable bodies, every grid node that several
//!   bodies' fields touch is split into one node per field
//!   (`physics::contact::field_split`), so each body has its own displacement
//!   there. The field of every active node (`NodeFields`) is what the ties of
//!   weakly supported nodes must know (`super::ties`: a tie never crosses
//!   bodies), and what the contact between the bodies finds its meetings on.
//!
//! This is the one place that decides which particles are off the grid
//! (`StepGrid::for_contact`, from the body kinds) and the one place of the
//! implicit step that advances them (`StepGrid::advance_off_grid`).

use super::ties::NodeFields;
use crate::model::body::{Advance, GridCoupling};
use crate::model::Model;
use crate::physics::contact::field_split::FieldSplit;
use crate::physics::shape::{ShapeFunction, Stencils};
use crate::physics::transfer::{stencils, NodeMap};
use crate::scene::contact::ContactPlan;

/// Which particles a step's grid carries and how its nodes are split among
/// the bodies (module docs).
#[derive(Clone, Debug, Default)]
pub struct StepGrid {
    /// Whether each particle's body meets the grid through contact only
    /// (left off the grid); empty when every particle is on it.
    rigid: Vec<bool>,
    /// The fields of the deformable bodies in contact, each on nodes of its
    /// own where they meet (None: the bodies share nodes).
    split: Option<FieldSplit>,
    /// The field of every active node of this step (with a split).
    nodes: Option<NodeFields>,
}

impl StepGrid {
    /// The grid of model m with implicit contact under `plan`: the particles
    /// of the bodies that meet the grid through contact only off it and, with
    /// `split`, every field on nodes of its own where several meet.
    pub fn for_contact<const D: usize>(m: &Model<D>, plan: &ContactPlan, split: bool) -> Self {
        let p = &m.particles;
        let field: Vec<u32> = (p.body.iter())
            .map(|&b| plan.field_of_body[b as usize])
            .collect();
        StepGrid {
            rigid: (0..p.len())
                .map(|q| m.kind_of(q).meets_grid() == GridCoupling::ContactOnly)
                .collect(),
            split: split.then(|| FieldSplit::new(field)),
            nodes: None,
        }
    }

    /// The step's stencils at the particles' step-start positions and its
    /// active nodes: the rigid bodies' particles left out, shared nodes split
    /// (from the step-start particles).
    pub fn build<const D: usize>(
        &mut self,
        m: &Model<D>,
        shape: ShapeFunction,
        st: &mut Stencils<D>,
        map: &mut NodeMap,
    ) {
        stencils(m, shape, st);
        for q in (0..self.rigid.len()).filter(|&q| self.rigid[q]) {
            st.count[q] = 0;
        }
        let n_grid = m.grid.node_count();
        let Some(split) = self.split.as_mut() else {
            map.build(st, n_grid);
            return;
        };
        split.split(st, map, n_grid);
        let owner = st.owner();
        let of = (0..map.len())
            .map(|a| split.field(owner.of(map.node_entries(a)[0])))
            .collect();
        self.nodes = Some(NodeFields::new(map, of));
    }

    /// Whether particle q belongs to a rigid body (it stays off the grid).
    pub fn is_rigid(&self, q: usize) -> bool {
        self.rigid.get(q).copied().unwrap_or(false)
    }

    /// The fields' split of the shared nodes (None: the bodies share nodes).
    pub fn split(&self) -> Option<&FieldSplit> {
        self.split.as_ref()
    }

    /// The field of every active node of this step, with a split.
    pub fn node_fields(&self) -> Option<&NodeFields> {
        self.nodes.as_ref()
    }

    /// The converged step hands each particle off the grid the work its
    /// body's kind declares (`model::body::Advance`).
    pub fn advance_off_grid<const D: usize>(&self, m: &mut Model<D>, dt: f64) {
        for q in (0..self.rigid.len()).filter(|&q| self.rigid[q]) {
            match m.kind_of(q).advance() {
                // x += v Δt: a prescribed rigid motion.
                Advance::AtOwnVelocity => {
                    let v = m.particles.v[q];
                    m.particles.x[q] += v * dt;
                }
                // On the grid, so never here; a free rigid body is refused
                // in implicit contact, a peridynamic body on implicit stages
                // (`scene::validate`).
                Advance::ByGrid | Advance::NewtonEuler | Advance::ByBonds => {}
            }
        }
    }
}
