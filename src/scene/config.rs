//! The scene file's structure. Field names are the TOML keys; `docs/scene.md`
//! documents each one. Every section is a plain struct with `deny_unknown_fields`
//! (so TOML errors point at the offending key); which optional keys a given
//! `shape` or `condition` needs is checked in `validate`, the keys of a material
//! model by the model (`material.rs`), those of a solver in `solver.rs`. Vectors
//! are arrays whose length must equal `dimension`. Enumerated values are read
//! (serde) and named (strum, `name()`) in snake_case.

use super::curve::TimeHistory;
use super::grid::GridConfig;
use super::material::MaterialConfig;
use super::solver::SolverConfig;
use crate::material::rigid::Motion;
use serde::Deserialize;
use strum::{EnumIter, IntoStaticStr};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// 2 (plane strain), 3, or "axisymmetric" (r–z, two components).
    pub dimension: Dimension,
    /// Gravitational acceleration vector (default zero).
    #[serde(default)]
    pub gravity: Option<Vec<f64>>,
    /// Gravity times this time history's factor on the run's clock
    /// (`scene::curve`; none: the stages' ramps).
    pub gravity_history: Option<TimeHistory>,
    pub grid: GridConfig,
    #[serde(default, rename = "material")]
    pub materials: Vec<MaterialConfig>,
    #[serde(default, rename = "body")]
    pub bodies: Vec<BodyConfig>,
    #[serde(default, rename = "boundary")]
    pub boundaries: Vec<BoundaryConfig>,
    #[serde(default, rename = "load")]
    pub loads: Vec<LoadConfig>,
    /// Contact between bodies (explicit solver), one table per law.
    #[serde(default, rename = "contact")]
    pub contacts: Vec<ContactConfig>,
    /// A single solver for the whole run …
    pub solver: Option<SolverConfig>,
    /// … or a sequence of stages on the same particles, each with its own solver.
    #[serde(default, rename = "stage")]
    pub stages: Vec<SolverConfig>,
    #[serde(default)]
    pub output: OutputConfig,
    /// Geostatic (K0) initial stresses, set before the first stage.
    pub geostatic: Option<GeostaticConfig>,
    /// A prescribed pore-water field (`model::water`, docs/pore_water.md).
    pub water: Option<WaterConfig>,
    /// Search for the factor of safety by strength reduction (`mpm run` runs the
    /// stages once per trial factor; docs/strength_reduction.md).
    pub strength_reduction: Option<StrengthReductionConfig>,
    /// The analytical reference the scene's error is measured against (`mpm bench`).
    pub reference: Option<ReferenceConfig>,
    /// Settings of `mpm bench` for this scene.
    pub bench: Option<BenchConfig>,
}

/// The `dimension` key: a number of Cartesian dimensions (2: plane strain, 3),
/// or `"axisymmetric"`: a solid of revolution about the y axis, modelled on the
/// r–z half plane (x = r ≥ 0, y = z) with two components everywhere, as in 2D.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dimension {
    /// 2 or 3 (other numbers are refused by the validation).
    Cartesian(usize),
    Axisymmetric,
}

impl Dimension {
    /// The number of components of positions, velocities and grid indices: 2
    /// for the axisymmetric r–z plane.
    pub fn spatial(self) -> usize {
        match self {
            Dimension::Cartesian(d) => d,
            Dimension::Axisymmetric => 2,
        }
    }

    pub fn is_axisymmetric(self) -> bool {
        self == Dimension::Axisymmetric
    }

    /// "2D", "3D" or "axisymmetric" (messages).
    pub fn label(self) -> String {
        match self {
            Dimension::Cartesian(d) => format!("{d}D"),
            Dimension::Axisymmetric => "axisymmetric".into(),
        }
    }
}

impl<'de> Deserialize<'de> for Dimension {
    fn deserialize<De: serde::Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Dimension;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("2, 3 or \"axisymmetric\"")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Dimension, E> {
                usize::try_from(v).map(Dimension::Cartesian).map_err(|_| {
                    E::custom(format!("dimension {v}: expected 2, 3 or \"axisymmetric\""))
                })
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Dimension, E> {
                self.visit_i64(i64::try_from(v).unwrap_or(-1))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Dimension, E> {
                match v {
                    "axisymmetric" => Ok(Dimension::Axisymmetric),
                    _ => Err(E::custom(format!(
                        "unknown dimension `{v}`: expected 2, 3 or \"axisymmetric\""
                    ))),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum BodyShape {
    /// 2D, `min` and `max` corners.
    Rectangle,
    /// 3D, `min` and `max` corners.
    Box,
    /// 2D, `centre` and `radius`.
    Disk,
    /// 3D, `centre` and `radius`.
    Sphere,
    /// 2D, `vertices` of a simple polygon in order.
    Polygon,
    /// 3D, axis along z: `centre` of its bottom face, `radius`, `height`.
    Cylinder,
    /// 3D, a polygon extruded along an axis: `vertices` in the plane of the
    /// other two axes (in increasing order: x–z for the default axis y),
    /// `extent` = [from, to] along `axis`.
    Prism,
    /// The particles of a CSV `file` (positions, volumes, optional material,
    /// stress and velocity per row), 2D or 3D (`model::import::particle_file`).
    Particles,
    /// 3D, the closed triangulated surface of an STL `file` (binary or ASCII),
    /// filled on the lattice (`model::import::stl`).
    Surface,
    /// 3D, the ground under the surface of an ESRI ASCII grid `file` of
    /// elevations (z up) down to the elevation `base` (`model::import::esri_grid`).
    Terrain,
    /// The elements of a Gmsh MSH 4.1 `file` (2D: triangles and quadrilaterals,
    /// 3D: tetrahedra and hexahedra), optionally of one `physical` group, with a
    /// particle at each Gauss point of the `quadrature` (`model::import::gmsh`).
    Mesh,
}

impl BodyShape {
    /// Whether the body's geometry is read from its `file` (known only once
    /// read: `model::import`).
    pub fn from_file(self) -> bool {
        matches!(
            self,
            BodyShape::Particles | BodyShape::Surface | BodyShape::Terrain | BodyShape::Mesh
        )
    }
}

impl BodyShape {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

/// The `kind` of a `[[body]]`: what the model does with its particles
/// (`model::body::BodyKind`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum BodyKindName {
    /// A deformable body integrated through the grid, with its material's
    /// constitutive model.
    #[default]
    Continuum,
    /// A rigid body (`motion`): it meets the other bodies through contact only
    /// and takes only the density of its material.
    Rigid,
    /// A bond-based peridynamic body (`horizon`, `bond_model`, fracture):
    /// advanced by its bonds' forces (`physics::peridynamics`); it takes the
    /// density, E and ν of its material.
    Peridynamic,
}

/// The bond model of a peridynamic body (`bond_model`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum BondModel {
    /// Prototype microelastic brittle (`material::bond::pmb`).
    #[default]
    Pmb,
    /// Beam-based: axial and tangential micromoduli (`material::bond::beam`).
    Beam,
    /// Non-ordinary state-based: the stress of the body's own material
    /// (`material::bond::correspondence`).
    Correspondence,
}

/// The 2D idealisation of a peridynamic body (`plane`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Plane {
    /// Plane strain (the 2D of the rest of the code; PMB ν = 1/4).
    #[default]
    Strain,
    /// Plane stress (PMB ν = 1/3).
    Stress,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    #[serde(default)]
    pub name: Option<String>,
    /// `continuum` or `rigid`; without it, rigid when the material is an
    /// old-form rigid one (`model = "rigid"`), else continuum
    /// (`SceneConfig::body_kind`, `body_kind.rs`).
    pub kind: Option<BodyKindName>,
    /// A rigid body's motion: `prescribed` (the default) or `free`.
    pub motion: Option<Motion>,
    /// `false`: the body enters the model when a stage activates it
    /// (`[[stage]] activate`; default true).
    pub active: Option<bool>,
    pub material: String,
    pub shape: BodyShape,
    pub min: Option<Vec<f64>>,
    pub max: Option<Vec<f64>>,
    pub centre: Option<Vec<f64>>,
    pub radius: Option<f64>,
    pub vertices: Option<Vec<Vec<f64>>>,
    /// Length along its axis (cylinder).
    pub height: Option<f64>,
    /// The axis a prism is extruded along: "x", "y" (default) or "z".
    pub axis: Option<String>,
    /// [from, to] of a prism along its axis.
    pub extent: Option<Vec<f64>>,
    /// The file of a `particles` or `surface` body, relative to the scene
    /// file's folder.
    pub file: Option<String>,
    /// A `particles` body: only the rows whose `body` column is this number.
    pub body_id: Option<u32>,
    /// A `terrain` body's bottom elevation (z).
    pub base: Option<f64>,
    /// A `terrain` body's bottom surface: a raster file (the top of the layer
    /// below), relative to the scene file's folder; instead of `base`.
    pub base_file: Option<String>,
    /// A `mesh` body: the elements of this physical group only (its name or
    /// its number); without it, every element of the scene's dimension.
    pub physical: Option<PhysicalGroup>,
    /// A `mesh` body: the Gauss points per element (default `full`).
    pub quadrature: Option<Quadrature>,
    /// Particles per cell per direction: one number or one per direction.
    #[serde(default = "default_ppc")]
    pub particles_per_cell: PerDirection,
    /// Uniform initial velocity.
    #[serde(default)]
    pub velocity: Option<Vec<f64>>,
    /// Initial velocity as expressions in the reference position x, y, z (with
    /// pi, sin, cos, exp, sqrt, abs), one per component; added to `velocity`.
    #[serde(default)]
    pub velocity_expr: Option<Vec<String>>,
    /// How the body is filled with particles (default `lattice`).
    #[serde(default)]
    pub fill: Fill,
    /// Peridynamic body: its horizon δ, or `horizon_factor` m = δ/Δx (Δx its
    /// particle spacing, the largest over the directions; default 3).
    pub horizon: Option<f64>,
    pub horizon_factor: Option<f64>,
    /// Peridynamic body: its bond model (default `pmb`).
    pub bond_model: Option<BondModel>,
    /// Peridynamic body: fracture energy G0 or critical stretch s0 (neither: no
    /// fracture).
    pub fracture_energy: Option<f64>,
    pub critical_stretch: Option<f64>,
    /// Peridynamic body in 2D: `strain` (default) or `stress`.
    pub plane: Option<Plane>,
    /// Correspondence peridynamic body: G of its zero-energy control (default
    /// `material::bond::correspondence::ZERO_ENERGY_CONTROL`) and its influence
    /// function (default constant).
    pub zero_energy_control: Option<f64>,
    pub influence: Option<crate::material::bond::correspondence::Influence>,
    /// Peridynamic body: c_S/c of the repulsion of its particles that no
    /// intact bond joins (default `material::bond::short_range::FACTOR`; 0:
    /// none).
    pub short_range_force: Option<f64>,
}

/// A physical group of a Gmsh file, by its name or its number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PhysicalGroup {
    Name(String),
    Tag(i64),
}

impl<'de> Deserialize<'de> for PhysicalGroup {
    fn deserialize<De: serde::Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = PhysicalGroup;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the name (a string) or the number of a physical group")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<PhysicalGroup, E> {
                Ok(PhysicalGroup::Tag(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<PhysicalGroup, E> {
                i64::try_from(v)
                    .map(PhysicalGroup::Tag)
                    .map_err(|_| E::custom(format!("physical group {v}: too large a number")))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<PhysicalGroup, E> {
                Ok(PhysicalGroup::Name(v.to_string()))
            }
        }
        d.deserialize_any(Visitor)
    }
}

impl std::fmt::Display for PhysicalGroup {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            PhysicalGroup::Name(n) => write!(f, "`{n}`"),
            PhysicalGroup::Tag(t) => write!(f, "{t}"),
        }
    }
}

/// The Gauss points a `mesh` body puts in each element (`model::mesh`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Quadrature {
    /// 3 per triangle, 2 × 2 per quadrilateral, 4 per tetrahedron, 2 × 2 × 2
    /// per hexahedron: the body's volume and first moments exact.
    #[default]
    Full,
    /// One per element, at ξ = 0 (a simplex's centroid) with the element's
    /// volume.
    One,
}

/// The particle fill of a body.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Fill {
    /// The grid-aligned lattice, `particles_per_cell` per cell and direction,
    /// keeping the points inside the shape (its curved faces become steps).
    #[default]
    Lattice,
    /// A disk in rings of equal width about its centre, each ring's particles
    /// of equal area (about the lattice's spacing): a smooth outer surface.
    Polar,
}

impl BodyConfig {
    /// Corners of the bounding box of the body's shape (its keys validated);
    /// `None` for a body read from a file, whose bounds the model knows once it
    /// has read the file (`model::geometry::Geometry::bounds`).
    pub fn bounds(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        Some(match self.shape {
            BodyShape::Rectangle | BodyShape::Box => {
                (self.min.clone().unwrap(), self.max.clone().unwrap())
            }
            BodyShape::Disk | BodyShape::Sphere => {
                let (c, r) = (self.centre.as_ref().unwrap(), self.radius.unwrap());
                (
                    c.iter().map(|x| x - r).collect(),
                    c.iter().map(|x| x + r).collect(),
                )
            }
            BodyShape::Cylinder => {
                let (c, r, h) = (
                    self.centre.as_ref().unwrap(),
                    self.radius.unwrap(),
                    self.height.unwrap(),
                );
                (
                    vec![c[0] - r, c[1] - r, c[2]],
                    vec![c[0] + r, c[1] + r, c[2] + h],
                )
            }
            BodyShape::Polygon => {
                let v = self.vertices.as_ref().unwrap();
                let lo = (0..2)
                    .map(|d| v.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min))
                    .collect();
                let hi = (0..2)
                    .map(|d| v.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max))
                    .collect();
                (lo, hi)
            }
            BodyShape::Prism => {
                let e = self.extent.as_ref().unwrap();
                prism_bounds(
                    self.vertices.as_ref().unwrap(),
                    self.prism_axis(),
                    [e[0], e[1]],
                )
            }
            BodyShape::Particles | BodyShape::Surface | BodyShape::Terrain | BodyShape::Mesh => {
                return None
            }
        })
    }

    /// A prism's axis (validated): 0, 1 or 2; y when not given.
    pub fn prism_axis(&self) -> usize {
        self.axis
            .as_deref()
            .and_then(crate::scene::grid::axis)
            .unwrap_or(1)
    }
}

/// The bounds (min, max) of the polygon `section` extruded over `extent`
/// along `axis`.
pub fn prism_bounds(section: &[Vec<f64>], axis: usize, extent: [f64; 2]) -> (Vec<f64>, Vec<f64>) {
    let (mut lo, mut hi) = (vec![extent[0]; 3], vec![extent[1]; 3]);
    for (k, &d) in prism_plane(axis).iter().enumerate() {
        lo[d] = section.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        hi[d] = section
            .iter()
            .map(|p| p[k])
            .fold(f64::NEG_INFINITY, f64::max);
    }
    (lo, hi)
}

/// The two axes of a prism's cross-section (its `vertices`' coordinates), in
/// increasing order: the axes other than `axis`.
pub fn prism_plane(axis: usize) -> [usize; 2] {
    match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(
    untagged,
    expecting = "a number of particles per direction, or an array with one per direction"
)]
pub enum PerDirection {
    Same(usize),
    Each(Vec<usize>),
}

impl PerDirection {
    pub fn get(&self, d: usize) -> usize {
        match self {
            PerDirection::Same(n) => *n,
            PerDirection::Each(v) => v.get(d).copied().unwrap_or(0),
        }
    }
}

fn default_ppc() -> PerDirection {
    PerDirection::Same(2)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Condition {
    /// All velocity components zero.
    Fixed,
    /// Normal velocity zero, tangential free.
    Roller,
    /// Prescribed `velocity` on the listed `components` (default all).
    Velocity,
    /// Non-reflecting: Lysmer–Kuhlemeyer dashpots (thesis 2-59…2-63), optionally
    /// with springs in parallel (`spring_distance` or `spring_stiffness`).
    Absorbing,
    /// Rigid rough wall: no penetration, Coulomb friction with
    /// `friction_coefficient` (explicit solver; fixed in implicit steps).
    Friction,
    /// The excess pore pressure of coupled materials is zero on the face's
    /// nodes (`model::drainage`); no velocity condition.
    Drained,
}

impl Condition {
    pub fn name(&self) -> &'static str {
        self.into()
    }

    /// Fixed, roller and velocity conditions prescribe nodal velocity components;
    /// absorbing and friction faces act through forces and contact.
    pub fn prescribes_velocity(&self) -> bool {
        !matches!(
            self,
            Condition::Absorbing | Condition::Friction | Condition::Drained
        )
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundaryConfig {
    /// Grid face: xmin, xmax, ymin, ymax, zmin, zmax.
    pub face: String,
    pub condition: Condition,
    pub velocity: Option<Vec<f64>>,
    /// Velocity condition: the face moves with this acceleration times the
    /// `time_history` factor, from rest at t = 0 (instead of `velocity`).
    pub acceleration: Option<Vec<f64>>,
    /// Velocity condition: the face's displacement is this vector times the
    /// `time_history` factor (instead of `velocity`).
    pub displacement: Option<Vec<f64>>,
    /// The factor of `velocity`, `acceleration`, `displacement` or
    /// `incoming_velocity` on the run's clock (`scene::curve`).
    pub time_history: Option<TimeHistory>,
    /// Absorbing: a compliant base; the incoming (upgoing) wave's particle
    /// velocity, times the `time_history` factor, enters as the traction
    /// 2 ρ c v_in beside the dashpots (Joyner & Chen 1975).
    pub incoming_velocity: Option<Vec<f64>>,
    /// Components the velocity condition acts on ("x", "y", "z"); default all.
    pub components: Option<Vec<String>>,
    /// Absorbing: springs in parallel with k_n = α_N G/R, k_s = α_T G/R, where R is
    /// this distance from the wave source to the face.
    pub spring_distance: Option<f64>,
    /// Absorbing: springs in parallel with these stiffnesses per unit area,
    /// [normal, tangential].
    pub spring_stiffness: Option<Vec<f64>>,
    /// Friction: the Coulomb coefficient μ of the rigid wall.
    pub friction_coefficient: Option<f64>,
    /// Drained: the excess pore pressure its nodes hold (default 0).
    pub pore_pressure: Option<f64>,
    /// Fixed, roller or velocity: only the face nodes in the box
    /// [region_min, region_max] (both or neither).
    pub region_min: Option<Vec<f64>>,
    pub region_max: Option<Vec<f64>>,
    /// Velocity: the condition is a rigid footing of this width (the modelled
    /// width; half the footing in a half model). The run writes footing.csv and
    /// the limit pressure to summary.json.
    pub footing_width: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum LoadKind {
    /// `force`: a total force shared equally by the selected particles.
    Point,
    /// `traction` on the `face` side of each selected particle: force per unit area
    /// of its reference face (unit thickness in 2D).
    Traction,
}

impl LoadKind {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadConfig {
    pub kind: LoadKind,
    /// Particles whose reference position lies in the box [region_min, region_max].
    pub region_min: Vec<f64>,
    pub region_max: Vec<f64>,
    /// Only particles of this body (by name); default all bodies.
    pub body: Option<String>,
    pub force: Option<Vec<f64>>,
    pub traction: Option<Vec<f64>>,
    pub face: Option<String>,
    /// Linear ramp from zero over this time (0: applied at once).
    #[serde(default)]
    pub ramp_time: f64,
    /// A pulse instead of a ramp: the load times sin²(π t / T) for t ≤ T, then zero.
    pub pulse_duration: Option<f64>,
    /// A time history instead of a ramp or pulse: the load times its factor
    /// on the run's clock (`scene::curve`).
    pub time_history: Option<TimeHistory>,
}

/// A `[[contact]]` table: the bodies it pairs and their contact law
/// (`crate::solver::explicit::contact`; docs/contact.md).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactConfig {
    /// Two body names; none: every pair of bodies of the scene.
    pub bodies: Option<Vec<String>>,
    /// Coulomb coefficient μ ≥ 0 (default 0: frictionless).
    #[serde(default)]
    pub friction_coefficient: f64,
    /// Shear strength of the interface per unit area, added to μ times the normal
    /// traction (default 0).
    #[serde(default)]
    pub adhesion: f64,
    /// λ of the gap criterion D ≤ λ h (default 0.5).
    #[serde(default = "default_gap_factor")]
    pub gap_factor: f64,
    /// How the common normal of a contact node is found (default `max_gradient`).
    #[serde(default)]
    pub normal: ContactNormal,
    /// Put deformable particles that enter a rigid body back on its surface
    /// (`crate::physics::rigid::surface`; default true).
    #[serde(default = "yes")]
    pub rigid_projection: bool,
    /// Implicit solver: the penalty ε_n = α M A_p / h of a particle against a
    /// rigid body is this α times the particle's P-wave modulus M, face area A_p
    /// and 1/h (`crate::solver::implicit::terms::contact::rigid`; default 100).
    #[serde(default = "default_penalty_factor")]
    pub penalty_factor: f64,
}

fn default_penalty_factor() -> f64 {
    100.0
}

fn yes() -> bool {
    true
}

/// The common normal of two fields at a contact node, from their volume gradients
/// g = Σ_p V_p ∇S_Ip (`crate::solver::explicit::contact`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum ContactNormal {
    /// The normal of the field with the larger |g| (Nairn's "maximum volume
    /// gradient"): the flat side of a contact decides at the other body's corners.
    #[default]
    MaxGradient,
    /// The average of the two unit normals, (ĝ_r − ĝ_s)/|ĝ_r − ĝ_s| (MPM3D's
    /// "average method").
    Average,
}

fn default_gap_factor() -> f64 {
    0.5
}

/// The `[geostatic]` table: σ_v = −ρ g d, σ_h = K0 σ_v, with d the depth below
/// the top surface of the particle's body at the particle's horizontal position.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeostaticConfig {
    /// Lateral earth pressure coefficient; default 1 − sin φ of each body's
    /// material (Jáky).
    pub k0: Option<f64>,
}

/// The `[water]` table: a prescribed pore pressure below a phreatic surface
/// (docs/pore_water.md).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterConfig {
    /// γ_w = ρ_w g in the scene's units (required: scenes use kPa or Pa).
    pub unit_weight: Option<f64>,
    /// A plane water table at this coordinate along the gravity axis.
    pub level: Option<f64>,
    /// The water table as points [horizontal, elevation] of a polyline (2D and
    /// axisymmetric), linear between them and level beyond its ends.
    pub phreatic_line: Option<Vec<Vec<f64>>>,
    /// How the water flows below the phreatic surface (default hydrostatic).
    #[serde(default)]
    pub seepage: Seepage,
}

/// The flow below the phreatic surface, which sets the pore pressure there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Seepage {
    /// No flow: p = γ_w d_v, d_v the vertical depth below the surface.
    #[default]
    Hydrostatic,
    /// Flow parallel to the phreatic surface inclined at β: p = γ_w d_v cos²β.
    Parallel,
}

/// The `[strength_reduction]` table.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrengthReductionConfig {
    /// Initial bracket [F_low, F_high] of the search; widened if F_low fails or
    /// F_high holds.
    pub search: Vec<f64>,
    /// Width of the final bracket (default 0.01).
    pub tolerance: Option<f64>,
    /// Monitored point: the particle nearest to it (reference position).
    pub monitor: Option<Vec<f64>>,
    /// A trial also fails when the monitored particle moves further than this.
    pub max_displacement: Option<f64>,
    /// Most trials the search may run (default 20).
    pub max_trials: Option<usize>,
    /// Start each trial from the last stable trial's end state, its strengths
    /// reduced further (default true; `false`: every trial from the scene's
    /// initial state). Only a scene of one implicit quasi-static stage
    /// continues (`analyses::strength_reduction::continues`).
    pub continuation: Option<bool>,
}

impl StrengthReductionConfig {
    pub fn tolerance(&self) -> f64 {
        self.tolerance.unwrap_or(0.01)
    }
    pub fn max_trials(&self) -> usize {
        self.max_trials.unwrap_or(20)
    }
    pub fn continuation(&self) -> bool {
        self.continuation.unwrap_or(true)
    }
}

impl SceneConfig {
    /// Every time history of the scene with its key path.
    pub fn time_histories(&self) -> Vec<(String, &TimeHistory)> {
        let loads = (self.loads.iter().enumerate()).filter_map(|(i, l)| {
            Some((format!("load.{i}.time_history"), l.time_history.as_ref()?))
        });
        let faces = (self.boundaries.iter().enumerate()).filter_map(|(i, b)| {
            Some((
                format!("boundary.{i}.time_history"),
                b.time_history.as_ref()?,
            ))
        });
        let gravity = (self.gravity_history.as_ref()).map(|h| ("gravity_history".to_string(), h));
        gravity.into_iter().chain(loads).chain(faces).collect()
    }

    pub fn time_histories_mut(&mut self) -> Vec<(String, &mut TimeHistory)> {
        let loads = (self.loads.iter_mut().enumerate()).filter_map(|(i, l)| {
            Some((format!("load.{i}.time_history"), l.time_history.as_mut()?))
        });
        let faces = (self.boundaries.iter_mut().enumerate()).filter_map(|(i, b)| {
            Some((
                format!("boundary.{i}.time_history"),
                b.time_history.as_mut()?,
            ))
        });
        let gravity = (self.gravity_history.as_mut()).map(|h| ("gravity_history".to_string(), h));
        gravity.into_iter().chain(loads).chain(faces).collect()
    }

    /// The stages of the run: the `[solver]` table alone, or the `[[stage]]` tables.
    pub fn stages(&self) -> Vec<&SolverConfig> {
        match &self.solver {
            Some(s) => vec![s],
            None => self.stages.iter().collect(),
        }
    }

    /// Total simulated time: the sum of the stage durations.
    pub fn total_time(&self) -> f64 {
        self.stages().iter().map(|s| s.end_time).sum()
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Number of ParaView frames after the initial one (0: none at all).
    #[serde(default = "default_frames")]
    pub frames: usize,
    /// Time between rows of history.csv (0: every step).
    #[serde(default)]
    pub history_interval: f64,
    /// Times at which particles_NNNN.csv is written (none: no such files).
    #[serde(default)]
    pub particle_times: Option<Vec<f64>>,
    /// Time between particles_NNNN.csv files, from t = 0 (none: no such files).
    #[serde(default)]
    pub particle_interval: Option<f64>,
    /// Simulation time between checkpoints (none: no checkpoints by time).
    #[serde(default)]
    pub checkpoint_interval: Option<f64>,
    /// Wall-clock seconds between checkpoints (none: no checkpoints by the clock).
    #[serde(default)]
    pub checkpoint_wall_seconds: Option<f64>,
    /// Matrix Market files of the implicit solver's linear systems.
    #[serde(default)]
    pub linear_systems: LinearSystems,
}

/// Which Newton iterations write their linear system K δu = −r to
/// `linear_systems/` (the direct linear solver only).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum LinearSystems {
    #[default]
    None,
    /// The first Newton iteration of every step (and of every cut-back attempt).
    First,
    /// Every Newton iteration.
    All,
}

fn default_frames() -> usize {
    10
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            frames: default_frames(),
            history_interval: 0.0,
            particle_times: None,
            particle_interval: None,
            checkpoint_interval: None,
            checkpoint_wall_seconds: None,
            linear_systems: LinearSystems::None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum ReferenceKind {
    /// Column under self-weight: σ along gravity against −ρ g (l0 − Y).
    Column,
    /// Fixed-free bar in its first axial mode: period against 4 L / c.
    VibratingBar,
    /// Cantilever with an end load: tip deflection against the elastica.
    Cantilever,
    /// Any scene: the displacement field against a finer reference run's.
    DisplacementField,
}

impl ReferenceKind {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, IntoStaticStr, EnumIter)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Beam {
    /// The elastica with extension and shear (the beam model of a 2D continuum).
    Reissner,
    /// The classical inextensible elastica.
    Elastica,
}

impl Beam {
    pub fn name(&self) -> &'static str {
        self.into()
    }
}

/// The `[reference]` table: which analytical solution the scene has
/// (`crate::analyses::reference`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceConfig {
    pub kind: ReferenceKind,
    /// Cantilever only: the beam model (default `reissner`).
    pub beam: Option<Beam>,
    /// Displacement field only: the reference run's `particles_final.csv`,
    /// relative to the scene file.
    pub file: Option<String>,
}

/// The `[bench]` table (or the same table in a separate file given to
/// `mpm bench --config`): which solver configurations and sweeps to run.
/// docs/bench.md documents the keys.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchConfig {
    /// Configurations to run, by name: built-in or `[[bench.configuration]]`.
    pub configurations: Option<Vec<String>>,
    /// User-defined configurations.
    #[serde(default, rename = "configuration")]
    pub custom: Vec<BenchConfiguration>,
    /// Time-step sweep (Newmark; quasi-static runs without `load_steps`).
    pub dt: Option<Vec<f64>>,
    /// Load-step sweep (quasi-static).
    pub load_steps: Option<Vec<usize>>,
    /// Grid sweep: cell counts per direction …
    pub cells: Option<Vec<Vec<usize>>>,
    /// … or refinement factors of the scene's cells.
    pub refine: Option<Vec<usize>>,
    /// Wall-time limit of one run in seconds.
    pub timeout: Option<f64>,
    /// Overrides applied to every run (`--set` syntax).
    #[serde(default)]
    pub set: Vec<String>,
}

/// A named solver configuration: scene overrides in `--set KEY=VALUE` syntax, and
/// keys to remove.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BenchConfiguration {
    pub name: String,
    #[serde(default)]
    pub set: Vec<String>,
    #[serde(default)]
    pub unset: Vec<String>,
}
