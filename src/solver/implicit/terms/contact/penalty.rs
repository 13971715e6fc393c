//! The penalty law of the implicit contact (`super`): a deformable particle
//! against a rigid body (`super::rigid`), and with the same law one deformable
//! body's surface against another's at a meeting of their split nodes
//! (`super::bodies`).
//!
//! The node-based contact of `solver::explicit::contact` corrects grid velocities, which
//! has no residual to put into a Newton iteration. Here the particle is the
//! slave point and the rigid body's exact `[[body]]` geometry the master
//! surface. A particle at x that reaches r along the normal (its domain's
//! half-width, `Surface::reached`) and is at the signed distance d ≤ r from the body
//! (negative inside; nearest surface point s, outward normal n) is g = r − d
//! deep in it and feels
//!
//!   f = ε_n g n + f_t                                  (normal penalty)
//!
//! with an elastic-plastic (Coulomb) regularisation of the tangential force
//! (Wriggers 2006, Computational Contact Mechanics, §5.2; Laursen 2002, §5.3):
//! the trial force h = P (f_t⁰ − ε_t Δ), P = I − n nᵀ, from the tangential force
//! at the step start f_t⁰ and the particle's motion relative to the body over
//! the step Δ = (x − x⁰) − u_body, and
//!
//!   f_t = h                 if |h| ≤ μ ε_n g   (stick)
//!   f_t = μ ε_n g h/|h|     otherwise          (slip).
//!
//! The derivative ∂f/∂x (f_t⁰ and the body's motion are fixed within a step),
//! with N = ∂n/∂x (zero on a plane face; `Bend`) and ∂g/∂x (−nᵀ plus the turn
//! of the reach with n, `Surface::reached`):
//!
//!   ∂(ε_n g n)/∂x = ε_n (g N + n ∂g/∂x)
//!   ∂h/∂x = −ε_t P − N (nᵀ b) − n (bᵀ N),  b = f_t⁰ − ε_t Δ
//!   slip: ∂f_t/∂x = μ ε_n ĥ ∂g/∂x + (μ ε_n g/|h|) (I − ĥ ĥᵀ) ∂h/∂x,  ĥ = h/|h|.
//!
//! The stick derivative is symmetric on plane faces; a curved face or slip makes
//! it unsymmetric. A slipping particle dissipates the tangential force times the
//! plastic part of its trial displacement, (|h| − μ ε_n g)/ε_t (the elastic part
//! is stored in the tangential penalty and given back), the force taken as the
//! mean of the step's start and end (trapezoidal: second order in the step).

use crate::dim::{Tensor, Vector};
use crate::physics::rigid::surface::Inside;

/// The law at one particle: penalties and friction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Penalty {
    /// Normal penalty ε_n (force per length).
    pub normal: f64,
    /// Tangential penalty ε_t (force per length).
    pub tangential: f64,
    /// Coulomb coefficient μ.
    pub friction: f64,
}

/// The contact force on a particle inside a rigid body and its derivative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleContact<const D: usize> {
    /// Force on the particle.
    pub force: Vector<D>,
    /// ∂force/∂x.
    pub derivative: Tensor<D>,
    /// Penetration depth g.
    pub depth: f64,
    /// Tangential force (part of `force`).
    pub tangential: Vector<D>,
    pub slips: bool,
    /// The work friction dissipated over the step: the slip (|h| − μ ε_n g)/ε_t
    /// times the mean of |f_t⁰| and |f_t| (trapezoidal; zero when it sticks).
    pub dissipation: f64,
}

impl<const D: usize> ParticleContact<D> {
    /// Whether the derivative is symmetric, to round-off (plane faces, no
    /// slip).
    pub fn is_symmetric(&self) -> bool {
        let d = &self.derivative;
        (d - d.transpose()).amax() <= 1e-10 * d.amax()
    }
}

/// The penalty force on a particle that reaches into a body (`inside`: nearest
/// surface point, normal and its derivative, depth), that moved by `relative` with
/// respect to the body over the step and carried the tangential force `f_t0` at
/// the step start.
pub fn penalty_force<const D: usize>(
    law: &Penalty,
    inside: &Inside<D>,
    relative: &Vector<D>,
    f_t0: &Vector<D>,
) -> ParticleContact<D> {
    let (n, dn) = (&inside.normal, &inside.normal_derivative);
    let id = Tensor::<D>::identity();
    let (g, dg) = (inside.depth, &inside.depth_gradient);
    let f_n = law.normal * g;
    let normal_part = (dn * g + n * dg.transpose()) * law.normal;
    if law.friction == 0.0 {
        return ParticleContact {
            force: n * f_n,
            derivative: normal_part,
            depth: g,
            tangential: Vector::<D>::zeros(),
            slips: false,
            dissipation: 0.0,
        };
    }
    let p = id - n * n.transpose();
    let b = f_t0 - relative * law.tangential;
    let h = p * b;
    // ∂h/∂x = −ε_t P − N (nᵀ b) − n (bᵀ N).
    let dh = -p * law.tangential - dn * n.dot(&b) - n * (b.transpose() * dn);
    let cap = law.friction * f_n;
    let h_norm = h.norm();
    let (tangential, d_t, slips) = if h_norm <= cap {
        (h, dh, false)
    } else {
        // The plastic part of the trial: the slip of the step.
        let t = h / h_norm;
        let d_t = (t * dg.transpose()) * (law.friction * law.normal)
            + (id - t * t.transpose()) * dh * (cap / h_norm);
        (t * cap, d_t, true)
    };
    ParticleContact {
        force: n * f_n + tangential,
        derivative: normal_part + d_t,
        depth: g,
        tangential,
        slips,
        dissipation: match slips {
            true => 0.5 * (f_t0.norm() + cap) * (h_norm - cap) / law.tangential,
            false => 0.0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::geometry::Geometry;
    use crate::model::particles::Particles;
    use crate::physics::rigid::surface::Surface;
    use nalgebra::{Vector2, Vector3};

    /// A rigid body of one particle at its centre with the given shape.
    fn body(shape: Geometry, centre: [f64; 2]) -> (Surface, Particles<2>) {
        let mut p = Particles::<2>::default();
        p.x0.push(Vector2::new(centre[0], centre[1]));
        p.x.push(Vector2::new(centre[0], centre[1]));
        p.mass.push(1.0);
        (Surface::new(0, vec![0], vec![shape], &p, false), p)
    }

    /// ∂f/∂x against central differences of f (the contact state at each
    /// perturbed x found anew: nearest point, normal, stick or slip).
    fn check_derivative(shape: Geometry, centre: [f64; 2], x: Vector2<f64>, law: Penalty) -> bool {
        let (s, p) = body(shape, centre);
        let at = s.placement(&p).shifted(&Vector3::new(0.01, -0.02, 0.0));
        let none = |_: usize, _: f64| false;
        let x0 = Vector2::new(x[0] - 0.003, x[1] + 0.001);
        let f_t0 = Vector2::new(30.0, 5.0);
        let u_body = Vector2::new(0.01, -0.02);
        let force = |y: &Vector2<f64>| {
            let ell = Vector2::new(0.008, 0.005);
            let inside = s.reached(&at, y, &ell, &none).expect("inside");
            penalty_force(&law, &inside, &(y - x0 - u_body), &f_t0)
        };
        let c = force(&x);
        let h = 1e-7;
        let mut fd = Tensor::<2>::zeros();
        for k in 0..2 {
            let mut e = Vector2::zeros();
            e[k] = h;
            let col = (force(&(x + e)).force - force(&(x - e)).force) / (2.0 * h);
            fd.set_column(k, &col);
        }
        let err = (fd - c.derivative).norm() / c.derivative.norm();
        println!(
            "slips {} depth {:.3e}: |∂f/∂x − FD| / |∂f/∂x| = {err:.2e}",
            c.slips, c.depth
        );
        err < 1e-6
    }

    #[test]
    fn derivative_matches_finite_differences_on_faces_and_balls_in_stick_and_slip() {
        let square = || Geometry::Box {
            min: vec![0.0, 0.0],
            max: vec![2.0, 2.0],
        };
        let disk = || Geometry::Ball {
            centre: vec![1.0, 1.0],
            radius: 1.0,
        };
        let stiff = |friction| Penalty {
            normal: 1e6,
            tangential: 1e6,
            friction,
        };
        // Inside under a face, outside within reach of a corner (the normal
        // turns about it), inside a disk, outside a disk within reach.
        let x_face = Vector2::new(1.2, 1.975);
        let x_corner = Vector2::new(2.014, 1.983);
        let x_ball = Vector2::new(1.5, 1.8);
        let x_near_ball = Vector2::new(1.01, 1.983);
        for (shape, x) in [
            (square(), x_face),
            (square(), x_corner),
            (disk(), x_ball),
            (disk(), x_near_ball),
        ] {
            // Frictionless, stick (μ large), slip (μ small).
            for mu in [0.0, 100.0, 0.1] {
                assert!(check_derivative(shape.clone(), [1.0, 1.0], x, stiff(mu)));
            }
        }
    }

    #[test]
    fn force_pushes_out_along_the_normal_and_friction_is_capped() {
        let (s, p) = body(
            Geometry::Box {
                min: vec![0.0, 0.0],
                max: vec![2.0, 2.0],
            },
            [1.0, 1.0],
        );
        let at = s.placement(&p);
        let none = |_: usize, _: f64| false;
        let x = Vector2::new(1.0, 1.99);
        let point = Vector2::zeros();
        let inside = s.reached(&at, &x, &point, &none).unwrap();
        let law = Penalty {
            normal: 1e4,
            tangential: 1e4,
            friction: 0.5,
        };
        // Depth 0.01: normal force 100 up; a slide of 1 along x would take 1e4,
        // capped at μ f_n = 50 against the motion.
        let c = penalty_force(&law, &inside, &Vector2::new(1.0, 0.0), &Vector2::zeros());
        assert!((c.depth - 0.01).abs() < 1e-12);
        assert!(
            (c.force - Vector2::new(-50.0, 100.0)).norm() < 1e-9,
            "{}",
            c.force
        );
        assert!(c.slips);
        // A small slide sticks: −ε_t Δ.
        let c = penalty_force(&law, &inside, &Vector2::new(1e-3, 0.0), &Vector2::zeros());
        assert!(
            (c.force - Vector2::new(-10.0, 100.0)).norm() < 1e-9,
            "{}",
            c.force
        );
        assert!(!c.slips);
        // Outside: no contact, unless the particle reaches the surface.
        assert!(s
            .reached(&at, &Vector2::new(1.0, 2.01), &point, &none)
            .is_none());
        let square = Vector2::new(0.015, 0.015);
        let reach = s
            .reached(&at, &Vector2::new(1.0, 2.01), &square, &none)
            .unwrap();
        assert!((reach.depth - 0.005).abs() < 1e-12 && reach.normal == Vector2::new(0.0, 1.0));
    }
}
