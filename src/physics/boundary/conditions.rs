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
/// every friction face's nodes stuck to the wall (no slip: at rest, or moving
/// with a shaken wall); on a corner shared with a face condition its
/// prescribed components win.
pub fn implicit_node_constraint<const D: usize>(
    grid: &Grid<D>,
    faces: &[FaceCondition<D>],
    friction: &[FrictionFace<D>],
    node: usize,
) -> Constraint<D> {
    let mut c = node_constraint(grid, faces, node);
    for f in node_friction(grid, friction, node) {
        let wall = friction[f as usize].velocity;
        for d in 0..D {
            if !c.fixed[d] {
                c.set(d, wall[d]);
            }
        }
    }
    c
}

/// The nodal velocity after contact with a rough rigid wall (`FrictionFace`),
/// on the velocity relative to the wall's, v_r = v − v_w. Approaching
/// (v_r·n > 0): the normal component is removed, Δv_n = v_r·n, and the
/// tangential slip speed drops by μ Δv_n, to zero at most (stick: v = v_w).
/// Separating: unchanged.
pub fn wall_contact<const D: usize>(wall: &FrictionFace<D>, v: &Vector<D>) -> Vector<D> {
    let n = wall.normal();
    let vr = v - wall.velocity;
    let vn = vr.dot(&n);
    if vn <= 0.0 {
        return *v;
    }
    let vt = vr - n * vn;
    let speed = vt.norm();
    let slip = speed - wall.coefficient * vn;
    if slip <= 0.0 {
        wall.velocity
    } else {
        wall.velocity + vt * (slip / speed)
    }
}

/// Indices of the friction faces node `node` lies on (empty for most nodes).
pub fn node_friction<const D: usize>(
    grid: &Grid<D>,
    faces: &[FrictionFace<D>],
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
    faces: &[FrictionFace<D>],
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

    fn base(mu: f64) -> FrictionFace<2> {
        FrictionFace {
            face: Face {
                axis: 1,
                upper: false,
            },
            coefficient: mu,
            velocity: Vector::<2>::zeros(),
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
            velocity: Vector::<3>::zeros(),
        };
        let v = wall_contact(&f, &Vector::<3>::new(3.0, 4.0, 5.0));
        // speed 5 − 0.2 × 5 = 4 along (3, 4)/5.
        assert!((v - Vector::<3>::new(2.4, 3.2, 0.0)).norm() < 1e-14);
    }

    /// A moving wall: the law acts on the velocity relative to the wall's. A
    /// node at rest on a wall sliding at (2, 0) is dragged by μ Δv_n towards the
    /// wall's velocity; one moving with the wall (and into it) sticks to it.
    #[test]
    fn a_moving_wall_drags_by_the_relative_velocity() {
        let wall = FrictionFace {
            velocity: Vector::<2>::new(2.0, 0.0),
            ..base(0.5)
        };
        // v_r = (−2, −1): slip 2 − 0.5 × 1 = 1.5 along −x, v = (2, 0) + (−1.5, 0).
        let v = wall_contact(&wall, &Vector::<2>::new(0.0, -1.0));
        assert!((v - Vector::<2>::new(0.5, 0.0)).norm() < 1e-14);
        let v = wall_contact(&wall, &Vector::<2>::new(2.3, -1.0));
        assert_eq!(v, wall.velocity);
        let free = Vector::<2>::new(0.0, 0.5);
        assert_eq!(wall_contact(&wall, &free), free);
    }
}
