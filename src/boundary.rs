//! Velocity conditions on grid faces: fixed, roller and prescribed velocity. A
//! condition acts on the layer of nodes on its face (for clamped B-splines, the
//! control points that interpolate the face), component by component, or only on
//! the nodes of that layer inside a box (`region`, e.g. a rigid footing).

use crate::dim::Vector;
use crate::grid::{Face, Grid};

/// Which velocity components of a node are prescribed, and their values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint<const D: usize> {
    pub fixed: [bool; D],
    pub value: Vector<D>,
}

impl<const D: usize> Constraint<D> {
    pub fn free() -> Self {
        Constraint {
            fixed: [false; D],
            value: Vector::<D>::zeros(),
        }
    }

    pub fn set(&mut self, d: usize, v: f64) {
        self.fixed[d] = true;
        self.value[d] = v;
    }

    pub fn is_free(&self) -> bool {
        !self.fixed.iter().any(|&f| f)
    }

    /// Overwrite the prescribed components of a nodal velocity.
    pub fn apply_velocity(&self, v: &mut Vector<D>) {
        for d in 0..D {
            if self.fixed[d] {
                v[d] = self.value[d];
            }
        }
    }

    /// Zero the prescribed components of a nodal acceleration or force.
    pub fn apply_rate(&self, a: &mut Vector<D>) {
        for d in 0..D {
            if self.fixed[d] {
                a[d] = 0.0;
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct FaceCondition<const D: usize> {
    pub face: Face,
    pub constraint: Constraint<D>,
    /// Only the face nodes whose position lies in this box [min, max] (None: all).
    pub region: Option<(Vector<D>, Vector<D>)>,
}

impl<const D: usize> FaceCondition<D> {
    /// Does the condition act on node `ijk`? Node positions are the Greville
    /// abscissae (the nodes themselves for linear and GIMP shapes); the box is
    /// widened by 1e-9 of a cell so that nodes on its edges belong to it.
    pub fn acts_on(&self, grid: &Grid<D>, ijk: [usize; D]) -> bool {
        if !grid.on_face(ijk, self.face) {
            return false;
        }
        let Some((lo, hi)) = &self.region else {
            return true;
        };
        let x = grid.node_position(ijk);
        (0..D).all(|d| {
            let tol = 1e-9 * grid.h[d];
            x[d] >= lo[d] - tol && x[d] <= hi[d] + tol
        })
    }
}

/// The combined constraint of node `node` from all face conditions (a corner node
/// collects the components of every face it lies on).
pub fn node_constraint<const D: usize>(
    grid: &Grid<D>,
    faces: &[FaceCondition<D>],
    node: usize,
) -> Constraint<D> {
    let ijk = grid.node_ijk(node);
    let mut c = Constraint::free();
    for fc in faces.iter().filter(|fc| fc.acts_on(grid, ijk)) {
        for d in 0..D {
            if fc.constraint.fixed[d] {
                c.set(d, fc.constraint.value[d]);
            }
        }
    }
    c
}
