//! The conditions of a model as built from the scene: velocity conditions on grid
//! faces (fixed, roller, prescribed velocity, optionally on a region: a rigid
//! footing; a velocity, acceleration or displacement that follows a time
//! history: `FaceMotion`), rough rigid faces with Coulomb friction, and absorbing faces with the
//! wave properties of the materials next to them. The laws that act with them are
//! in `physics::boundary::conditions` and `physics::boundary::absorbing`.
//!
//! A velocity condition acts on the layer of nodes on its face (for clamped
//! B-splines, the control points that interpolate the face), component by
//! component, or only on the nodes of that layer inside a box (`region`).

use crate::dim::Vector;
use crate::material::{shear_modulus, Material};
use crate::model::curve::TimeCurve;
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::scene::{BoundaryConfig, Condition, Face};
use std::sync::Arc;

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

/// What a face's time history prescribes, and so the order of its integral
/// that gives the face's displacement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionKind {
    Displacement,
    Velocity,
    Acceleration,
}

/// A velocity condition that follows a time history f(t) (`model::curve`):
/// its displacement is u(t) = a F_n(t), with a the vector of the scene
/// (`displacement`, `velocity`, `acceleration`) and F_n the integral of f
/// from t = 0 of order n = 0, 1, 2 (from rest at the reference position).
#[derive(Clone, Debug)]
pub struct FaceMotion<const D: usize> {
    /// Index of the condition in `Model::faces`.
    pub face: usize,
    pub kind: MotionKind,
    pub amplitude: Vector<D>,
    pub curve: Arc<TimeCurve>,
}

impl<const D: usize> FaceMotion<D> {
    /// The face's displacement at t, a F_n(t).
    pub fn displacement(&self, t: f64) -> Vector<D> {
        let order = match self.kind {
            MotionKind::Displacement => 0,
            MotionKind::Velocity => 1,
            MotionKind::Acceleration => 2,
        };
        self.amplitude * self.curve.integral(order, t)
    }

    /// The velocity a step from t to t + dt prescribes: the mean over the step,
    /// (u(t + dt) − u(t)) / dt, so that the face is at u(t) after every step
    /// whatever the steps (explicit and implicit alike).
    pub fn step_velocity(&self, t: f64, dt: f64) -> Vector<D> {
        debug_assert!(dt > 0.0, "a step has a positive length");
        (self.displacement(t + dt) - self.displacement(t)) / dt
    }
}

/// A rigid face with Coulomb friction (a rough base): a node on the face may
/// separate from it, but not move into it, and slides along it only against a
/// friction impulse of at most μ times the normal impulse (rigid-wall contact in
/// the manner of Bardenhagen et al. 2001, with the wall as the rigid body). The
/// wall may move along itself (a shaken base): the law acts on the velocity
/// relative to the wall's.
#[derive(Clone, Copy, Debug)]
pub struct FrictionFace<const D: usize> {
    pub face: Face,
    /// Coulomb friction coefficient μ ≥ 0 (0: a roller that lets go).
    pub coefficient: f64,
    /// The wall's velocity over the current step, tangential (zero at rest;
    /// `Model::walls_during` sets it from the wall's motion).
    pub velocity: Vector<D>,
}

impl<const D: usize> FrictionFace<D> {
    /// Unit outward normal of the face (out of the grid, into the wall).
    pub fn normal(&self) -> Vector<D> {
        let mut n = Vector::<D>::zeros();
        n[self.face.axis] = if self.face.upper { 1.0 } else { -1.0 };
        n
    }
}

/// The footing of a scene (at most one).
#[derive(Clone, Debug)]
pub struct Footing<const D: usize> {
    pub condition: FaceCondition<D>,
    /// Width the load is spread over (the modelled width: B/2 in a half model).
    pub width: f64,
    /// Cohesion of the material under the footing centre, if it has one.
    pub cohesion: Option<f64>,
}

impl<const D: usize> Footing<D> {
    /// The area the load is spread over: the width per unit thickness in 2D, a
    /// square of side `width` in 3D (a quarter model of a square footing of side
    /// B has width B/2).
    pub fn area(&self) -> f64 {
        self.width.powi(D as i32 - 1)
    }

    /// +1 on an upper face (the footing pushes towards −axis), −1 on a lower one.
    fn outward(&self) -> f64 {
        if self.condition.face.upper {
            1.0
        } else {
            -1.0
        }
    }

    /// Rate at which the footing moves into the body.
    pub fn settlement_rate(&self) -> f64 {
        -self.outward() * self.condition.constraint.value[self.condition.face.axis]
    }

    /// Load the footing exerts on the body, from the reactions (grid node,
    /// force of the prescribed components on the body) of a converged step.
    pub fn load(&self, grid: &Grid<D>, reaction: &[(u32, Vector<D>)]) -> f64 {
        let axis = self.condition.face.axis;
        let total: f64 = reaction
            .iter()
            .filter(|(g, _)| self.condition.acts_on(grid, grid.node_ijk(*g as usize)))
            .map(|(_, f)| f[axis])
            .sum();
        -self.outward() * total
    }
}

/// How the springs of one absorbing face are given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spring {
    /// Dashpots only.
    None,
    /// k = α G / R with R the distance from the wave source to the face.
    Distance(f64),
    /// Stiffness per unit area, normal and tangential.
    Stiffness { normal: f64, tangential: f64 },
}

#[derive(Clone, Copy, Debug)]
pub struct AbsorbingFace {
    pub face: Face,
    pub spring: Spring,
    /// Index of its `[[boundary]]` table (for errors).
    pub boundary: usize,
}

/// Wave properties of one material at rest.
#[derive(Clone, Copy, Debug)]
pub struct Waves {
    /// ρ0 c_d = √(ρ0 (λ + 2G)) (2-59, 2-61).
    pub normal_impedance: f64,
    /// ρ0 c_s = √(ρ0 G) (2-60, 2-62).
    pub shear_impedance: f64,
    /// Shear modulus G (for the spring stiffness α G / R).
    pub shear_modulus: f64,
}

impl Waves {
    pub fn of(m: &dyn Material) -> Waves {
        let g = shear_modulus(m);
        Waves {
            normal_impedance: (m.density() * m.p_wave_modulus()).sqrt(),
            shear_impedance: (m.density() * g).sqrt(),
            shear_modulus: g,
        }
    }
}

/// The incoming wave of a compliant base (an absorbing face with
/// `incoming_velocity`): the particle velocity v_in(t) of the upgoing wave at
/// the face, the scene's vector times its time history's factor (1 without
/// one). Joyner & Chen (1975): the medium beyond the face acts on it with
/// t = C (2 v_in − v), C the dashpots of the face (`physics::boundary::absorbing`).
#[derive(Clone, Debug)]
pub struct IncomingWave<const D: usize> {
    /// Index of the face in `Absorbing::faces`.
    pub face: usize,
    pub velocity: Vector<D>,
    pub curve: Option<Arc<TimeCurve>>,
}

impl<const D: usize> IncomingWave<D> {
    /// v_in(t).
    pub fn at(&self, t: f64) -> Vector<D> {
        self.velocity * self.curve.as_ref().map_or(1.0, |c| c.value(t))
    }
}

/// The absorbing faces of a scene and the wave properties of its materials.
#[derive(Clone, Debug, Default)]
pub struct Absorbing<const D: usize> {
    pub faces: Vec<AbsorbingFace>,
    pub waves: Vec<Waves>,
    /// The incoming waves of the compliant bases among the faces (most scenes: none).
    pub incoming: Vec<IncomingWave<D>>,
}

impl<const D: usize> Absorbing<D> {
    /// From the `[[boundary]]` tables with `condition = "absorbing"`.
    pub fn new(boundaries: &[BoundaryConfig], materials: &[Box<dyn Material>]) -> Self {
        let faces: Vec<AbsorbingFace> = boundaries
            .iter()
            .enumerate()
            .filter(|(_, b)| b.condition == Condition::Absorbing)
            .map(|(i, b)| AbsorbingFace {
                face: Face::parse(&b.face, D).expect("validated face"),
                spring: match (b.spring_distance, &b.spring_stiffness) {
                    (Some(r), _) => Spring::Distance(r),
                    (None, Some(k)) => Spring::Stiffness {
                        normal: k[0],
                        tangential: k[1],
                    },
                    (None, None) => Spring::None,
                },
                boundary: i,
            })
            .collect();
        let waves = if faces.is_empty() {
            Vec::new()
        } else {
            materials.iter().map(|m| Waves::of(m.as_ref())).collect()
        };
        let incoming = (faces.iter().enumerate())
            .filter_map(|(face, f)| {
                let b = &boundaries[f.boundary];
                let v = b.incoming_velocity.as_ref()?;
                Some(IncomingWave {
                    face,
                    velocity: Vector::<D>::from_fn(|d, _| v[d]),
                    curve: (b.time_history.as_ref()).map(|h| Arc::new(TimeCurve::new(&h.points()))),
                })
            })
            .collect();
        Absorbing {
            faces,
            waves,
            incoming,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Every absorbing face needs material in its outermost cell layer: its
    /// impedance comes from there. Returns the offending `[[boundary]]` index.
    pub fn check_adjacent(&self, grid: &Grid<D>, p: &Particles<D>) -> Result<(), (usize, String)> {
        for f in &self.faces {
            if !p.x.iter().any(|x| grid.in_outer_layer(f.face, x)) {
                return Err((
                    f.boundary,
                    format!(
                        "no material next to the absorbing face {}: its dashpots take ρ c_d and ρ c_s from the particles in the outermost layer of cells (within {} of the face), and there are none",
                        f.face.name(),
                        grid.h[f.face.axis]
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::hencky::Hencky;
    use crate::material::linear_elastic::LinearElastic;
    use crate::material::mooney_rivlin::MooneyRivlin;
    use crate::material::neo_hookean::NeoHookean;

    /// The shear modulus read off the stress derivative at rest is G for every
    /// model, and the P-wave modulus of the trait is consistent with it.
    #[test]
    fn shear_modulus_of_every_model() {
        let (e, nu) = (50.0e6, 0.25);
        let g = e / (2.0 * (1.0 + nu));
        let models: Vec<(Box<dyn Material>, f64)> = vec![
            (Box::new(LinearElastic::new(2000.0, e, nu)), g),
            (Box::new(Hencky::new(2000.0, e, nu)), g),
            (Box::new(NeoHookean::new(2000.0, e, nu)), g),
            (
                Box::new(MooneyRivlin::from_thesis(2000.0, 3.0e6, 1.0e6, nu)),
                8.0e6,
            ),
        ];
        for (m, expected) in models {
            let got = shear_modulus(m.as_ref());
            assert!(
                (got / expected - 1.0).abs() < 1e-9,
                "{}: G = {got}, expected {expected}",
                m.model()
            );
            let w = Waves::of(m.as_ref());
            assert!(
                (w.shear_impedance - (2000.0 * expected).sqrt()).abs() < 1e-6 * w.shear_impedance
            );
            assert!(w.normal_impedance > w.shear_impedance);
        }
    }
}
