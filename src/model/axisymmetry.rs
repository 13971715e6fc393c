//! The axisymmetric model's measures (`dimension = "axisymmetric"`): a solid of
//! revolution about the y axis on the r–z half plane, x = r ≥ 0, y = z.
//!
//! Every integral over the solid is ∫ (·) r dr dz dθ; the model keeps the
//! integrand per radian: a particle of area A_p at radius r_p has the volume
//! V_p = r_p A_p and the mass m_p = ρ r_p A_p (per radian: 2π V_p is the ring's
//! volume), and a traction on one of its faces acts over that face's area per
//! radian. Gravity, the nodal masses, momenta and forces, reactions and energies
//! built from them are then per radian too. The hoop terms of the kinematics
//! and of the internal force are in `physics::shape::hoop`.

use crate::dim::Vector;
use crate::model::conditions::{Constraint, FaceCondition};
use crate::model::particles::Particles;
use crate::scene::Face;

/// Make the last `added` particles' volumes and masses per radian: × r_p
/// (V = ∫ r dA over the particle's rectangular domain centred at r_p: exactly
/// r_p A_p).
pub fn per_radian<const D: usize>(p: &mut Particles<D>, added: usize) {
    let n = p.len();
    for q in n - added..n {
        let r = p.x[q][0];
        p.mass[q] *= r;
        p.volume[q] *= r;
        p.volume0[q] *= r;
    }
}

/// The area per radian of the face of a particle's reference domain (centre x,
/// half-lengths `half`) on `face`: ∫ r ds along it. A face normal to r sits at
/// r_p ± l_r (area (r_p ± l_r) 2 l_z); a face normal to z spans r_p − l_r …
/// r_p + l_r (area 2 l_r r_p).
pub fn face_area_per_radian<const D: usize>(x: &Vector<D>, half: &Vector<D>, face: Face) -> f64 {
    if face.axis == 0 {
        let r = if face.upper {
            x[0] + half[0]
        } else {
            x[0] - half[0]
        };
        r * 2.0 * half[1]
    } else {
        2.0 * half[0] * x[0]
    }
}

/// The axis r = 0 (the grid's xmin face when it starts at x = 0): zero radial
/// velocity by symmetry. Added to the scene's conditions, so a node on the axis
/// never moves off it and no particle reaches r ≤ 0.
pub fn axis_condition<const D: usize>() -> FaceCondition<D> {
    let mut constraint = Constraint::<D>::free();
    constraint.set(0, 0.0);
    FaceCondition {
        face: Face {
            axis: 0,
            upper: false,
        },
        constraint,
        region: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The per-radian areas of the faces of the domain [1, 1.5] × [0, 2]
    /// against their closed forms.
    #[test]
    fn face_areas_per_radian() {
        let x = Vector::<2>::new(1.25, 1.0);
        let half = Vector::<2>::new(0.25, 1.0);
        let area = |axis, upper| face_area_per_radian(&x, &half, Face { axis, upper });
        assert!((area(0, false) - 1.0 * 2.0).abs() < 1e-15);
        assert!((area(0, true) - 1.5 * 2.0).abs() < 1e-15);
        // ∫_1^1.5 r dr = (1.5² − 1²)/2 = 0.625.
        assert!((area(1, false) - 0.625).abs() < 1e-15);
        assert!((area(1, true) - 0.625).abs() < 1e-15);
    }
}
