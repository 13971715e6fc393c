//! From a validated scene to the objects a solver works on: grid, particles,
//! materials, boundary conditions and loads.

pub mod conditions;
pub mod grid;
pub mod particles;

use crate::dim::Vector;
use crate::material::drucker_prager::DruckerPrager;
use crate::material::hencky::Hencky;
use crate::material::linear_elastic::LinearElastic;
use crate::material::mohr_coulomb::MohrCoulomb;
use crate::material::mohr_coulomb::{Softening, Strength};
use crate::material::mooney_rivlin::MooneyRivlin;
use crate::material::neo_hookean::NeoHookean;
use crate::material::ogden::Ogden;
use crate::material::{drucker_prager, Material};
use crate::model::conditions::Absorbing;
use crate::model::conditions::Footing;
use crate::model::conditions::{Constraint, FaceCondition, FrictionFace};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::scene::validate::{axis, body_bounds};
use crate::scene::Face;
use crate::scene::{
    expr, BodyConfig, Condition, LoadKind, MaterialConfig, MaterialModel, MohrCoulombFit, Scene,
    SceneError, Shape,
};

/// Everything a solver needs, in dimension D.
#[derive(Debug)]
pub struct Model<const D: usize> {
    pub grid: Grid<D>,
    pub particles: Particles<D>,
    pub materials: Vec<Box<dyn Material>>,
    pub faces: Vec<FaceCondition<D>>,
    /// Rigid rough faces (Coulomb friction; held fixed in implicit steps).
    pub friction: Vec<FrictionFace>,
    /// The velocity condition with a `footing_width`, if any.
    pub footing: Option<Footing<D>>,
    /// Non-reflecting faces (Lysmer–Kuhlemeyer dashpots, optional springs).
    pub absorbing: Absorbing<D>,
    pub gravity: Vector<D>,
    /// The distinct time histories of the loads (the force is stored on the
    /// particles grouped by history, see `load_scales`).
    pub load_ramps: Vec<LoadTime>,
    /// For each particle, the index into `load_ramps` of its load (u32::MAX: none).
    pub load_ramp_of: Vec<u32>,
}

impl<const D: usize> Model<D> {
    pub fn build(scene: &Scene) -> Result<Model<D>, SceneError> {
        let c = &scene.config;
        assert_eq!(c.dimension, D, "caller dispatches on the scene dimension");
        let err =
            |key: String, msg: String| SceneError::at_key(&scene.file, &scene.text, &key, msg);
        let vec = |v: &[f64]| Vector::<D>::from_fn(|d, _| v[d]);
        let cells = std::array::from_fn(|d| c.grid.cells[d]);
        let grid = Grid::new(
            vec(&c.grid.min),
            vec(&c.grid.max),
            cells,
            c.grid.shape_function.degree(),
        );
        let materials: Vec<Box<dyn Material>> = c.materials.iter().map(material).collect();
        let mut particles = Particles::default();
        for (i, b) in c.bodies.iter().enumerate() {
            let m = c
                .materials
                .iter()
                .position(|m| m.name == b.material)
                .expect("validated");
            let added = fill_body(&mut particles, &grid, b, i, m as u32, materials[m].as_ref())
                .map_err(|(k, msg)| err(k, msg))?;
            if added == 0 {
                return Err(err(format!("body.{i}.shape"), "the body holds no particle centre: refine the grid or raise particles_per_cell".into()));
            }
        }
        let faces: Vec<FaceCondition<D>> = c
            .boundaries
            .iter()
            .filter(|b| !matches!(b.condition, Condition::Absorbing | Condition::Friction))
            .map(|b| face_condition(b, D, &vec))
            .collect();
        let friction = c
            .boundaries
            .iter()
            .filter(|b| b.condition == Condition::Friction)
            .map(|b| FrictionFace {
                face: Face::parse(&b.face, D).unwrap(),
                coefficient: b.friction_coefficient.unwrap(),
            })
            .collect();
        // A region must hold at least one node of its face.
        let velocity_conditions =
            c.boundaries.iter().enumerate().filter(|(_, b)| {
                !matches!(b.condition, Condition::Absorbing | Condition::Friction)
            });
        for ((i, _), fc) in velocity_conditions.zip(&faces) {
            if !(0..grid.node_count()).any(|g| fc.acts_on(&grid, grid.node_ijk(g))) {
                return Err(err(
                    format!("boundary.{i}.region_min"),
                    "the region holds no grid node of the face".into(),
                ));
            }
        }
        let footing = footing(c, &faces, &grid, &particles);
        let absorbing = Absorbing::new(&c.boundaries, &materials);
        absorbing
            .check_adjacent(&grid, &particles)
            .map_err(|(i, msg)| err(format!("boundary.{i}.face"), msg))?;
        let gravity = c.gravity.as_deref().map_or(Vector::<D>::zeros(), vec);
        let mut load_ramp_of = vec![u32::MAX; particles.len()];
        let mut load_ramps = Vec::new();
        for (i, l) in c.loads.iter().enumerate() {
            let body = l.body.as_ref().map(|n| {
                c.bodies
                    .iter()
                    .position(|b| b.name.as_deref() == Some(n))
                    .unwrap() as u32
            });
            let (lo, hi) = (vec(&l.region_min), vec(&l.region_max));
            let selected: Vec<usize> = (0..particles.len())
                .filter(|&p| body.is_none_or(|b| particles.body[p] == b))
                .filter(|&p| {
                    (0..D).all(|d| particles.x0[p][d] >= lo[d] && particles.x0[p][d] <= hi[d])
                })
                .collect();
            if selected.is_empty() {
                return Err(err(
                    format!("load.{i}.region_min"),
                    "the load region selects no particle".into(),
                ));
            }
            let time = match l.pulse_duration {
                Some(t) => LoadTime::Pulse(t),
                None => LoadTime::Ramp(l.ramp_time),
            };
            let ramp = load_ramps
                .iter()
                .position(|&r| r == time)
                .unwrap_or_else(|| {
                    load_ramps.push(time);
                    load_ramps.len() - 1
                });
            for &p in &selected {
                if load_ramp_of[p] != u32::MAX && load_ramp_of[p] != ramp as u32 {
                    let key = if l.pulse_duration.is_some() {
                        "pulse_duration"
                    } else {
                        "ramp_time"
                    };
                    return Err(err(
                        format!("load.{i}.{key}"),
                        format!("particle {p} already carries a load with another time history (ramp_time or pulse_duration)"),
                    ));
                }
                load_ramp_of[p] = ramp as u32;
                particles.load[p] += match l.kind {
                    LoadKind::Point => vec(l.force.as_ref().unwrap()) / selected.len() as f64,
                    LoadKind::Traction => {
                        let face = Face::parse(l.face.as_ref().unwrap(), D).unwrap();
                        let half = particles.half_length0[p];
                        let area: f64 = (0..D)
                            .filter(|&d| d != face.axis)
                            .map(|d| 2.0 * half[d])
                            .product();
                        vec(l.traction.as_ref().unwrap()) * area
                    }
                };
            }
        }
        Ok(Model {
            grid,
            particles,
            materials,
            faces,
            friction,
            footing,
            absorbing,
            gravity,
            load_ramps,
            load_ramp_of,
        })
    }

    /// Load factor of each load time history at time t.
    pub fn load_scales(&self, t: f64) -> Vec<f64> {
        self.load_ramps.iter().map(|r| r.factor(t)).collect()
    }

    /// Set every material to the scene's one with c/F, tan φ/F, tan ψ/F when it
    /// has a frictional strength (strength reduction; F = 1: as given). Not
    /// cumulative: each call starts from the scene's values. The particles keep
    /// their stresses; the next stress update returns them to the new surface.
    pub fn reduce_strength(&mut self, scene: &[MaterialConfig], factor: f64) {
        self.materials = scene
            .iter()
            .map(|c| {
                let m = material(c);
                m.with_reduced_strength(factor).unwrap_or(m)
            })
            .collect();
    }

    /// Equivalent plastic strain of every particle (0 where the material has
    /// none), or `None` when no material of the scene has one.
    pub fn plastic_strain(&self) -> Option<Vec<f64>> {
        let p = &self.particles;
        let values: Vec<Option<f64>> = (0..p.len())
            .map(|q| {
                self.materials[p.material[q] as usize].equivalent_plastic_strain(p.history.get(q))
            })
            .collect();
        values
            .iter()
            .any(Option::is_some)
            .then(|| values.iter().map(|v| v.unwrap_or(0.0)).collect())
    }

    /// Index of the particle whose reference position is nearest to `x`.
    pub fn nearest_particle(&self, x: &[f64]) -> Option<usize> {
        let p = &self.particles;
        let d2 = |q: usize| (0..D).map(|d| (p.x0[q][d] - x[d]).powi(2)).sum::<f64>();
        (0..p.len()).min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
    }

    /// Number of bodies (for per-body outputs).
    pub fn n_bodies(&self) -> usize {
        self.particles
            .body
            .iter()
            .map(|&b| b as usize + 1)
            .max()
            .unwrap_or(0)
    }
}

/// How a load varies in time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadTime {
    /// min(t / ramp_time, 1); at once when the ramp time is 0.
    Ramp(f64),
    /// A smooth pulse of duration T: sin²(π t / T) for t ≤ T, then 0.
    Pulse(f64),
}

impl LoadTime {
    pub fn factor(&self, t: f64) -> f64 {
        match *self {
            LoadTime::Ramp(r) if r > 0.0 => (t / r).min(1.0),
            LoadTime::Ramp(_) => 1.0,
            LoadTime::Pulse(d) if t >= 0.0 && t <= d => {
                (std::f64::consts::PI * t / d).sin().powi(2)
            }
            LoadTime::Pulse(_) => 0.0,
        }
    }
}

/// Load factor of particle q from its ramp (`Model::load_ramp_of`) and the factor
/// of each ramp (0: the particle carries no load).
pub fn load_factor(ramp_of: &[u32], q: usize, scales: &[f64]) -> f64 {
    match ramp_of[q] {
        u32::MAX => 0.0,
        r => scales[r as usize],
    }
}

fn material(m: &MaterialConfig) -> Box<dyn Material> {
    let nu = m.poisson_ratio.unwrap();
    match m.model {
        MaterialModel::LinearElastic => {
            Box::new(LinearElastic::new(m.density, m.youngs_modulus.unwrap(), nu))
        }
        MaterialModel::Hencky => Box::new(Hencky::new(m.density, m.youngs_modulus.unwrap(), nu)),
        MaterialModel::NeoHookean => {
            Box::new(NeoHookean::new(m.density, m.youngs_modulus.unwrap(), nu))
        }
        MaterialModel::MooneyRivlin => Box::new(MooneyRivlin::from_thesis(
            m.density,
            m.a.unwrap(),
            m.b.unwrap(),
            nu,
        )),
        MaterialModel::Ogden => Box::new(Ogden::new(
            m.density,
            m.mu.clone().unwrap(),
            m.alpha.clone().unwrap(),
            nu,
        )),
        MaterialModel::DruckerPrager => {
            let peak = peak_strength(m);
            Box::new(DruckerPrager {
                density: m.density,
                youngs_modulus: m.youngs_modulus.unwrap(),
                poisson_ratio: nu,
                cohesion: peak.cohesion,
                friction_angle: peak.friction_angle,
                dilation_angle: peak.dilation_angle,
                fit: match m.mohr_coulomb_fit.unwrap() {
                    MohrCoulombFit::Outer => drucker_prager::MohrCoulombFit::Outer,
                    MohrCoulombFit::Inner => drucker_prager::MohrCoulombFit::Inner,
                    MohrCoulombFit::PlaneStrain => drucker_prager::MohrCoulombFit::PlaneStrain,
                },
            })
        }
        MaterialModel::MohrCoulomb => {
            let peak = peak_strength(m);
            let softening = m.softening_start.map(|start| {
                let phi_r = m
                    .residual_friction_angle
                    .unwrap_or(m.friction_angle.unwrap());
                Softening {
                    residual_cohesion: m.residual_cohesion.unwrap_or(peak.cohesion),
                    residual_friction_angle: phi_r.to_radians(),
                    residual_dilation_angle: m
                        .residual_dilation_angle
                        .unwrap_or(m.dilation_angle.unwrap_or(0.0).min(phi_r))
                        .to_radians(),
                    start,
                    end: m.softening_end.unwrap(),
                }
            });
            Box::new(MohrCoulomb {
                density: m.density,
                youngs_modulus: m.youngs_modulus.unwrap(),
                poisson_ratio: nu,
                peak,
                softening,
                tensile_strength: m.tensile_strength,
            })
        }
    }
}

/// Peak cohesion, friction and dilation (degrees in the scene, radians here).
fn peak_strength(m: &MaterialConfig) -> Strength {
    Strength {
        cohesion: m.cohesion.unwrap(),
        friction_angle: m.friction_angle.unwrap().to_radians(),
        dilation_angle: m.dilation_angle.unwrap_or(0.0).to_radians(),
    }
}

fn face_condition<const D: usize>(
    b: &crate::scene::BoundaryConfig,
    dim: usize,
    vec: &impl Fn(&[f64]) -> Vector<D>,
) -> FaceCondition<D> {
    let face = Face::parse(&b.face, dim).unwrap();
    let mut constraint = Constraint::<D>::free();
    match b.condition {
        Condition::Fixed => (0..D).for_each(|d| constraint.set(d, 0.0)),
        Condition::Roller => constraint.set(face.axis, 0.0),
        Condition::Absorbing | Condition::Friction => {
            unreachable!("absorbing and friction faces are not velocity conditions")
        }
        Condition::Velocity => {
            let v = vec(b.velocity.as_ref().unwrap());
            let comps: Vec<usize> = match &b.components {
                Some(c) => c.iter().map(|a| axis(a).unwrap()).collect(),
                None => (0..D).collect(),
            };
            comps.into_iter().for_each(|d| constraint.set(d, v[d]));
        }
    }
    let region = b
        .region_min
        .as_ref()
        .zip(b.region_max.as_ref())
        .map(|(lo, hi)| (vec(lo), vec(hi)));
    FaceCondition {
        face,
        constraint,
        region,
    }
}

/// The footing (the velocity condition with a `footing_width`), with the cohesion
/// of the material of the particle nearest to the centre of its region.
fn footing<const D: usize>(
    c: &crate::scene::SceneConfig,
    faces: &[FaceCondition<D>],
    grid: &Grid<D>,
    particles: &Particles<D>,
) -> Option<Footing<D>> {
    let (b, condition) = c
        .boundaries
        .iter()
        .filter(|b| !matches!(b.condition, Condition::Absorbing | Condition::Friction))
        .zip(faces)
        .find(|(b, _)| b.footing_width.is_some())?;
    let nodes: Vec<Vector<D>> = (0..grid.node_count())
        .map(|g| grid.node_ijk(g))
        .filter(|&ijk| condition.acts_on(grid, ijk))
        .map(|ijk| grid.node_position(ijk))
        .collect();
    let centre = nodes.iter().sum::<Vector<D>>() / nodes.len() as f64;
    let nearest = (0..particles.len()).min_by(|&a, &b| {
        let (da, db) = (particles.x[a] - centre, particles.x[b] - centre);
        da.norm_squared().total_cmp(&db.norm_squared())
    });
    Some(Footing {
        condition: *condition,
        width: b.footing_width.unwrap(),
        cohesion: nearest.and_then(|q| c.materials[particles.material[q] as usize].cohesion),
    })
}

/// Put particles on the lattice of `particles_per_cell` points per cell direction
/// (aligned with the grid) wherever the lattice point lies inside the body.
fn fill_body<const D: usize>(
    particles: &mut Particles<D>,
    grid: &Grid<D>,
    b: &BodyConfig,
    i: usize,
    material: u32,
    model: &dyn Material,
) -> Result<usize, (String, String)> {
    let (lo, hi) = body_bounds(b, i, D)?;
    let spacing = Vector::<D>::from_fn(|d, _| grid.h[d] / b.particles_per_cell.get(d) as f64);
    let volume = spacing.product();
    let mass = model.density() * volume;
    // Lattice index range covering the bounding box.
    let first: [usize; D] =
        std::array::from_fn(|d| (((lo[d] - grid.min[d]) / spacing[d]).floor().max(0.0)) as usize);
    let last: [usize; D] =
        std::array::from_fn(|d| ((hi[d] - grid.min[d]) / spacing[d]).ceil() as usize);
    let counts: Vec<usize> = (0..D).map(|d| last[d].saturating_sub(first[d])).collect();
    let total: usize = counts.iter().product();
    let uniform = b
        .velocity
        .as_deref()
        .map_or(Vector::<D>::zeros(), |v| Vector::<D>::from_fn(|d, _| v[d]));
    let mut added = 0;
    for flat in 0..total {
        let mut rem = flat;
        let x = Vector::<D>::from_fn(|d, _| {
            let k = first[d] + rem % counts[d];
            rem /= counts[d];
            grid.min[d] + (k as f64 + 0.5) * spacing[d]
        });
        if !inside(b, &x) {
            continue;
        }
        let mut v = uniform;
        if let Some(exprs) = &b.velocity_expr {
            let mut pos = [0.0; 3];
            (0..D).for_each(|d| pos[d] = x[d]);
            for (d, e) in exprs.iter().enumerate() {
                v[d] +=
                    expr::eval(e, &pos).map_err(|m| (format!("body.{i}.velocity_expr.{d}"), m))?;
            }
        }
        particles.push(
            x,
            v,
            mass,
            volume,
            spacing / 2.0,
            i as u32,
            material,
            model.n_history(),
        );
        added += 1;
    }
    Ok(added)
}

/// Is the lattice point x inside the body's geometry?
fn inside<const D: usize>(b: &BodyConfig, x: &Vector<D>) -> bool {
    match b.shape {
        Shape::Rectangle | Shape::Box => {
            let (lo, hi) = (b.min.as_ref().unwrap(), b.max.as_ref().unwrap());
            (0..D).all(|d| x[d] > lo[d] && x[d] < hi[d])
        }
        Shape::Disk | Shape::Sphere => {
            let c = b.centre.as_ref().unwrap();
            let r2: f64 = (0..D).map(|d| (x[d] - c[d]).powi(2)).sum();
            r2 < b.radius.unwrap().powi(2)
        }
        Shape::Polygon => point_in_polygon(x[0], x[1], b.vertices.as_ref().unwrap()),
    }
}

/// Even-odd rule (ray crossing to +x).
fn point_in_polygon(x: f64, y: f64, v: &[Vec<f64>]) -> bool {
    let mut inside = false;
    let n = v.len();
    for k in 0..n {
        let (a, b) = (&v[k], &v[(k + 1) % n]);
        if (a[1] > y) != (b[1] > y) {
            let xc = a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x < xc {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    #[test]
    fn polygon_membership() {
        let tri = vec![vec![0.0, 0.0], vec![2.0, 0.0], vec![0.0, 2.0]];
        assert!(super::point_in_polygon(0.5, 0.5, &tri));
        assert!(!super::point_in_polygon(1.5, 1.5, &tri));
    }
}
