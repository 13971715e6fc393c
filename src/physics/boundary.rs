//! Velocity conditions on grid faces: fixed, roller and prescribed velocity. A
//! condition acts on the layer of nodes on its face (for clamped B-splines, the
//! control points that interpolate the face), component by component, or only on
//! the nodes of that layer inside a box (`region`, e.g. a rigid footing).

use crate::dim::Vector;
use crate::model::grid::{Face, Grid};

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

/// The constraint of node `node` in an implicit step: the face conditions, and
/// every friction face held fixed (no slip: a rough rigid base at rest); on a
/// corner shared with a face condition its prescribed components win.
pub fn implicit_node_constraint<const D: usize>(
    grid: &Grid<D>,
    faces: &[FaceCondition<D>],
    friction: &[FrictionFace],
    node: usize,
) -> Constraint<D> {
    let mut c = node_constraint(grid, faces, node);
    if !node_friction(grid, friction, node).is_empty() {
        for d in 0..D {
            if !c.fixed[d] {
                c.set(d, 0.0);
            }
        }
    }
    c
}

/// A rigid face with Coulomb friction (a rough base): a node on the face may
/// separate from it, but not move into it, and slides along it only against a
/// friction impulse of at most μ times the normal impulse (rigid-wall contact in
/// the manner of Bardenhagen et al. 2001, with the wall as the rigid body).
#[derive(Clone, Copy, Debug)]
pub struct FrictionFace {
    pub face: Face,
    /// Coulomb friction coefficient μ ≥ 0 (0: a roller that lets go).
    pub coefficient: f64,
}

impl FrictionFace {
    /// Unit outward normal of the face (out of the grid, into the wall).
    pub fn normal<const D: usize>(&self) -> Vector<D> {
        let mut n = Vector::<D>::zeros();
        n[self.face.axis] = if self.face.upper { 1.0 } else { -1.0 };
        n
    }

    /// The nodal velocity after contact with the wall. Approaching (v·n > 0): the
    /// normal component is removed, Δv_n = v·n, and the tangential speed drops by
    /// μ Δv_n, to zero at most (stick). Separating: unchanged.
    pub fn contact<const D: usize>(&self, v: &Vector<D>) -> Vector<D> {
        let n = self.normal::<D>();
        let vn = v.dot(&n);
        if vn <= 0.0 {
            return *v;
        }
        let vt = v - n * vn;
        let speed = vt.norm();
        let slip = speed - self.coefficient * vn;
        if slip <= 0.0 {
            Vector::<D>::zeros()
        } else {
            vt * (slip / speed)
        }
    }
}

/// Indices of the friction faces node `node` lies on (empty for most nodes).
pub fn node_friction<const D: usize>(
    grid: &Grid<D>,
    faces: &[FrictionFace],
    node: usize,
) -> Vec<u8> {
    let ijk = grid.node_ijk(node);
    (0..faces.len())
        .filter(|&f| grid.on_face(ijk, faces[f].face))
        .map(|f| f as u8)
        .collect()
}

/// Apply the friction faces `on` (from `node_friction`) to a nodal velocity, then
/// the prescribed components of `constraint` (which win on a shared corner).
pub fn friction_contact<const D: usize>(
    faces: &[FrictionFace],
    on: &[u8],
    constraint: &Constraint<D>,
    v: &Vector<D>,
) -> Vector<D> {
    let mut v = on.iter().fold(*v, |v, &f| faces[f as usize].contact(&v));
    constraint.apply_velocity(&mut v);
    v
}

#[cfg(test)]
mod friction_tests {
    use super::*;

    fn base(mu: f64) -> FrictionFace {
        FrictionFace {
            face: Face {
                axis: 1,
                upper: false,
            },
            coefficient: mu,
        }
    }

    #[test]
    fn approaching_node_slides_with_reduced_speed() {
        // v = (3, −1) into the ymin wall: Δv_n = 1, speed 3 − 0.5 × 1.
        let v = base(0.5).contact(&Vector::<2>::new(3.0, -1.0));
        assert!((v - Vector::<2>::new(2.5, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn approaching_node_sticks_when_friction_suffices() {
        let v = base(0.5).contact(&Vector::<2>::new(-0.4, -1.0));
        assert_eq!(v, Vector::<2>::zeros());
    }

    #[test]
    fn separating_node_is_free() {
        let v = Vector::<2>::new(3.0, 0.5);
        assert_eq!(base(10.0).contact(&v), v);
    }

    #[test]
    fn tangential_direction_is_kept_in_3d() {
        let f = FrictionFace {
            face: Face {
                axis: 2,
                upper: true,
            },
            coefficient: 0.2,
        };
        let v = f.contact(&Vector::<3>::new(3.0, 4.0, 5.0));
        // speed 5 − 0.2 × 5 = 4 along (3, 4)/5.
        assert!((v - Vector::<3>::new(2.4, 3.2, 0.0)).norm() < 1e-14);
    }
}
