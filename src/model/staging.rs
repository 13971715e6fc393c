//! Staged construction: bodies that enter the model at a stage's start (a fill
//! placed in layers, a wall installed), bodies and regions that leave it
//! (excavation), and a stage's displacement reset (`[[stage]] activate`,
//! `deactivate`, `excavate`, `reset_displacement`; docs/staging.md).
//!
//! A particle that leaves is taken out of `Model::particles` (and of the
//! model's per-particle arrays), so it keeps nothing and costs nothing; a
//! body not yet active is held here as built, outside the model. Each
//! particle keeps its index among all the particles as built (`built`), by
//! which a checkpoint names the particles present and a restart rebuilds
//! them (`Model::restore_staging`). A scene that stages nothing has no
//! `Staging` (`Model::staging` is None).

use crate::model::body::BodyKind;
use crate::model::geometry::Geometry;
use crate::model::particles::Particles;
use crate::model::Model;
use crate::scene::staging::{RegionConfig, RegionShape};
use crate::scene::SceneConfig;

/// The particles outside the model and the built index of those inside.
#[derive(Clone, Debug)]
pub struct Staging<const D: usize> {
    /// For each particle of `Model::particles`, its index among all the
    /// particles as built (in the order of the scene's bodies).
    pub built: Vec<u32>,
    /// The bodies not yet active, as built.
    dormant: Vec<Dormant<D>>,
}

impl<const D: usize> Staging<D> {
    /// The particles of the bodies not active yet, as built.
    pub fn dormant_particles(&self) -> impl Iterator<Item = &Particles<D>> {
        self.dormant.iter().map(|d| &d.particles)
    }
}

/// A body held outside the model until a stage activates it.
#[derive(Clone, Debug)]
struct Dormant<const D: usize> {
    body: usize,
    particles: Particles<D>,
    built: Vec<u32>,
    load_ramp_of: Vec<u32>,
}

/// What a stage changes at its start, in this order: bodies deactivated,
/// regions excavated, bodies activated, displacements reset.
#[derive(Clone, Debug, Default)]
pub struct StageChanges {
    pub deactivate: Vec<usize>,
    pub excavate: Vec<Geometry>,
    pub activate: Vec<usize>,
    pub reset_displacement: bool,
}

impl StageChanges {
    /// The changes of stage k of a validated scene.
    pub fn of(c: &SceneConfig, k: usize) -> StageChanges {
        let st = &c.stages[k];
        let bodies = |names: &Option<Vec<String>>| -> Vec<usize> {
            (names.iter().flatten())
                .flat_map(|name| c.bodies_named(name))
                .collect()
        };
        StageChanges {
            deactivate: bodies(&st.deactivate),
            excavate: st.excavate.iter().flatten().map(region).collect(),
            activate: bodies(&st.activate),
            reset_displacement: st.reset_displacement == Some(true),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.deactivate.is_empty()
            && self.excavate.is_empty()
            && self.activate.is_empty()
            && !self.reset_displacement
    }
}

impl<const D: usize> Model<D> {
    /// Start staging: every particle numbered as built, and the particles of
    /// the `inactive` bodies taken out and held until activated.
    pub(crate) fn start_staging(&mut self, inactive: &[usize]) {
        let n = self.particles.len();
        self.staging = Some(Staging {
            built: (0..n as u32).collect(),
            dormant: Vec::new(),
        });
        for &body in inactive {
            let rows = self.rows_of_body(body);
            let dormant = Dormant {
                body,
                particles: self.particles.select(&rows),
                built: rows.iter().map(|&q| q as u32).collect(),
                load_ramp_of: pick(&self.load_ramp_of, &rows),
            };
            self.staging.as_mut().expect("set above").dormant.push(dormant);
            self.retain(|m, q| m.particles.body[q] as usize != body);
        }
    }

    /// Apply a stage's changes at its start (`StageChanges`, in its order).
    pub fn change(&mut self, changes: &StageChanges) {
        for &body in &changes.deactivate {
            self.retain(|m, q| m.particles.body[q] as usize != body);
        }
        for region in &changes.excavate {
            self.retain(|m, q| !m.excavated_by(region, q));
        }
        for &body in &changes.activate {
            self.activate(body);
        }
        if changes.reset_displacement {
            self.reset_displacement();
        }
    }

    /// Whether excavating `region` takes particle q: a continuum particle
    /// whose current position lies inside.
    fn excavated_by(&self, region: &Geometry, q: usize) -> bool {
        self.kind_of(q) == BodyKind::Continuum && region.contains(self.particles.x[q].as_slice())
    }

    /// The particles of dormant `body` added after those in the model, at
    /// rest as built (unstressed, undeformed).
    fn activate(&mut self, body: usize) {
        let staging = self.staging.as_mut().expect("a staged scene");
        let Some(k) = staging.dormant.iter().position(|d| d.body == body) else {
            return;
        };
        let d = staging.dormant.remove(k);
        let n = self.particles.len();
        self.particles.append(&d.particles);
        staging.built.extend_from_slice(&d.built);
        if !(self.load_ramp_of.is_empty() && d.load_ramp_of.is_empty()) {
            self.load_ramp_of.resize(n, u32::MAX);
            match d.load_ramp_of.is_empty() {
                true => self.load_ramp_of.resize(n + d.built.len(), u32::MAX),
                false => self.load_ramp_of.extend_from_slice(&d.load_ramp_of),
            }
        }
    }

    /// Displacements measured from now on: the reference position of every
    /// continuum particle set to its current one (a rigid body's reference
    /// positions define its shape and stay).
    fn reset_displacement(&mut self) {
        for q in 0..self.particles.len() {
            if self.kind_of(q) == BodyKind::Continuum {
                self.particles.x0[q] = self.particles.x[q];
            }
        }
    }

    /// Keep the particles for which `keep` holds, with their per-particle
    /// arrays (`Particles::select`, the loads' histories, the built indices).
    fn retain(&mut self, keep: impl Fn(&Model<D>, usize) -> bool) {
        let rows: Vec<usize> = (0..self.particles.len()).filter(|&q| keep(self, q)).collect();
        if rows.len() == self.particles.len() {
            return;
        }
        self.particles = self.particles.select(&rows);
        self.load_ramp_of = pick(&self.load_ramp_of, &rows);
        if let Some(s) = &mut self.staging {
            s.built = pick(&s.built, &rows);
        }
    }

    fn rows_of_body(&self, body: usize) -> Vec<usize> {
        (0..self.particles.len())
            .filter(|&q| self.particles.body[q] as usize == body)
            .collect()
    }

    /// A restart's particles: the bodies activated up to its stage (`active`)
    /// added, then the particles the checkpoint names by their built index
    /// (`built`), in its order; the caller then restores their state. Err
    /// names an index the scene does not build.
    pub fn restore_staging(&mut self, activated: &[usize], built: &[u32]) -> Result<(), String> {
        for &body in activated {
            self.activate(body);
        }
        let staging = self.staging.as_ref().expect("a staged scene");
        let mut row_of = vec![usize::MAX; 1 + staging.built.iter().max().map_or(0, |&b| b as usize)];
        for (q, &b) in staging.built.iter().enumerate() {
            row_of[b as usize] = q;
        }
        let rows = (built.iter())
            .map(|&b| match row_of.get(b as usize) {
                Some(&q) if q != usize::MAX => Ok(q),
                _ => Err(format!("particle {b} (as built) is not in the staged scene")),
            })
            .collect::<Result<Vec<usize>, String>>()?;
        self.particles = self.particles.select(&rows);
        self.load_ramp_of = pick(&self.load_ramp_of, &rows);
        self.staging.as_mut().expect("a staged scene").built = built.to_vec();
        Ok(())
    }

    /// The particle now in the model that was built as `built` (None: it has
    /// left); the identity without staging.
    pub fn particle_built_as(&self, built: usize) -> Option<usize> {
        match &self.staging {
            None => Some(built),
            Some(s) => s.built.iter().position(|&b| b as usize == built),
        }
    }

    /// The built index of particle q (q itself without staging).
    pub fn built_index(&self, q: usize) -> usize {
        self.staging.as_ref().map_or(q, |s| s.built[q] as usize)
    }
}

/// The geometry of a validated region.
fn region(r: &RegionConfig) -> Geometry {
    match r.shape {
        RegionShape::Rectangle | RegionShape::Box => Geometry::Box {
            min: r.min.clone().expect("validated"),
            max: r.max.clone().expect("validated"),
        },
        RegionShape::Disk | RegionShape::Sphere => Geometry::Ball {
            centre: r.centre.clone().expect("validated"),
            radius: r.radius.expect("validated"),
        },
        RegionShape::Polygon => Geometry::Polygon(r.vertices.clone().expect("validated")),
    }
}

/// The values of `rows` (an empty array stays empty: no particle has one).
fn pick<T: Copy>(v: &[T], rows: &[usize]) -> Vec<T> {
    match v.is_empty() {
        true => Vec::new(),
        false => rows.iter().map(|&q| v[q]).collect(),
    }
}
