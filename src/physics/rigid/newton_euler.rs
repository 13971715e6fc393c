//! Free rigid bodies (`model::body::BodyKind::Rigid`, `motion = "free"`) in the explicit
//! solver: Newton–Euler for a body of point masses, its particles.
//!
//! The state lives in the particles: at the start of every step the body's mass
//! M = Σ m_p, centre c = Σ m_p x_p / M, velocity V = Σ m_p v_p / M, inertia
//! I = Σ m_p (|r_p|² 1 − r_p r_pᵀ) and spin Ω = I⁻¹ Σ m_p r_p × (v_p − V)
//! (r_p = x_p − c) are computed from them, so a restart needs nothing more. In
//! the step the body is a field of infinite mass whose nodes move with
//! V + Ω × (x_I − c) (`solver::explicit::contact`), and the contact corrections that
//! reach the particles give it the impulse J = Σ Δp_I and the angular impulse
//! H = Σ (x_I − c) × Δp_I (the opposite of what its partners received, so
//! linear and angular momentum are conserved). After G2P:
//!
//!   V' = V + (J + Δt Σ f_p)/M,   Ω' = I⁻¹ (I Ω + H + Δt Σ r_p × f_p),
//!
//! with f_p gravity and the loads on its particles; the particles then take
//! x_p' = c + V'Δt + Q r_p and v_p' = V' + Ω' × Q r_p, Q the rotation by Ω'Δt
//! (Rodrigues; symplectic Euler), so the body keeps its shape exactly.
//! 2D bodies are embedded in 3D (z = 0, Ω along z); in axisymmetric mode a body
//! of revolution on the axis moves along it only (Ω = 0, no radial velocity).
//! The particles' own rotational inertia is left out (m_p δ²/6 against M R²/2:
//! below 0.1 % for 10 particles across a radius).

use crate::dim::{Mat3, Vector};
use crate::model::particles::Particles;
use nalgebra::{Rotation3, Vector3};

/// One free body's state at the start of the step.
#[derive(Clone, Debug, Default)]
struct Body {
    mass: f64,
    centre: Vector3<f64>,
    velocity: Vector3<f64>,
    spin: Vector3<f64>,
    inertia: Mat3,
    /// Impulse and angular impulse (about `centre`) received in the step.
    impulse: Vector3<f64>,
    moment: Vector3<f64>,
}

/// The free rigid bodies of a scene, one per free velocity field.
#[derive(Clone, Debug)]
pub struct FreeBodies<const D: usize> {
    /// Body of each velocity field (`usize::MAX`: not a free body).
    body_of_field: Vec<usize>,
    /// The particles of the free bodies and their body.
    particles: Vec<(usize, usize)>,
    /// r_p = x_p − c at the start of the step, per entry of `particles`.
    offsets: Vec<Vector3<f64>>,
    bodies: Vec<Body>,
}

/// A D-vector embedded in 3D (zero beyond D).
pub fn to3<const D: usize>(v: &Vector<D>) -> Vector3<f64> {
    Vector3::from_fn(|i, _| if i < D { v[i] } else { 0.0 })
}

/// The first D components of a 3-vector.
pub fn from3<const D: usize>(v: &Vector3<f64>) -> Vector<D> {
    Vector::<D>::from_fn(|i, _| v[i])
}

impl<const D: usize> FreeBodies<D> {
    /// The free bodies of the fields marked `free`, `None` if there are none.
    pub fn new(free: &[bool], field: &[u32]) -> Option<Self> {
        let mut body_of_field = vec![usize::MAX; free.len()];
        let mut n = 0;
        for (k, _) in free.iter().enumerate().filter(|(_, &f)| f) {
            body_of_field[k] = n;
            n += 1;
        }
        if n == 0 {
            return None;
        }
        let particles: Vec<(usize, usize)> = (field.iter().enumerate())
            .filter(|&(_, &k)| free[k as usize])
            .map(|(q, &k)| (q, body_of_field[k as usize]))
            .collect();
        Some(FreeBodies {
            body_of_field,
            offsets: vec![Vector3::zeros(); particles.len()],
            particles,
            bodies: vec![Body::default(); n],
        })
    }

    /// The particles of the free bodies.
    pub fn particles(&self) -> impl Iterator<Item = usize> + '_ {
        self.particles.iter().map(|&(q, _)| q)
    }

    /// The bodies' state at the start of a step, from their particles.
    pub fn start(&mut self, p: &Particles<D>, axisymmetric: bool) {
        for b in &mut self.bodies {
            *b = Body::default();
        }
        for &(q, k) in &self.particles {
            let b = &mut self.bodies[k];
            b.mass += p.mass[q];
            b.centre += to3(&p.x[q]) * p.mass[q];
            b.velocity += to3(&p.v[q]) * p.mass[q];
        }
        for b in &mut self.bodies {
            b.centre /= b.mass;
            b.velocity /= b.mass;
        }
        let mut momentum = vec![Vector3::zeros(); self.bodies.len()];
        for (i, &(q, k)) in self.particles.iter().enumerate() {
            let b = &mut self.bodies[k];
            let r = to3(&p.x[q]) - b.centre;
            self.offsets[i] = r;
            // I = Σ m (|r|² 1 − r rᵀ); L = Σ m r × (v − V).
            b.inertia += (Mat3::identity() * r.norm_squared() - r * r.transpose()) * p.mass[q];
            momentum[k] += r.cross(&(to3(&p.v[q]) - b.velocity)) * p.mass[q];
        }
        for (b, l) in self.bodies.iter_mut().zip(&momentum) {
            b.spin = spin::<D>(&b.inertia, l, axisymmetric);
        }
    }

    /// The velocity of a free body's node at x (`None` if the field is not free).
    pub fn node_velocity(&self, field: usize, x: &Vector<D>) -> Option<Vector<D>> {
        let b = &self.bodies[*self
            .body_of_field
            .get(field)
            .filter(|&&k| k != usize::MAX)?];
        Some(from3(&(b.velocity + b.spin.cross(&(to3(x) - b.centre)))))
    }

    /// Field `field` received the momentum `dp` at the node at x.
    pub fn receive(&mut self, field: usize, x: &Vector<D>, dp: &Vector<D>) {
        if let Some(&k) = self.body_of_field.get(field).filter(|&&k| k != usize::MAX) {
            let b = &mut self.bodies[k];
            b.impulse += to3(dp);
            b.moment += (to3(x) - b.centre).cross(&to3(dp));
        }
    }

    /// Advance the bodies over the step just taken (Newton–Euler, above) and set
    /// their particles' positions and velocities; `force` is the applied force
    /// on each particle of `particles()`, in order.
    pub fn advance(
        &mut self,
        p: &mut Particles<D>,
        force: &[Vector<D>],
        axisymmetric: bool,
        dt: f64,
    ) {
        let n = self.bodies.len();
        let (mut impulse, mut moment) = (vec![Vector3::zeros(); n], vec![Vector3::zeros(); n]);
        for (i, &(_, k)) in self.particles.iter().enumerate() {
            let f = to3(&force[i]) * dt;
            impulse[k] += f;
            moment[k] += self.offsets[i].cross(&f);
        }
        let mut motion = Vec::with_capacity(n);
        for (k, b) in self.bodies.iter().enumerate() {
            let (velocity, spin) = b.kicked::<D>(&impulse[k], &moment[k], axisymmetric);
            let rotation = Rotation3::new(spin * dt);
            motion.push((b.centre + velocity * dt, velocity, spin, rotation));
        }
        for (i, &(q, k)) in self.particles.iter().enumerate() {
            let (centre, velocity, spin, rotation) = &motion[k];
            let r = rotation * self.offsets[i];
            p.x[q] = from3(&(centre + r));
            p.v[q] = from3(&(velocity + spin.cross(&r)));
        }
    }

    /// After `advance` and a `start` on the particles it moved, give the bodies
    /// the impulses `kicks` (field, point, Δp) and set their particles'
    /// velocities: V' = V + J/M, Ω' = I⁻¹(IΩ + H).
    pub fn kick(
        &mut self,
        p: &mut Particles<D>,
        kicks: &[(usize, Vector<D>, Vector<D>)],
        axisymmetric: bool,
    ) {
        for (field, x, dp) in kicks {
            self.receive(*field, x, dp);
        }
        let none = Vector3::zeros();
        for b in &mut self.bodies {
            (b.velocity, b.spin) = b.kicked::<D>(&none, &none, axisymmetric);
            (b.impulse, b.moment) = (none, none);
        }
        for (i, &(q, k)) in self.particles.iter().enumerate() {
            let b = &self.bodies[k];
            p.v[q] = from3(&(b.velocity + b.spin.cross(&self.offsets[i])));
        }
    }
}

impl Body {
    /// Velocity and spin after the received impulse and moment and `extra` ones:
    /// V + (J + J')/M and I⁻¹(IΩ + H + H') (along the axis only, no spin, in
    /// axisymmetric mode).
    fn kicked<const D: usize>(
        &self,
        extra_impulse: &Vector3<f64>,
        extra_moment: &Vector3<f64>,
        axisymmetric: bool,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let mut velocity = self.velocity + (self.impulse + extra_impulse) / self.mass;
        if axisymmetric {
            velocity[0] = 0.0;
        }
        let l = self.inertia * self.spin + self.moment + extra_moment;
        (velocity, spin::<D>(&self.inertia, &l, axisymmetric))
    }
}

/// Ω = I⁻¹ L: about z in 2D (L_z/I_zz), none in axisymmetric mode, the full
/// inverse in 3D (zero for a body without rotational inertia: one particle).
fn spin<const D: usize>(inertia: &Mat3, l: &Vector3<f64>, axisymmetric: bool) -> Vector3<f64> {
    if axisymmetric {
        Vector3::zeros()
    } else if D == 2 {
        let izz = inertia[(2, 2)];
        Vector3::new(0.0, 0.0, if izz > 0.0 { l[2] / izz } else { 0.0 })
    } else {
        inertia
            .try_inverse()
            .map_or(Vector3::zeros(), |inv| inv * l)
    }
}
