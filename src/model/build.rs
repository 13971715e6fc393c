//! `Model::build`: from a validated scene to the model. The materials come from
//! `material::registry`, the bodies are filled with particles on a lattice aligned
//! with the grid, and the conditions and loads are put on grid faces and
//! particles. What only the built model can tell (a region without grid nodes, a
//! load region without particles, an absorbing face without material next to it)
//! is reported here, at the scene key.

use crate::dim::Vector;
use crate::material::bond::BondLaw;
use crate::material::Material;
use crate::model::body::{Body, BodyKind};
use crate::model::conditions::{
    Absorbing, Constraint, FaceCondition, FaceMotion, Footing, FrictionFace, MotionKind,
};
use crate::model::curve::TimeCurve;
use crate::model::drainage::Drainage;
use crate::model::geometry::Geometry;
use crate::model::grid::Grid;
use crate::model::loads::{LoadTime, Loads};
use crate::model::mesh::ElementMesh;
use crate::model::particle_set::ParticleSet;
use crate::model::particles::Particles;
use crate::model::peridynamics::bonds::Bonds;
use crate::model::peridynamics::state::StressState;
use crate::model::peridynamics::{PdBody, Peridynamics};
use crate::model::triangles::{Cells, TriangleSurface};
use crate::model::water::Water;
use crate::model::{axisymmetry, import, Model};
use crate::scene::SceneConfig;
use crate::scene::{
    axis, expr, BodyConfig, BoundaryConfig, Condition, DomainStress, Face, Fill, ParticlesOutside,
    Scene, SceneError,
};
use std::sync::Arc;

impl<const D: usize> Model<D> {
    pub fn build(scene: &Scene) -> Result<Model<D>, SceneError> {
        let c = &scene.config;
        assert_eq!(
            c.dimension.spatial(),
            D,
            "caller dispatches on the scene dimension"
        );
        let err = |(key, msg): (String, String)| scene.at_key(&key, msg);
        let vec = |v: &[f64]| Vector::<D>::from_fn(|d, _| v[d]);
        let cells = std::array::from_fn(|d| c.grid.cells[d]);
        let grid = Grid::new(
            vec(&c.grid.min),
            vec(&c.grid.max),
            cells,
            c.grid.shape_function.degree(),
        );
        let tables = (c.materials.iter().enumerate())
            .map(|(i, m)| m.build(i))
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        // A rigid body's particles carry the zero-stress material (`model::body`).
        let base_materials = c.particle_materials(tables);
        let bodies = (0..c.bodies.len())
            .map(|i| import::body_geometry(scene, i).map(|g| Body::of(c, i, g)))
            .collect::<Result<Vec<Body>, _>>()?;
        let mut particles = Particles::default();
        for (i, b) in c.bodies.iter().enumerate() {
            let m = c
                .materials
                .iter()
                .position(|m| m.name == b.material)
                .expect("validated");
            let material = base_materials[m].as_ref();
            let added = match &bodies[i].geometry {
                Geometry::Particles(set) => {
                    put_file_particles(&mut particles, b, set, i, m as u32, &base_materials)
                        .map_err(err)?
                }
                geometry => fill_body(&mut particles, &grid, b, geometry, i, m as u32, material)
                    .map_err(err)?,
            };
            // A particle file's volumes are per radian already.
            let file = matches!(bodies[i].geometry, Geometry::Particles(_));
            if c.dimension.is_axisymmetric() && !file {
                axisymmetry::per_radian(&mut particles, added);
            }
            if added == 0 {
                return Err(err((format!("body.{i}.shape"), "the body holds no particle centre: refine the grid or raise particles_per_cell".into())));
            }
        }
        let peridynamics = peridynamic_bodies(c, &bodies, &particles);
        // The velocity conditions, with the index of their [[boundary]] table.
        let velocity: Vec<(usize, &BoundaryConfig)> = (c.boundaries.iter().enumerate())
            .filter(|(_, b)| b.condition.prescribes_velocity())
            .collect();
        let mut faces: Vec<FaceCondition<D>> = velocity
            .iter()
            .map(|(_, b)| face_condition(b, &vec))
            .collect();
        let face_motions = face_motions(&velocity, &vec);
        let friction_tables: Vec<(usize, &BoundaryConfig)> = (c.boundaries.iter().enumerate())
            .filter(|(_, b)| b.condition == Condition::Friction)
            .collect();
        let friction = (friction_tables.iter())
            .map(|(_, b)| FrictionFace {
                face: Face::parse(&b.face, D).unwrap(),
                coefficient: b.friction_coefficient.unwrap(),
                velocity: Vector::<D>::zeros(),
            })
            .collect();
        let wall_motions = wall_motions(&friction_tables, &vec);
        for ((i, _), fc) in velocity.iter().zip(&faces) {
            holds_a_node(*i, fc, &grid).map_err(err)?;
        }
        let footing = footing(&velocity, &faces, &grid, &particles, &base_materials);
        let axisymmetric = c.dimension.is_axisymmetric();
        if axisymmetric && grid.min[0] == 0.0 {
            faces.push(axisymmetry::axis_condition());
        }
        let absorbing = Absorbing::new(&c.boundaries, &base_materials);
        absorbing
            .check_adjacent(&grid, &particles)
            .map_err(|(i, msg)| err((format!("boundary.{i}.face"), msg)))?;
        let drained: Vec<(usize, FaceCondition<D>, f64)> = (c.boundaries.iter().enumerate())
            .filter(|(_, b)| b.condition == Condition::Drained)
            .map(|(i, b)| (i, face_condition(b, &vec), b.pore_pressure.unwrap_or(0.0)))
            .collect();
        for (i, fc, _) in &drained {
            holds_a_node(*i, fc, &grid).map_err(err)?;
        }
        let drained = drained.into_iter().map(|(_, fc, p)| (fc, p)).collect();
        let drainage = Drainage::new(&base_materials, drained);
        let gravity = c.gravity.as_deref().map_or(Vector::<D>::zeros(), vec);
        let loads = Loads::apply(c, &mut particles).map_err(err)?;
        let erosion = base_materials.iter().any(|m| m.erodes());
        let mut model = Model {
            erosion,
            remove_outside: c.grid.particles_outside == ParticlesOutside::Remove,
            linear_domain_stress: c.grid.domain_stress == DomainStress::Linear,
            grid,
            particles,
            materials: base_materials.clone(),
            base_materials,
            bodies,
            faces,
            face_motions,
            wall_motions,
            friction,
            footing,
            absorbing,
            contact: crate::scene::contact::plan(c).map_err(err)?,
            gravity,
            gravity_history: (c.gravity_history.as_ref())
                .map(|h| LoadTime::Curve(Arc::new(TimeCurve::new(&h.points())))),
            load_ramps: loads.ramps,
            load_ramp_of: loads.ramp_of,
            axisymmetric,
            peridynamics,
            staging: None,
            water: (c.water.as_ref())
                .map(|w| Water::new(w, c.gravity.as_deref().expect("validated"))),
            drainage,
        };
        if c.stages_construction() {
            model.start_staging(&c.inactive_bodies());
        }
        model.update_pore_pressure();
        Ok(model)
    }
}

/// The peridynamic bodies with their bonds (`model::peridynamics`), built
/// from the particles' reference positions and volumes, a correspondence
/// body with its own material (built from its table: its particles carry the
/// zero-stress one) at rest; None without one.
fn peridynamic_bodies<const D: usize>(
    c: &SceneConfig,
    bodies: &[Body],
    p: &Particles<D>,
) -> Option<Peridynamics<D>> {
    let pd: Vec<PdBody<D>> = (0..bodies.len())
        .filter(|&i| bodies[i].kind == BodyKind::Peridynamic)
        .map(|i| {
            let of: Vec<usize> = (0..p.len()).filter(|&q| p.body[q] as usize == i).collect();
            let x: Vec<Vector<D>> = of.iter().map(|&q| p.x[q]).collect();
            let volume = of.iter().map(|&q| p.volume[q]).collect();
            // A bond stays inside its body (not across a notch), sampled every
            // half particle spacing.
            let (shape, step) = (&bodies[i].geometry, 0.5 * c.particle_spacing(i));
            let inside =
                |j: usize, k: usize| shape.holds_segment(x[j].as_slice(), x[k].as_slice(), step);
            let law = c.peridynamic(i);
            let bonds = Bonds::build_where(&x, law.horizon(), inside);
            let n = of.len();
            let body = PdBody::with_bonds(i, of, &x, volume, law, bonds)
                .with_short_range(c.short_range(i, &law));
            match law {
                BondLaw::Correspondence(_) => {
                    let k = p.material[body.particles[0]] as usize;
                    let material = c.materials[k].build(k).expect("validated");
                    body.with_stress(StressState::at_rest(material, n))
                }
                _ => body,
            }
        })
        .collect();
    (!pd.is_empty()).then(|| Peridynamics::new(pd, &p.mass))
}

/// A condition's region must hold at least one node of its face (boundary i).
fn holds_a_node<const D: usize>(
    i: usize,
    fc: &FaceCondition<D>,
    grid: &Grid<D>,
) -> Result<(), (String, String)> {
    if (0..grid.node_count()).any(|g| fc.acts_on(grid, grid.node_ijk(g))) {
        Ok(())
    } else {
        Err((
            format!("boundary.{i}.region_min"),
            "the region holds no grid node of the face".into(),
        ))
    }
}

fn face_condition<const D: usize>(
    b: &BoundaryConfig,
    vec: &impl Fn(&[f64]) -> Vector<D>,
) -> FaceCondition<D> {
    let face = Face::parse(&b.face, D).unwrap();
    let mut constraint = Constraint::<D>::free();
    match b.condition {
        Condition::Fixed => (0..D).for_each(|d| constraint.set(d, 0.0)),
        Condition::Roller => constraint.set(face.axis, 0.0),
        // A drained face holds the pore pressure, not the velocity.
        Condition::Drained => {}
        Condition::Absorbing | Condition::Friction => {
            unreachable!("absorbing and friction faces are not velocity conditions")
        }
        Condition::Velocity => {
            let v = vec(motion_vector(b).1);
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

/// The vector of a velocity condition and what it is: `velocity`,
/// `acceleration` or `displacement` (validated: exactly one).
fn motion_vector(b: &BoundaryConfig) -> (MotionKind, &[f64]) {
    match (&b.velocity, &b.acceleration, &b.displacement) {
        (Some(v), _, _) => (MotionKind::Velocity, v),
        (None, Some(a), _) => (MotionKind::Acceleration, a),
        (None, None, Some(u)) => (MotionKind::Displacement, u),
        (None, None, None) => unreachable!("validated: a velocity condition gives a vector"),
    }
}

/// The velocity conditions (`velocity`, in the order of `Model::faces`) that
/// follow a time history.
fn face_motions<const D: usize>(
    velocity: &[(usize, &BoundaryConfig)],
    vec: &impl Fn(&[f64]) -> Vector<D>,
) -> Vec<FaceMotion<D>> {
    (velocity.iter().enumerate())
        .filter_map(|(face, (_, b))| {
            let h = b.time_history.as_ref()?;
            let (kind, amplitude) = motion_vector(b);
            Some(FaceMotion {
                face,
                kind,
                amplitude: vec(amplitude),
                curve: Arc::new(TimeCurve::new(&h.points())),
            })
        })
        .collect()
}

/// The friction faces (in the order of `Model::friction`) that move along
/// themselves: a constant `velocity`, or a vector with a time history.
fn wall_motions<const D: usize>(
    friction: &[(usize, &BoundaryConfig)],
    vec: &impl Fn(&[f64]) -> Vector<D>,
) -> Vec<FaceMotion<D>> {
    (friction.iter().enumerate())
        .filter(|(_, (_, b))| b.velocity.is_some() || b.time_history.is_some())
        .map(|(face, (_, b))| {
            let (kind, amplitude) = motion_vector(b);
            let points = (b.time_history.as_ref()).map_or(vec![[0.0, 1.0]], |h| h.points());
            FaceMotion {
                face,
                kind,
                amplitude: vec(amplitude),
                curve: Arc::new(TimeCurve::new(&points)),
            }
        })
        .collect()
}

/// The footing (the velocity condition with a `footing_width`), with the cohesion
/// of the material of the particle nearest to the centre of its region.
fn footing<const D: usize>(
    velocity: &[(usize, &BoundaryConfig)],
    faces: &[FaceCondition<D>],
    grid: &Grid<D>,
    particles: &Particles<D>,
    materials: &[Box<dyn Material>],
) -> Option<Footing<D>> {
    let ((_, b), condition) = velocity
        .iter()
        .zip(faces)
        .find(|((_, b), _)| b.footing_width.is_some())?;
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
    let strength = |q: usize| materials[particles.material[q] as usize].frictional_strength();
    Some(Footing {
        condition: *condition,
        width: b.footing_width.unwrap(),
        cohesion: nearest.and_then(strength).map(|s| s.cohesion),
    })
}

/// Put particles on the lattice of `particles_per_cell` points per cell direction
/// (aligned with the grid) wherever the lattice point lies inside the body.
fn fill_body<const D: usize>(
    particles: &mut Particles<D>,
    grid: &Grid<D>,
    b: &BodyConfig,
    geometry: &Geometry,
    i: usize,
    material: u32,
    model: &dyn Material,
) -> Result<usize, (String, String)> {
    let spacing = Vector::<D>::from_fn(|d, _| grid.h[d] / b.particles_per_cell.get(d) as f64);
    let points = match (b.fill, geometry) {
        (_, Geometry::Surface(surface)) => surface_cells(grid, surface, geometry, &spacing),
        (_, Geometry::Mesh(mesh)) => mesh_points(mesh),
        (Fill::Lattice, _) => lattice(grid, geometry, &spacing),
        (Fill::Polar, _) => polar(b, spacing[0].min(spacing[1]), spacing[D - 1]),
    };
    let uniform = b
        .velocity
        .as_deref()
        .map_or(Vector::<D>::zeros(), |v| Vector::<D>::from_fn(|d, _| v[d]));
    particles.reserve(points.len());
    let mut added = 0;
    for (x, volume, half) in points {
        let v = uniform + velocity_expr(b, i, &x)?;
        particles.push(
            x,
            v,
            model.density() * volume,
            volume,
            half,
            i as u32,
            material,
            model.n_history(),
        );
        added += 1;
    }
    Ok(added)
}

/// The body's `velocity_expr` at x (zero without one).
fn velocity_expr<const D: usize>(
    b: &BodyConfig,
    i: usize,
    x: &Vector<D>,
) -> Result<Vector<D>, (String, String)> {
    let mut v = Vector::<D>::zeros();
    if let Some(exprs) = &b.velocity_expr {
        let mut pos = [0.0; 3];
        (0..D).for_each(|d| pos[d] = x[d]);
        for (d, e) in exprs.iter().enumerate() {
            v[d] += expr::eval(e, &pos).map_err(|m| (format!("body.{i}.velocity_expr.{d}"), m))?;
        }
    }
    Ok(v)
}

/// Put the particles of a particle file in as they are: each with its
/// volume, its row's material (else the body's, `material`), its stress and
/// its velocity plus the body's `velocity` and `velocity_expr`; its domain the
/// square (cube) of its volume (`ParticleSet::half_length`).
fn put_file_particles<const D: usize>(
    particles: &mut Particles<D>,
    b: &BodyConfig,
    set: &ParticleSet,
    i: usize,
    material: u32,
    materials: &[Box<dyn Material>],
) -> Result<usize, (String, String)> {
    let uniform = b
        .velocity
        .as_deref()
        .map_or(Vector::<D>::zeros(), |v| Vector::<D>::from_fn(|d, _| v[d]));
    particles.reserve(set.particles.len());
    for (q, p) in set.particles.iter().enumerate() {
        let x = Vector::<D>::from_fn(|d, _| p.x[d]);
        let own = p
            .velocity
            .map_or(Vector::<D>::zeros(), |v| Vector::<D>::from_fn(|d, _| v[d]));
        let v = own + uniform + velocity_expr(b, i, &x)?;
        let m = p.material.unwrap_or(material);
        let model = materials[m as usize].as_ref();
        let h = set.half_length(q);
        let half = Vector::<D>::from_fn(|d, _| h[d]);
        particles.push(
            x,
            v,
            model.density() * p.volume,
            p.volume,
            half,
            i as u32,
            m,
            model.n_history(),
        );
        if let Some(s) = &p.stress {
            particles.stress.set(particles.len() - 1, s);
        }
    }
    Ok(set.particles.len())
}

/// A particle of a fill: position, volume and the half-lengths of its domain.
type Point<const D: usize> = (Vector<D>, f64, Vector<D>);

/// The lattice index range [first, last) covering the body's bounding box.
fn lattice_range<const D: usize>(
    grid: &Grid<D>,
    geometry: &Geometry,
    spacing: &Vector<D>,
) -> ([usize; D], [usize; D]) {
    let (lo, hi) = geometry.bounds();
    let first: [usize; D] =
        std::array::from_fn(|d| (((lo[d] - grid.min[d]) / spacing[d]).floor().max(0.0)) as usize);
    // A body cut at a symmetry plane keeps the part inside the grid.
    let last: [usize; D] = std::array::from_fn(|d| {
        let upper = hi[d].min(grid.min[d] + grid.h[d] * grid.cells[d] as f64);
        ((upper - grid.min[d]) / spacing[d]).ceil() as usize
    });
    (first, last)
}

/// A mesh's particles at its elements' Gauss points (`ElementMesh::gauss_points`),
/// each domain the square (cube) of its volume, as a particle file's
/// (`ParticleSet::half_length`; of the area, before `axisymmetry::per_radian`).
fn mesh_points<const D: usize>(mesh: &ElementMesh) -> Vec<Point<D>> {
    (mesh.gauss_points().into_iter())
        .map(|(x, volume)| {
            let half = 0.5 * volume.powf(1.0 / D as f64);
            let x = Vector::<D>::from_fn(|d, _| x[d]);
            (x, volume, Vector::<D>::repeat(half))
        })
        .collect()
}

/// A closed surface on the lattice: each lattice cell the solid reaches
/// holds one particle with the solid's volume in the cell, at the lattice
/// point where the cell is whole (as `lattice` puts it) and at the centroid of
/// the part inside where the surface cuts the cell (`TriangleSurface::cell_parts`);
/// its domain the cell's, shrunk to the part's volume.
fn surface_cells<const D: usize>(
    grid: &Grid<D>,
    surface: &TriangleSurface,
    geometry: &Geometry,
    spacing: &Vector<D>,
) -> Vec<Point<D>> {
    let (first, last) = lattice_range(grid, geometry, spacing);
    let cells = Cells {
        origin: std::array::from_fn(|d| grid.min[d]),
        spacing: std::array::from_fn(|d| spacing[d]),
        first: std::array::from_fn(|d| first[d]),
        last: std::array::from_fn(|d| last[d]),
    };
    let whole = spacing.product();
    (surface.cell_parts(&cells).into_iter())
        .map(|part| {
            let fraction = part.volume / whole;
            match fraction >= 1.0 - 1e-12 {
                true => {
                    let x = Vector::<D>::from_fn(|d, _| {
                        grid.min[d] + (part.cell[d] as f64 + 0.5) * spacing[d]
                    });
                    (x, whole, spacing / 2.0)
                }
                false => {
                    let x = Vector::<D>::from_fn(|d, _| part.centroid[d]);
                    let shrink = fraction.powf(1.0 / D as f64);
                    (x, part.volume, spacing * (0.5 * shrink))
                }
            }
        })
        .collect()
}

/// The lattice points with the given spacing that lie inside the body.
fn lattice<const D: usize>(
    grid: &Grid<D>,
    geometry: &Geometry,
    spacing: &Vector<D>,
) -> Vec<Point<D>> {
    let volume = spacing.product();
    let (first, last) = lattice_range(grid, geometry, spacing);
    let counts: Vec<usize> = (0..D).map(|d| last[d].saturating_sub(first[d])).collect();
    let total: usize = counts.iter().product();
    (0..total)
        .filter_map(|flat| {
            let mut rem = flat;
            let x = Vector::<D>::from_fn(|d, _| {
                let k = first[d] + rem % counts[d];
                rem /= counts[d];
                grid.min[d] + (k as f64 + 0.5) * spacing[d]
            });
            geometry
                .contains(x.as_slice())
                .then(|| (x, volume, spacing / 2.0))
        })
        .collect()
}

/// A disk in n = round(R/δ) rings of width Δ = R/n about its centre: ring k
/// (area π(2k + 1)Δ²) holds N_k = round(π(2k + 1)) particles of equal area at its
/// mid radius (k + ½)Δ, every other ring turned by half a pitch; each particle's
/// domain is the square of its area. A cylinder (3D, axis z) is that disk
/// repeated in layers of thickness about `spacing_z` along its height.
fn polar<const D: usize>(b: &BodyConfig, spacing: f64, spacing_z: f64) -> Vec<Point<D>> {
    let (c, radius) = (
        b.centre.as_ref().expect("validated"),
        b.radius.expect("validated"),
    );
    // The disk: (x, y, area) of each particle.
    let rings = (radius / spacing).round().max(1.0) as usize;
    let width = radius / rings as f64;
    let mut disk = Vec::new();
    for k in 0..rings {
        let band = std::f64::consts::PI * (2 * k + 1) as f64;
        let count = band.round().max(1.0) as usize;
        let area = band * width * width / count as f64;
        let r = (k as f64 + 0.5) * width;
        for j in 0..count {
            let turn = (j as f64 + 0.5 * (k % 2) as f64) / count as f64;
            let (sin, cos) = (2.0 * std::f64::consts::PI * turn).sin_cos();
            disk.push((c[0] + r * cos, c[1] + r * sin, area));
        }
    }
    // Layers along a cylinder's axis (a disk is one layer of unit thickness).
    let (layers, thickness) = match b.height {
        Some(height) if D == 3 => {
            let n = (height / spacing_z).round().max(1.0) as usize;
            (n, height / n as f64)
        }
        _ => (1, 1.0),
    };
    let z = |layer: usize| {
        c.get(2)
            .map_or(0.0, |base| base + (layer as f64 + 0.5) * thickness)
    };
    (0..layers)
        .flat_map(|layer| disk.iter().map(move |&p| (layer, p)))
        .map(|(layer, (x, y, area))| {
            let at = Vector::<D>::from_fn(|d, _| [x, y, z(layer)][d]);
            let side = 0.5 * area.sqrt();
            let half = Vector::<D>::from_fn(|d, _| if d < 2 { side } else { 0.5 * thickness });
            (at, area * thickness, half)
        })
        .collect()
}
