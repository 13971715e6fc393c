//! What each `[[body]]` is (`BodyKindName`): its `kind`, or the old form of a
//! rigid body (a material with `model = "rigid"`), its motion, the key that
//! makes it what it is (for messages), and the materials its particles carry
//! (a rigid body takes only the density of its material). The model builds its
//! bodies' kinds from these (`model::body`); the validation checks the keys
//! (`validate::grid_bodies`).

use super::BondModel;
use super::{BodyKindName, MaterialConfig, Plane, SceneConfig};
use crate::material::bond::correspondence::{Correspondence, ZERO_ENERGY_CONTROL};
use crate::material::bond::short_range::{self, ShortRange};
use crate::material::bond::{beam::Beam, pmb::Pmb, BondLaw, Space};
use crate::material::parameters::FromParameters;
use crate::material::rigid::{Motion, Rigid};
use crate::material::Material;

impl SceneConfig {
    /// The kind of body i: its `kind`, else rigid when its material is an
    /// old-form rigid material (`model = "rigid"`), else continuum.
    pub fn body_kind(&self, i: usize) -> BodyKindName {
        let old_form = self.old_form_rigid(i).is_some();
        match self.bodies[i].kind {
            Some(kind) => kind,
            None if old_form => BodyKindName::Rigid,
            None => BodyKindName::Continuum,
        }
    }

    /// The key that makes body i what it is, for messages about its kind:
    /// `body.i.kind`, or `body.i.material` for the old form of a rigid body.
    pub fn body_kind_key(&self, i: usize) -> String {
        match self.bodies[i].kind {
            None if self.old_form_rigid(i).is_some() => format!("body.{i}.material"),
            _ => format!("body.{i}.kind"),
        }
    }

    /// The motion of rigid body i: its `motion`, else its old-form rigid
    /// material's, else prescribed.
    pub fn rigid_motion(&self, i: usize) -> Motion {
        let old_form = self
            .old_form_rigid(i)
            .and_then(|m| Motion::of(&m.parameters));
        (self.bodies[i].motion).or(old_form).unwrap_or_default()
    }

    /// Body i's material when it is an old-form rigid material
    /// (`model = "rigid"`, `material::rigid`): the one place the scene reads
    /// rigidity from a material.
    pub fn old_form_rigid(&self, i: usize) -> Option<&MaterialConfig> {
        let name = &self.bodies[i].material;
        (self.materials.iter()).find(|m| &m.name == name && m.model == Rigid::NAME)
    }

    /// The materials the particles carry, one per table, from the tables' own
    /// (`built`): the table of a rigid or a peridynamic body gives the
    /// zero-stress `Rigid` with its density instead, whatever its model (only
    /// its density acts on a rigid body; a peridynamic body's E and ν act
    /// through its bonds, `peridynamic`, not through the grid; the validation
    /// refuses a table shared with a continuum body).
    pub fn particle_materials(&self, mut built: Vec<Box<dyn Material>>) -> Vec<Box<dyn Material>> {
        let off_grid = |i: &usize| self.body_kind(*i) != BodyKindName::Continuum;
        for i in (0..self.bodies.len()).filter(off_grid) {
            let table = (self.materials.iter()).position(|m| m.name == self.bodies[i].material);
            if let Some(k) = table {
                built[k] = Box::new(Rigid::new(self.materials[k].density));
            }
        }
        built
    }
}

impl SceneConfig {
    /// Body i's particle spacing Δx: the largest over the directions of the
    /// cell size over `particles_per_cell`.
    pub fn particle_spacing(&self, i: usize) -> f64 {
        let dim = self.dimension.spatial();
        let ppc = &self.bodies[i].particles_per_cell;
        (0..dim)
            .map(|d| {
                (self.grid.max[d] - self.grid.min[d])
                    / self.grid.cells[d] as f64
                    / ppc.get(d) as f64
            })
            .fold(0.0, f64::max)
    }

    /// The PMB space of peridynamic body i: 3D, or its `plane` in 2D.
    pub fn peridynamic_space(&self, i: usize) -> Space {
        match (
            self.dimension.spatial(),
            self.bodies[i].plane.unwrap_or_default(),
        ) {
            (3, _) => Space::ThreeD,
            (_, Plane::Strain) => Space::PlaneStrain,
            (_, Plane::Stress) => Space::PlaneStress,
        }
    }

    /// The horizon δ of peridynamic body i: `horizon`, else `horizon_factor`
    /// (default 3) × its particle spacing.
    pub fn horizon(&self, i: usize) -> f64 {
        let b = &self.bodies[i];
        b.horizon
            .unwrap_or_else(|| b.horizon_factor.unwrap_or(3.0) * self.particle_spacing(i))
    }

    /// The Young's modulus of body i's material (`youngs_modulus`), if it has one.
    pub fn youngs_modulus(&self, i: usize) -> Option<f64> {
        self.material_number(i, "youngs_modulus")
    }

    /// The number `key` of body i's material table, if it has one.
    fn material_number(&self, i: usize, key: &str) -> Option<f64> {
        let m = self
            .materials
            .iter()
            .find(|m| m.name == self.bodies[i].material)?;
        m.parameters
            .get(key)
            .and_then(|v| v.as_float().or(v.as_integer().map(|n| n as f64)))
    }

    /// The bond law of peridynamic body i of a validated scene: its
    /// `bond_model` with its material's E (and ν, beam; the P-wave modulus,
    /// correspondence), its horizon and its critical stretch (`fracture_energy`
    /// or `critical_stretch`).
    pub fn peridynamic(&self, i: usize) -> BondLaw {
        let (b, space) = (&self.bodies[i], self.peridynamic_space(i));
        let (e, delta) = (|| self.youngs_modulus(i).unwrap(), self.horizon(i));
        match b.bond_model.unwrap_or_default() {
            BondModel::Pmb => {
                let e = e();
                let pmb = Pmb::new(space, e, delta);
                BondLaw::Pmb(match (b.fracture_energy, b.critical_stretch) {
                    (Some(g0), _) => pmb.with_fracture_energy(space, g0),
                    (_, Some(s0)) => pmb.with_critical_stretch(s0),
                    _ => pmb,
                })
            }
            BondModel::Beam => {
                let beam = Beam::new(space, e(), self.poisson_ratio(i).unwrap(), delta);
                BondLaw::Beam(match (b.fracture_energy, b.critical_stretch) {
                    (Some(g0), _) => beam.with_fracture_energy(space, g0),
                    (_, Some(s0)) => beam.with_critical_stretch(s0),
                    _ => beam,
                })
            }
            BondModel::Correspondence => {
                let g = b.zero_energy_control.unwrap_or(ZERO_ENERGY_CONTROL);
                let c = Correspondence::new(space, self.p_wave_modulus(i), delta, g)
                    .with_influence(b.influence.unwrap_or_default());
                BondLaw::Correspondence(match (b.fracture_energy, b.critical_stretch) {
                    (Some(g0), _) => c.with_fracture_energy(space, g0),
                    (_, Some(s0)) => c.with_critical_stretch(s0),
                    _ => c,
                })
            }
        }
    }

    /// The short-range repulsion of peridynamic body i of bond law `law`
    /// (`peridynamic(i)`): c_S = `short_range_force` (default
    /// `short_range::FACTOR`) × the law's micromodulus; None at 0.
    pub fn short_range(&self, i: usize, law: &BondLaw) -> Option<ShortRange> {
        let factor = self.bodies[i]
            .short_range_force
            .unwrap_or(short_range::FACTOR);
        (factor > 0.0).then(|| ShortRange::new(factor, law.micromodulus(), law.horizon()))
    }

    /// The P-wave modulus of body i's material as built (`Material::p_wave_modulus`).
    pub fn p_wave_modulus(&self, i: usize) -> f64 {
        let k = (self.materials.iter())
            .position(|m| m.name == self.bodies[i].material)
            .expect("validated");
        self.materials[k]
            .build(k)
            .expect("validated")
            .p_wave_modulus()
    }

    /// The Poisson ratio of body i's material (`poisson_ratio`), if it has one.
    pub fn poisson_ratio(&self, i: usize) -> Option<f64> {
        self.material_number(i, "poisson_ratio")
    }
}
