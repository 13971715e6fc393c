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
//! them (`Staging::restore`). The model's methods (`Model::change`, …) hand
//! their arrays over (`Arrays`). A scene that stages nothing has no
//! `Staging` (`Model::staging` is None).

use crate::model::geometry::Geometry;
use crate::model::particles::{pick, Particles};
use crate::scene::region::{RegionConfig, RegionShape};
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

/// The model's per-particle arrays a change touches: the particles, the
/// index of each one's load history (`Model::load_ramp_of`), and whether
/// each body is a continuum body (the kind staging applies to).
pub struct Arrays<'a, const D: usize> {
    pub particles: &'a mut Particles<D>,
    pub load_ramp_of: &'a mut Vec<u32>,
    pub continuum: &'a [bool],
}

impl<const D: usize> Arrays<'_, D> {
    /// Whether particle q belongs to a continuum body.
    fn continuum(&self, q: usize) -> bool {
        (self.continuum.get(self.particles.body[q] as usize)).is_some_and(|&c| c)
    }

    /// Keep the particles of `rows`, in that order, with their loads' histories
    /// and their built indices `built`.
    fn keep(&mut self, rows: &[usize], built: &mut Vec<u32>) {
        *self.particles = self.particles.select(rows);
        *self.load_ramp_of = pick(self.load_ramp_of, rows);
        *built = pick(built, rows);
    }
}

impl<const D: usize> Staging<D> {
    /// Staging of a model as built: every particle numbered as built, and the
    /// particles of the `inactive` bodies taken out and held until activated.
    pub fn start(a: &mut Arrays<D>, inactive: &[usize]) -> Staging<D> {
        let mut s = Staging {
            built: (0..a.particles.len() as u32).collect(),
            dormant: Vec::new(),
        };
        for &body in inactive {
            let (of, rest): (Vec<usize>, Vec<usize>) =
                (0..a.particles.len()).partition(|&q| a.particles.body[q] as usize == body);
            s.dormant.push(Dormant {
                body,
                particles: a.particles.select(&of),
                built: pick(&s.built, &of),
                load_ramp_of: pick(a.load_ramp_of, &of),
            });
            a.keep(&rest, &mut s.built);
        }
        s
    }

    /// Apply a stage's changes at its start (`StageChanges`, in its order).
    pub fn change(&mut self, a: &mut Arrays<D>, changes: &StageChanges) {
        for &body in &changes.deactivate {
            self.retain(a, |a, q| a.particles.body[q] as usize != body);
        }
        for region in &changes.excavate {
            let inside = |a: &Arrays<D>, q: usize| region.contains(a.particles.x[q].as_slice());
            self.retain(a, |a, q| !(a.continuum(q) && inside(a, q)));
        }
        for &body in &changes.activate {
            self.activate(a, body);
        }
        if changes.reset_displacement {
            reset_displacement(a);
        }
    }

    /// The particles of dormant `body` added after those in the model, at
    /// rest as built (unstressed, undeformed).
    fn activate(&mut self, a: &mut Arrays<D>, body: usize) {
        let Some(k) = self.dormant.iter().position(|d| d.body == body) else {
            return;
        };
        let d = self.dormant.remove(k);
        let n = a.particles.len();
        a.particles.append(&d.particles);
        self.built.extend_from_slice(&d.built);
        if !(a.load_ramp_of.is_empty() && d.load_ramp_of.is_empty()) {
            a.load_ramp_of.resize(n, u32::MAX);
            match d.load_ramp_of.is_empty() {
                true => a.load_ramp_of.resize(n + d.built.len(), u32::MAX),
                false => a.load_ramp_of.extend_from_slice(&d.load_ramp_of),
            }
        }
    }

    /// Keep the particles for which `keep` holds.
    fn retain(&mut self, a: &mut Arrays<D>, keep: impl Fn(&Arrays<D>, usize) -> bool) {
        let rows: Vec<usize> = (0..a.particles.len()).filter(|&q| keep(a, q)).collect();
        if rows.len() < a.particles.len() {
            a.keep(&rows, &mut self.built);
        }
    }

    /// A restart's particles: the bodies activated up to its stage
    /// (`activated`) added, then the particles the checkpoint names by their
    /// built index (`built`) kept, in its order; the caller then restores
    /// their state. Err names an index the scene does not build.
    pub fn restore(
        &mut self,
        a: &mut Arrays<D>,
        activated: &[usize],
        built: &[u32],
    ) -> Result<(), String> {
        for &body in activated {
            self.activate(a, body);
        }
        let mut row_of = vec![usize::MAX; 1 + self.built.iter().max().map_or(0, |&b| b as usize)];
        for (q, &b) in self.built.iter().enumerate() {
            row_of[b as usize] = q;
        }
        let rows = (built.iter())
            .map(|&b| match row_of.get(b as usize) {
                Some(&q) if q != usize::MAX => Ok(q),
                _ => Err(format!(
                    "particle {b} (as built) is not in the staged scene"
                )),
            })
            .collect::<Result<Vec<usize>, String>>()?;
        a.keep(&rows, &mut self.built);
        Ok(())
    }

    /// The particles of the bodies not active yet, as built.
    pub fn dormant_particles(&self) -> impl Iterator<Item = &Particles<D>> {
        self.dormant.iter().map(|d| &d.particles)
    }
}

/// Displacements measured from now on: the reference position of every
/// continuum particle set to its current one (a rigid body's reference
/// positions define its shape and stay).
fn reset_displacement<const D: usize>(a: &mut Arrays<D>) {
    for q in 0..a.particles.len() {
        if a.continuum(q) {
            a.particles.x0[q] = a.particles.x[q];
        }
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
