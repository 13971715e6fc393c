//! The state every solver works on: grid, particles, materials, conditions,
//! loads and the bodies (their geometry and kind, `body.rs`), built once from a
//! validated scene (`build.rs`) and then independent of it.

pub(crate) mod axisymmetry;
pub(crate) mod body;
mod build;
pub(crate) mod conditions;
pub mod curve;
pub mod drainage;
pub mod geometry;
pub mod grid;
pub(crate) mod import;
pub(crate) mod loads;
pub(crate) mod memory;
pub mod mesh;
pub mod particle_set;
pub mod particles;
pub mod peridynamics;
pub mod staging;
pub(crate) mod tensors;
pub mod terrain;
pub mod triangles;
pub mod water;

use crate::model::peridynamics::Peridynamics;
pub use loads::{load_factor, LoadTime};

use crate::dim::Vector;
use crate::material::Material;
use crate::model::body::{Body, BodyKind};
use crate::model::conditions::{Absorbing, FaceCondition, FaceMotion, Footing, FrictionFace};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::model::water::Water;
use crate::scene::contact::ContactPlan;
use std::borrow::Cow;

/// A body's particles as built (`Model::body_extents`).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyExtent {
    pub particles: usize,
    /// Σ V_p: area × unit thickness in 2D, per radian in an axisymmetric model.
    pub volume: f64,
    /// The box of the particles' domains (x_p ± half-lengths).
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

/// Everything a solver needs, in dimension D.
#[derive(Debug)]
pub struct Model<const D: usize> {
    pub grid: Grid<D>,
    pub particles: Particles<D>,
    /// The materials in use (strengths reduced by the current factor).
    pub materials: Vec<Box<dyn Material>>,
    /// The materials as built from the scene (factor 1), which `reduce_strength`
    /// starts from.
    pub base_materials: Vec<Box<dyn Material>>,
    /// Each body's geometry and kind (by `Particles::body`).
    pub bodies: Vec<Body>,
    pub faces: Vec<FaceCondition<D>>,
    /// The velocity conditions that follow a time history (`Model::faces_during`).
    pub face_motions: Vec<FaceMotion<D>>,
    /// Rigid rough faces (Coulomb friction; no slip in implicit steps).
    pub friction: Vec<FrictionFace<D>>,
    /// The friction faces that move along themselves (`Model::walls_during`;
    /// `FaceMotion::face` indexes `friction`).
    pub wall_motions: Vec<FaceMotion<D>>,
    /// The velocity condition with a `footing_width`, if any.
    pub footing: Option<Footing<D>>,
    /// Non-reflecting faces (Lysmer–Kuhlemeyer dashpots, optional springs).
    pub absorbing: Absorbing<D>,
    /// Contact between bodies: velocity fields and their laws (`[[contact]]`).
    pub contact: Option<ContactPlan>,
    pub gravity: Vector<D>,
    /// `gravity_history`: gravity times this factor on the run's clock, in place
    /// of the stages' ramps (None: the ramps).
    pub gravity_history: Option<LoadTime>,
    /// The distinct time histories of the loads (the force is stored on the
    /// particles grouped by history, see `load_scales`).
    pub load_ramps: Vec<LoadTime>,
    /// For each particle, the index into `load_ramps` of its load (u32::MAX: none).
    pub load_ramp_of: Vec<u32>,
    /// `dimension = "axisymmetric"` (D = 2, x = r, y = z): masses, volumes and
    /// loads are per radian, and the stencils carry the hoop terms
    /// (`physics::shape::hoop`).
    pub axisymmetric: bool,
    /// Whether some material erodes its failed points (`Material::erodes`).
    pub erosion: bool,
    /// Whether particles that leave the grid are removed from the transfers
    /// (`[grid] particles_outside = "remove"`) instead of stopping the run.
    pub remove_outside: bool,
    /// `[grid] domain_stress = "linear"`: a stress linear within each particle
    /// domain in the implicit internal force (`solver::implicit::stress_gradient`).
    pub linear_domain_stress: bool,
    /// The peridynamic bodies' bonds (`model::peridynamics`); None in a
    /// scene without one, which then allocates and computes nothing of them.
    pub peridynamics: Option<Peridynamics<D>>,
    /// Staged construction (`model::staging`): the bodies not yet active and
    /// the built index of each particle; None in a scene that stages nothing.
    pub staging: Option<staging::Staging<D>>,
    /// The prescribed pore-water field (`[water]`, `model::water`); None
    /// without one, and then no particle carries a pore pressure.
    pub water: Option<Water>,
    /// The drained faces of coupled pore flow (`model::drainage`); None
    /// without a coupled material, and then no pore water flows.
    pub drainage: Option<drainage::Drainage<D>>,
}

impl<const D: usize> Model<D> {
    /// Whether the scene can remove particles from the transfers: by erosion or
    /// when they leave the grid.
    pub fn removes_particles(&self) -> bool {
        self.erosion || self.remove_outside
    }

    /// Whether particle q is removed: eroded (`Material::eroded`) or, with
    /// `remove_outside`, outside the grid. It is left out of the transfers
    /// (`physics::transfer::stencils`) and of the critical time step.
    pub fn removed(&self, q: usize) -> bool {
        let p = &self.particles;
        let mat = &self.materials[p.material[q] as usize];
        (self.erosion && mat.eroded(p.history.get(q)))
            || (self.remove_outside && !self.grid.contains(&p.x[q]))
    }

    /// Mass and energy (kinetic + stored) of the removed particles, which keep the
    /// velocity and internal energy they had when removed (history.csv).
    pub fn removed_mass_and_energy(&self) -> (f64, f64) {
        let p = &self.particles;
        let eroded: Vec<usize> = (0..p.len()).filter(|&q| self.removed(q)).collect();
        let mass = eroded.iter().fold(0.0, |sum, &q| sum + p.mass[q]);
        let energy = eroded.iter().fold(0.0, |sum, &q| {
            let mat = &self.materials[p.material[q] as usize];
            let stored = mat.strain_energy_density(&p.f.get(q), &p.stress.get(q), p.history.get(q));
            sum + 0.5 * p.mass[q] * p.v[q].norm_squared() + p.volume[q] * stored
        });
        (mass, energy)
    }

    /// The face conditions of the step t → t + dt: `faces`, the values of those
    /// that follow a time history set to their velocity over the step
    /// (`FaceMotion::step_velocity`). Borrowed when no face has a history.
    pub fn faces_during(&self, t: f64, dt: f64) -> Cow<'_, [FaceCondition<D>]> {
        if self.face_motions.is_empty() {
            return Cow::Borrowed(&self.faces);
        }
        let mut faces = self.faces.clone();
        for motion in &self.face_motions {
            let v = motion.step_velocity(t, dt);
            let c = &mut faces[motion.face].constraint;
            (0..D)
                .filter(|&d| c.fixed[d])
                .for_each(|d| c.value[d] = v[d]);
        }
        Cow::Owned(faces)
    }

    /// The friction faces of the step t → t + dt: `friction`, each moving
    /// wall's velocity set to its mean over the step (`FaceMotion::step_velocity`).
    /// Borrowed when no wall moves.
    pub fn walls_during(&self, t: f64, dt: f64) -> Cow<'_, [FrictionFace<D>]> {
        if self.wall_motions.is_empty() {
            return Cow::Borrowed(&self.friction);
        }
        let mut walls = self.friction.clone();
        for motion in &self.wall_motions {
            walls[motion.face].velocity = motion.step_velocity(t, dt);
        }
        Cow::Owned(walls)
    }

    /// The factor of gravity at time t: its history's, or else the stage's `ramp`.
    pub fn gravity_factor(&self, t: f64, ramp: &LoadTime) -> f64 {
        self.gravity_history.as_ref().unwrap_or(ramp).factor(t)
    }

    /// Load factor of each load time history at time t.
    pub fn load_scales(&self, t: f64) -> Vec<f64> {
        self.load_ramps.iter().map(|r| r.factor(t)).collect()
    }

    /// Set every material with a frictional strength to its base material with
    /// c/F, tan φ/F, tan ψ/F (strength reduction; F = 1: as given, up to the
    /// round-off of atan(tan φ)). Not cumulative: each call starts from the base
    /// materials. The particles keep their stresses; the next stress update
    /// returns them to the new surface.
    pub fn reduce_strength(&mut self, factor: f64) {
        self.materials = (self.base_materials.iter())
            .map(|m| m.with_reduced_strength(factor).unwrap_or_else(|| m.clone()))
            .collect();
    }

    /// Set every particle's history from its initial stress
    /// (`Material::initial_history`, e.g. Modified Cam-Clay's pre-consolidation
    /// pressure from OCR) of the material as given (before strength reduction):
    /// once, after the geostatic stresses, in a run that does not restart.
    pub fn initialise_history(&mut self) {
        let p = &mut self.particles;
        let stress = &p.stress;
        let slots = p.history.own_slots_mut();
        for (q, slot) in slots.into_iter().enumerate() {
            let m = &self.base_materials[p.material[q] as usize];
            m.initial_history(&stress.get(q), slot);
        }
    }

    /// Equivalent plastic strain of every particle (0 where the material has
    /// none), or `None` when no material of the scene has one.
    pub fn plastic_strain(&self) -> Option<Vec<f64>> {
        self.material_field(|m, h| m.equivalent_plastic_strain(h))
    }

    /// Each particle's excess pore pressure (`material::undrained`, 0 for a
    /// drained material), `None` when no material is undrained.
    pub fn excess_pore_pressure(&self) -> Option<Vec<f64>> {
        self.material_field(|m, h| m.excess_pore_pressure(h))
    }

    /// A value each particle's material reads off its history, 0 where the
    /// material has none; `None` when no particle's has one.
    fn material_field(
        &self,
        value: impl Fn(&dyn Material, &[f64]) -> Option<f64>,
    ) -> Option<Vec<f64>> {
        let p = &self.particles;
        let values: Vec<Option<f64>> = (0..p.len())
            .map(|q| {
                value(
                    self.materials[p.material[q] as usize].as_ref(),
                    p.history.get(q),
                )
            })
            .collect();
        values
            .iter()
            .any(Option::is_some)
            .then(|| values.iter().map(|v| v.unwrap_or(0.0)).collect())
    }

    /// The per-particle fields the outputs add where the run has them:
    /// `eps_p` (`plastic_strain`), with a peridynamic body `damage`
    /// (`Peridynamics::damage`, 0 off the peridynamic bodies) and with
    /// `[water]` `p_water`, the pore pressure of the last step (at its start),
    /// and with an undrained material `p_excess` (the stress columns are then
    /// σ′ − p_excess I: see docs/pore_water.md).
    pub fn point_fields(&self) -> Vec<(&'static str, Vec<f64>)> {
        let mut fields: Vec<(&'static str, Vec<f64>)> = Vec::new();
        if let Some(e) = self.plastic_strain() {
            fields.push(("eps_p", e));
        }
        if let Some(pd) = &self.peridynamics {
            fields.push(("damage", pd.damage(self.particles.len())));
        }
        if self.water.is_some() {
            fields.push(("p_water", self.particles.pore_pressure.clone()));
        }
        if let Some(p) = self.excess_pore_pressure() {
            fields.push(("p_excess", p));
        }
        fields
    }

    /// The particles as the outputs write them (frames, particles_final.csv,
    /// particle dumps): a correspondence body's particles with the stress and F
    /// of their own state (`peridynamics::state`; on the grid they carry a
    /// zero-stress material); borrowed, not copied, when no body has that state.
    pub fn output_particles(&self) -> Cow<'_, Particles<D>> {
        let own = |pd: &&Peridynamics<D>| pd.bodies.iter().any(|b| b.stress.is_some());
        let Some(pd) = self.peridynamics.as_ref().filter(own) else {
            return Cow::Borrowed(&self.particles);
        };
        let mut p = self.particles.clone();
        for b in &pd.bodies {
            let Some(state) = &b.stress else { continue };
            for (i, &q) in b.particles.iter().enumerate() {
                p.stress.set(q, &state.stress[i]);
                p.f.set(q, &state.f[i]);
            }
        }
        Cow::Owned(p)
    }

    /// Set the particles' pore pressures at their current positions (the run
    /// calls this before every step); nothing without `[water]`.
    pub fn update_pore_pressure(&mut self) {
        if let Some(w) = &self.water {
            w.assign(&self.bodies, &mut self.particles);
        }
    }

    /// Index of the particle whose reference position is nearest to `x`.
    pub fn nearest_particle(&self, x: &[f64]) -> Option<usize> {
        let p = &self.particles;
        let d2 = |q: usize| (0..D).map(|d| (p.x0[q][d] - x[d]).powi(2)).sum::<f64>();
        (0..p.len()).min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
    }

    /// Each body's particles as built: their count, total volume (per radian
    /// in an axisymmetric model) and the box of their domains (`mpm check`),
    /// also of a body not active yet (`model::staging`).
    pub fn body_extents(&self) -> Vec<BodyExtent> {
        let dormant = self.staging.iter().flat_map(|s| s.dormant_particles());
        let mut extents: Vec<BodyExtent> = (0..self.bodies.len())
            .map(|_| BodyExtent {
                particles: 0,
                volume: 0.0,
                min: vec![f64::INFINITY; D],
                max: vec![f64::NEG_INFINITY; D],
            })
            .collect();
        for p in std::iter::once(&self.particles).chain(dormant) {
            for q in 0..p.len() {
                let e = &mut extents[p.body[q] as usize];
                e.particles += 1;
                e.volume += p.volume[q];
                for d in 0..D {
                    let (x, h) = (p.x[q][d], p.half_length0[q][d]);
                    e.min[d] = e.min[d].min(x - h);
                    e.max[d] = e.max[d].max(x + h);
                }
            }
        }
        extents
    }

    /// Start staging (`model::staging`): the particles of the `inactive`
    /// bodies held aside until a stage activates them.
    pub(crate) fn start_staging(&mut self, inactive: &[usize]) {
        let staging = self.with_arrays(|a| staging::Staging::start(a, inactive));
        self.staging = Some(staging);
    }

    /// Apply a stage's changes at its start (`model::staging`; nothing
    /// without staging).
    pub fn change(&mut self, changes: &staging::StageChanges) {
        if let Some(mut s) = self.staging.take() {
            self.with_arrays(|a| s.change(a, changes));
            self.staging = Some(s);
        }
    }

    /// A restart's particles of a staged scene (`Staging::restore`).
    pub fn restore_staging(&mut self, activated: &[usize], built: &[u32]) -> Result<(), String> {
        let Some(mut s) = self.staging.take() else {
            return Ok(());
        };
        let restored = self.with_arrays(|a| s.restore(a, activated, built));
        self.staging = Some(s);
        restored
    }

    /// `f` on the per-particle arrays staging changes (`staging::Arrays`).
    fn with_arrays<R>(&mut self, f: impl FnOnce(&mut staging::Arrays<D>) -> R) -> R {
        let continuum: Vec<bool> = (self.bodies.iter())
            .map(|b| b.kind == BodyKind::Continuum)
            .collect();
        f(&mut staging::Arrays {
            particles: &mut self.particles,
            load_ramp_of: &mut self.load_ramp_of,
            continuum: &continuum,
        })
    }

    /// The particle now in the model that was built as `built` (None: it has
    /// left, `model::staging`); the identity without staging.
    pub fn particle_built_as(&self, built: usize) -> Option<usize> {
        match &self.staging {
            None => Some(built),
            Some(s) => s.built.iter().position(|&b| b as usize == built),
        }
    }

    /// The index as built of particle q (q itself without staging).
    pub fn built_index(&self, q: usize) -> usize {
        self.staging.as_ref().map_or(q, |s| s.built[q] as usize)
    }

    /// The kind of particle q's body.
    pub fn kind_of(&self, q: usize) -> BodyKind {
        self.bodies[self.particles.body[q] as usize].kind
    }

    /// Number of bodies (for per-body outputs): the scene's, also those not
    /// active yet (`model::staging`).
    pub fn n_bodies(&self) -> usize {
        let of_particles = self.particles.body.iter().map(|&b| b as usize + 1).max();
        of_particles.unwrap_or(0).max(self.bodies.len())
    }
}
