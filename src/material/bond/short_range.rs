//! The short-range force of peridynamic particles that no intact bond joins
//! (Silling & Askari 2005 §5; LAMMPS PERI, survey-peridynamics.md §1.4): a
//! repulsion, per unit volume squared,
//!
//!   f = −(c_S/δ) (d − |y_j − y_i|) ŷ  while |y_j − y_i| < d, else 0,
//!
//! ŷ the unit vector from i to j, c_S = 15 c (`FACTOR`, c the body's PMB
//! micromodulus: its bonds' axial one), so two fragments of one body, or two
//! peridynamic bodies, that meet push each other apart instead of passing
//! through. Never an attraction.
//!
//! The contact distance d:
//! - two particles of one body: d = min(0.9 |ξ|, 1.35 (r_i + r_j)) (Silling &
//!   Askari's), |ξ| their reference distance, r = V^{1/D}/2 half the particle
//!   spacing; 0.9 |ξ| keeps the reference configuration free of it, so the
//!   faces of a fresh crack (at |ξ| ≈ Δx) feel it only when pressed 10 %
//!   closer than they started;
//! - particles of two bodies: d = r_i + r_j, the distance of the two centres
//!   when the bodies' faces touch (each centre half a spacing inside its
//!   face), so bodies laid face to face start at rest. Silling's 1.35 (r_i +
//!   r_j) there would throw touching faces apart at the first step.
//!
//! The pair of two bodies takes the mean of their c_S/δ.

use crate::dim::Vector;

/// Silling & Askari's c_S/c.
pub const FACTOR: f64 = 15.0;
/// Within a body, d is at most this fraction of the reference distance |ξ|…
pub const OF_REFERENCE: f64 = 0.9;
/// … and at most this multiple of r_i + r_j.
pub const OF_RADII: f64 = 1.35;

/// A body's short-range repulsion: its stiffness c_S/δ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShortRange {
    /// c_S/δ = factor × c / δ.
    pub stiffness: f64,
}

impl ShortRange {
    /// The repulsion of a body of micromodulus c and horizon δ, c_S = factor × c.
    pub fn new(factor: f64, micromodulus: f64, delta: f64) -> ShortRange {
        ShortRange {
            stiffness: factor * micromodulus / delta,
        }
    }

    /// The contact distance of two particles of one body, reference distance
    /// |ξ|, radii r_i and r_j.
    pub fn same_body_distance(length: f64, ri: f64, rj: f64) -> f64 {
        (OF_REFERENCE * length).min(OF_RADII * (ri + rj))
    }

    /// The contact distance of two particles of different bodies.
    pub fn other_body_distance(ri: f64, rj: f64) -> f64 {
        ri + rj
    }

    /// The repulsion on i from j (per unit volume squared) at positions y_i,
    /// y_j, contact distance d and stiffness k = c_S/δ: −k (d − |y|) ŷ, zero
    /// at and beyond d. Exactly the negative of j's from i.
    #[inline]
    pub fn pair_force<const D: usize>(
        stiffness: f64,
        yi: &Vector<D>,
        yj: &Vector<D>,
        d: f64,
    ) -> Option<Vector<D>> {
        let y = yj - yi;
        let l = y.norm();
        (l < d && l > 0.0).then(|| y * (-stiffness * (d - l) / l))
    }

    /// Half the particle spacing of a particle of volume V: V^{1/D}/2.
    pub fn radius<const D: usize>(volume: f64) -> f64 {
        0.5 * match D {
            2 => volume.sqrt(),
            _ => volume.cbrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::vector;

    #[test]
    fn the_repulsion_is_linear_in_the_overlap_opposite_and_never_an_attraction() {
        let (k, d) = (2.0e20, 1e-3);
        let (yi, yj) = (vector![0.0, 0.0], vector![0.6e-3, 0.8e-3]);
        // |y| = 1e-3: at d, nothing.
        assert_eq!(ShortRange::pair_force(k, &yi, &yj, d), None);
        let yj = yj * 0.5;
        let f = ShortRange::pair_force(k, &yi, &yj, d).unwrap();
        let back = ShortRange::pair_force(k, &yj, &yi, d).unwrap();
        assert_eq!(f, -back);
        // |f| = k (d − |y|), pointing from j to i.
        assert!((f.norm() / (k * 0.5e-3) - 1.0).abs() < 1e-14);
        assert!(f.dot(&(yj - yi)) < 0.0);
        // Beyond d, and at coincident centres, nothing.
        assert_eq!(ShortRange::pair_force(k, &yi, &(yj * 3.0), d), None);
        assert_eq!(ShortRange::pair_force(k, &yi, &yi, d), None);
    }

    #[test]
    fn the_contact_distances_leave_the_reference_configuration_at_rest() {
        let (dx, r) = (1e-3, 0.5e-3);
        assert_eq!(ShortRange::radius::<2>(dx * dx), r);
        assert!((ShortRange::radius::<3>(dx * dx * dx) / r - 1.0).abs() < 1e-15);
        // A lattice neighbour at Δx: 0.9 Δx; beyond the horizon 1.35 × 2r.
        assert_eq!(ShortRange::same_body_distance(dx, r, r), 0.9 * dx);
        assert_eq!(ShortRange::same_body_distance(4.0 * dx, r, r), 1.35 * dx);
        // Faces of two bodies touching: centres at Δx, d = Δx.
        assert_eq!(ShortRange::other_body_distance(r, r), dx);
    }
}
