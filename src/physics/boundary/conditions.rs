//! The laws of the grid-face conditions (`model::conditions`): the constraint of
//! each node from the velocity conditions of the faces it lies on, and rigid-wall
//! contact with Coulomb friction on rough faces.

use crate::dim::Vector;
use crate::model::conditions::{Constraint, FaceCondition, FrictionFace};
use crate::model::grid::Grid;

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

/// The nodal velocity after contact with a rough rigid wall (`FrictionFace`). Approaching (v·n > 0): the
/// normal component is removed, Δv_n = v·n, and the tangential speed drops by
/// μ Δv_n, to zero at most (stick). Separating: unchanged.
pub fn wall_contact<const D: usize>(wall: &FrictionFace, v: &Vector<D>) -> Vector<D> {
    let n = wall.normal::<D>();
    let vn = v.dot(&n);
    if vn <= 0.0 {
        return *v;
    }
    let vt = v - n * vn;
    let speed = vt.norm();
    let slip = speed - wall.coefficient * vn;
    if slip <= 0.0 {
        Vector::<D>::zeros()
    } else {
        vt * (slip / speed)
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
    let mut v = on
        .iter()
        .fold(*v, |v, &f| wall_contact(&faces[f as usize], &v));
    constraint.apply_velocity(&mut v);
    v
}

#[cfg(test)]
mod friction_tests {
    use super::*;
    use crate::scene::Face;

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
        let v = wall_contact(&base(0.5), &Vector::<2>::new(3.0, -1.0));
        assert!((v - Vector::<2>::new(2.5, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn approaching_node_sticks_when_friction_suffices() {
        let v = wall_contact(&base(0.5), &Vector::<2>::new(-0.4, -1.0));
        assert_eq!(v, Vector::<2>::zeros());
    }

    #[test]
    fn separating_node_is_free() {
        let v = Vector::<2>::new(3.0, 0.5);
        assert_eq!(wall_contact(&base(10.0), &v), v);
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
        let v = wall_contact(&f, &Vector::<3>::new(3.0, 4.0, 5.0));
        // speed 5 − 0.2 × 5 = 4 along (3, 4)/5.
        assert!((v - Vector::<3>::new(2.4, 3.2, 0.0)).norm() < 1e-14);
    }
}
