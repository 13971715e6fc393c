//! Rigid bodies are impenetrable (explicit solver; `[[contact]]` key
//! `rigid_projection`, on by default).
//!
//! Node-based contact (`solver::explicit::contact`) acts at grid nodes, so a deformable
//! particle can enter a rigid body by up to about a cell before the nodes it
//! touches stop it: in a penetration, concrete that the nose carries along the
//! axis ends up inside the shank and is crushed there
//! (papers/penetration_hanchak). A rigid body's shape is known exactly, its
//! `[[body]]` geometry carried by its rigid motion, so after G2P a deformable
//! particle whose centre lies inside a rigid body it is in contact with is put
//! on the body's nearest surface point, and its velocity relative to the body
//! loses its inward normal part: w·n < 0 ⇒ v ← v − (w·n) n, w = v − u_body(x).
//! Frictionless: friction acts at the nodes. The particle's momentum change goes
//! to the body, equal and opposite (a free body takes it as an impulse at that
//! point, `FreeBodies::kick`; a prescribed one absorbs it), and to the pair's
//! contact force.
//!
//! The placement of a rigid body comes from its particles: centre
//! c = Σ m x / M, reference centre c⁰ = Σ m X / M, and the rotation Q taking the
//! reference offsets to the current ones, the polar factor of
//! A = Σ m (x − c)(X − c⁰)ᵀ (in 2D θ = atan2(A₁₀ − A₀₁, A₀₀ + A₁₁); none for a
//! prescribed motion or in axisymmetric mode). A point x is then at
//! X = c⁰ + Qᵀ(x − c) in the body's `[[body]]` geometry. Faces on a plane of the
//! grid's boundary (the axis, a symmetry plane) are not surface.

use crate::dim::{polar_rotation, restrict, Mat3, Tensor, Vector};
use crate::model::geometry::{Bend, Geometry};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::physics::rigid::newton_euler::{from3, to3};
use crate::scene::contact::ContactPlan;
use nalgebra::Vector3;

/// A particle whose reach falls short of a rigid surface by this fraction of
/// the reach touches it (depth 0: no force, but the stiffness). Surfaces laid
/// to coincide differ by round-off: a block's particles filled from y = 0.25
/// with spacing 0.025 lie 0.012500000000000011 above it with a reach of
/// 0.0125, and a block resting there started with no support at all (a
/// singular first tangent).
const TOUCH_TOLERANCE: f64 = 1e-9;

/// One rigid velocity field: its particles and the geometries of its bodies.
#[derive(Clone, Debug)]
pub struct Surface {
    pub field: u32,
    members: Vec<usize>,
    shapes: Vec<Geometry>,
    /// Bounds of the union of `shapes`, reference configuration.
    lower: Vector3<f64>,
    upper: Vector3<f64>,
    mass: f64,
    centre0: Vector3<f64>,
    rotates: bool,
}

/// Where a rigid field is now: x = c + Q (X − c⁰).
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    centre: Vector3<f64>,
    centre0: Vector3<f64>,
    rotation: Mat3,
}

/// A particle to put back on a rigid body's surface.
#[derive(Clone, Copy, Debug)]
pub struct Push<const D: usize> {
    pub particle: usize,
    /// The rigid field.
    pub field: u32,
    /// The surface point (new position) and the outward normal there.
    pub x: Vector<D>,
    pub normal: Vector<D>,
    /// The body's velocity at x.
    pub body_velocity: Vector<D>,
}

impl Surface {
    /// The rigid field `field` made of `members` (particles) and `shapes`
    /// (its bodies' geometries); `rotates` for a free body outside axisymmetry.
    pub fn new<const D: usize>(
        field: u32,
        members: Vec<usize>,
        shapes: Vec<Geometry>,
        p: &Particles<D>,
        rotates: bool,
    ) -> Self {
        let mass: f64 = members.iter().map(|&q| p.mass[q]).sum();
        let centre0 = members
            .iter()
            .fold(Vector3::zeros(), |c, &q| c + to3(&p.x0[q]) * p.mass[q])
            / mass;
        let (mut lower, mut upper) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for (lo, hi) in shapes.iter().map(Geometry::bounds) {
            for d in 0..D {
                (lower[d], upper[d]) = (lower[d].min(lo[d]), upper[d].max(hi[d]));
            }
        }
        Surface {
            field,
            members,
            shapes,
            lower,
            upper,
            mass,
            centre0,
            rotates,
        }
    }

    /// One of the field's particles.
    pub fn particle(&self) -> usize {
        self.members[0]
    }

    /// The field's placement now, from its particles.
    pub fn placement<const D: usize>(&self, p: &Particles<D>) -> Placement {
        let centre = (self.members.iter())
            .fold(Vector3::zeros(), |c, &q| c + to3(&p.x[q]) * p.mass[q])
            / self.mass;
        let mut rotation = Mat3::identity();
        if self.rotates {
            // A = Σ m (x − c)(X − c⁰)ᵀ = Q S, S symmetric.
            let a = self.members.iter().fold(Mat3::zeros(), |a, &q| {
                let r = to3(&p.x[q]) - centre;
                let r0 = to3(&p.x0[q]) - self.centre0;
                a + r * r0.transpose() * p.mass[q]
            });
            rotation = polar_rotation::<D>(&a);
        }
        Placement {
            centre,
            centre0: self.centre0,
            rotation,
        }
    }

    /// Where to put a particle at x that is inside the field's bodies: the
    /// nearest surface point and its outward normal (`None` outside).
    pub fn push_out<const D: usize>(
        &self,
        at: &Placement,
        x: &Vector<D>,
        on_boundary: &dyn Fn(usize, f64) -> bool,
    ) -> Option<(Vector<D>, Vector<D>)> {
        let xr = at.body_point(x);
        if (0..D).any(|d| xr[d] <= self.lower[d] || xr[d] >= self.upper[d]) {
            return None;
        }
        let xs = &xr.as_slice()[..D];
        let (y, n) = (self.shapes.iter())
            .find(|s| s.contains(xs))?
            .nearest_surface(xs, on_boundary)?;
        Some((at.point_to_world(&y), at.direction_to_world(&n)))
    }
}

/// A deformable particle that reaches into a rigid body: its nearest surface
/// point, the outward normal there and its derivative ∂n/∂x, in the current
/// frame, and how deep it reaches.
#[derive(Clone, Copy, Debug)]
pub struct Inside<const D: usize> {
    pub point: Vector<D>,
    pub normal: Vector<D>,
    pub normal_derivative: Tensor<D>,
    /// The particle's reach minus its signed distance to the surface (> 0).
    pub depth: f64,
    /// ∂depth/∂x.
    pub depth_gradient: Vector<D>,
}

impl Placement {
    /// A point x in the body's `[[body]]` geometry: X = c⁰ + Qᵀ(x − c).
    fn body_point<const D: usize>(&self, x: &Vector<D>) -> Vector3<f64> {
        self.centre0 + self.rotation.transpose() * (to3(x) - self.centre)
    }

    /// A point of the body's geometry where it is now: x = c + Q (X − c⁰).
    fn point_to_world<const D: usize>(&self, y: &[f64]) -> Vector<D> {
        let y = Vector3::from_fn(|i, _| if i < D { y[i] } else { 0.0 });
        from3(&(self.centre + self.rotation * (y - self.centre0)))
    }

    /// A direction of the body's geometry where it is now: Q n.
    fn direction_to_world<const D: usize>(&self, n: &[f64]) -> Vector<D> {
        let n = Vector3::from_fn(|i, _| if i < D { n[i] } else { 0.0 });
        from3(&(self.rotation * n))
    }

    /// The placement moved by `by` (a prescribed motion over a step).
    pub fn shifted(&self, by: &Vector3<f64>) -> Placement {
        Placement {
            centre: self.centre + by,
            ..*self
        }
    }
}

impl Surface {
    /// A particle at x whose domain an ellipse (ellipsoid) of semi-axes ℓ
    /// (`half_lengths`, along the coordinate axes) stands for, and that comes as
    /// close to the field's bodies as its reach r = |L n| along the outward
    /// normal n (L = diag ℓ), or is inside them: the nearest surface point, n
    /// with its derivative N (`Bend`), the depth g = r − d ≥ 0 (d the signed
    /// distance) and ∂g/∂x = −n + N L² n / r; `None` when it does not reach. A
    /// particle that just touches (g = 0) is in contact: no force, but the
    /// stiffness that holds a body resting on the surface. The round reach keeps
    /// the normal continuous about a body's corners (the contact region is the
    /// body's offset, rounded there), and a particle beside a footing's corner
    /// is not caught by it.
    pub fn reached<const D: usize>(
        &self,
        at: &Placement,
        x: &Vector<D>,
        half_lengths: &Vector<D>,
        on_boundary: &dyn Fn(usize, f64) -> bool,
    ) -> Option<Inside<D>> {
        let reach = half_lengths.max() * (1.0 + TOUCH_TOLERANCE);
        let xr = at.body_point(x);
        let outside = |d: usize| xr[d] < self.lower[d] - reach || xr[d] > self.upper[d] + reach;
        if (0..D).any(outside) {
            return None;
        }
        let xs = &xr.as_slice()[..D];
        let (distance, s) = (self.shapes.iter())
            .filter_map(|g| g.signed_surface_point(xs, on_boundary))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        if distance > reach {
            return None;
        }
        let q = &at.rotation;
        let n = Vector3::from_fn(|i, _| if i < D { s.normal[i] } else { 0.0 });
        let dn = match s.bend {
            Bend::Flat => Mat3::zeros(),
            Bend::About { distance, axis } => {
                let mut a = Mat3::identity() - n * n.transpose();
                if let Some(k) = axis {
                    a[(k, k)] -= 1.0;
                }
                a / distance
            }
        };
        let normal: Vector<D> = at.direction_to_world(&s.normal);
        let normal_derivative: Tensor<D> = restrict(&(q * dn * q.transpose()));
        let l2n = half_lengths
            .component_mul(half_lengths)
            .component_mul(&normal);
        let reach_n = l2n.dot(&normal).sqrt();
        // Surfaces that coincide up to round-off touch (`TOUCH_TOLERANCE`).
        if distance > reach_n * (1.0 + TOUCH_TOLERANCE) {
            return None;
        }
        Some(Inside {
            point: at.point_to_world(&s.point),
            normal,
            normal_derivative,
            depth: (reach_n - distance).max(0.0),
            depth_gradient: normal_derivative * l2n / reach_n - normal,
        })
    }
}

/// The rigid fields k of `plan` with `wanted(k)`, with their particles (by
/// `field`, the field of each particle) and their bodies' geometries; a free
/// body outside axisymmetry rotates.
pub fn rigid_surfaces<const D: usize>(
    plan: &ContactPlan,
    m: &Model<D>,
    field: &[u32],
    wanted: &dyn Fn(usize) -> bool,
) -> Vec<Surface> {
    (0..plan.fields)
        .filter(|&k| plan.rigid[k] && wanted(k))
        .map(|k| {
            let members = (0..field.len())
                .filter(|&q| field[q] as usize == k)
                .collect();
            let shapes = (plan.field_of_body.iter().enumerate())
                .filter(|&(_, &f)| f as usize == k)
                .map(|(b, _)| m.bodies[b].geometry.clone())
                .collect();
            let rotates = plan.free[k] && !m.axisymmetric;
            Surface::new(k as u32, members, shapes, &m.particles, rotates)
        })
        .collect()
}

/// Whether x_d = c is a plane of the grid's boundary (faces there, on the axis
/// or a symmetry plane, are not surface).
pub fn on_grid_boundary<const D: usize>(grid: &Grid<D>) -> impl Fn(usize, f64) -> bool + '_ {
    let tolerance = 1e-9 * grid.h_min();
    move |d: usize, c: f64| {
        (c - grid.min[d]).abs() <= tolerance || (c - grid.max[d]).abs() <= tolerance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::Vector;
    use nalgebra::{Rotation3, Vector2};

    fn particles(x0: &[[f64; 2]], x: &[[f64; 2]]) -> Particles<2> {
        let mut p = Particles::<2>::default();
        for (a, b) in x0.iter().zip(x) {
            p.x0.push(Vector2::new(a[0], a[1]));
            p.x.push(Vector2::new(b[0], b[1]));
            p.mass.push(1.0);
        }
        p
    }

    #[test]
    fn a_turned_and_moved_square_pushes_a_point_out_through_its_nearest_face() {
        // The square [0, 2]² turned by 30° about its centre and moved by (5, 1).
        let theta: f64 = 30f64.to_radians();
        let q = Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
        let corners = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let moved: Vec<[f64; 2]> = (corners.iter())
            .map(|c| {
                let r = q * Vector3::new(c[0] - 1.0, c[1] - 1.0, 0.0);
                [6.0 + r[0], 2.0 + r[1]]
            })
            .collect();
        let p = particles(&corners, &moved);
        let square = Geometry::Box {
            min: vec![0.0, 0.0],
            max: vec![2.0, 2.0],
        };
        let s = Surface::new(0, vec![0, 1, 2, 3], vec![square], &p, true);
        let at = s.placement(&p);
        assert!((at.rotation - q.matrix()).norm() < 1e-14);
        // Reference point (1.9, 1.2): nearest face x = 2, normal (1, 0) turned.
        let place = |x: [f64; 2]| {
            let r = q * Vector3::new(x[0] - 1.0, x[1] - 1.0, 0.0);
            Vector::<2>::new(6.0 + r[0], 2.0 + r[1])
        };
        let none = |_: usize, _: f64| false;
        let (y, n) = s.push_out(&at, &place([1.9, 1.2]), &none).unwrap();
        assert!((y - place([2.0, 1.2])).norm() < 1e-13);
        assert!((n - Vector::<2>::new(theta.cos(), theta.sin())).norm() < 1e-14);
        assert!(s.push_out(&at, &place([2.1, 1.2]), &none).is_none());
    }

    #[test]
    fn a_particle_laid_on_a_face_touches_it_despite_round_off() {
        // A base [-0.5, 3] × [0, 0.25] at rest; a particle of spacing 0.025
        // laid on it sits at 0.25 + 0.0125, which rounds to 0.012500000000000011
        // above the face against a reach of 0.0125.
        let p = particles(&[[1.25, 0.125]], &[[1.25, 0.125]]);
        let base = Geometry::Box {
            min: vec![-0.5, 0.0],
            max: vec![3.0, 0.25],
        };
        let s = Surface::new(0, vec![0], vec![base], &p, false);
        let at = s.placement(&p);
        let none = |_: usize, _: f64| false;
        let ell = Vector::<2>::new(0.0125, 0.0125);
        let x = Vector::<2>::new(0.5125, 0.25 + 0.0125);
        assert!(x[1] - 0.25 > ell[1], "the round-off this test is about");
        let touch = s.reached(&at, &x, &ell, &none).expect("touches");
        assert_eq!(touch.depth, 0.0);
        assert_eq!(touch.normal, Vector::<2>::new(0.0, 1.0));
        // A particle a hair farther off (1e-6 of its reach) does not.
        let off = Vector::<2>::new(0.5125, 0.25 + 0.0125 * (1.0 + 1e-6));
        assert!(s.reached(&at, &off, &ell, &none).is_none());
    }

    #[test]
    fn the_placement_of_a_turned_box_in_3d_is_its_rotation() {
        use nalgebra::Vector3 as V3;
        let q = Rotation3::from_axis_angle(&V3::y_axis(), 0.4)
            * Rotation3::from_axis_angle(&V3::x_axis(), -0.7);
        let mut p = Particles::<3>::default();
        for c in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 3.0],
        ] {
            let x0 = V3::new(c[0], c[1], c[2]);
            p.x0.push(x0);
            p.x.push(q * x0 + V3::new(1.0, 2.0, 3.0));
            p.mass.push(1.0);
        }
        let bx = Geometry::Box {
            min: vec![0.0, 0.0, 0.0],
            max: vec![1.0, 2.0, 3.0],
        };
        let s = Surface::new(0, vec![0, 1, 2, 3], vec![bx], &p, true);
        let at = s.placement(&p);
        assert!((at.rotation - q.matrix()).norm() < 1e-13);
        // (0.5, 1.0, 2.9) is nearest the face z = 3.
        let x = q * V3::new(0.5, 1.0, 2.9) + V3::new(1.0, 2.0, 3.0);
        let none = |_: usize, _: f64| false;
        let (y, n) = s.push_out(&at, &x, &none).unwrap();
        let expected = q * V3::new(0.5, 1.0, 3.0) + V3::new(1.0, 2.0, 3.0);
        assert!((y - expected).norm() < 1e-13);
        assert!((n - q * V3::z()).norm() < 1e-14);
    }
}
