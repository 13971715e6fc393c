//! The peridynamic bodies of a model (issue 51): per body its particles, their
//! reference volumes, its bonds and its bond law's constants, built once in
//! the reference configuration; the bonds' broken flags are the state that
//! evolves (and is checkpointed). Their forces on the particles and the step
//! that advances them are `physics::peridynamics`; the bond laws are
//! `material::bond`.
//!
//! - `bonds`: the families, built once in the reference configuration by cell
//!   binning in a deterministic order; each bond stored once for both ends
//!   (i < j), numbered by the lower end, with each particle's bonds to lower
//!   ends listed apart; broken flags; damage.
//! - `state`: a correspondence body's own material and its particles' F,
//!   stress and history.
//!
//! A scene without a peridynamic body has `Model::peridynamics = None` and
//! allocates nothing.

pub mod bonds;
pub mod state;

use crate::dim::Vector;
use crate::material::bond::short_range::ShortRange;
use crate::material::bond::BondLaw;
use bonds::Bonds;
use state::StressState;

/// One peridynamic body: its particles, bonds and bond law.
#[derive(Clone, Debug)]
pub struct PdBody<const D: usize> {
    /// The body's index among the scene's `[[body]]`.
    pub body: usize,
    /// Global indices of its particles, ascending (local index = position here).
    pub particles: Vec<usize>,
    /// Reference volumes V_j of its particles (per unit thickness in 2D).
    pub volume: Vec<f64>,
    /// Reference positions of its particles (the bonds' ξ).
    pub reference: Vec<Vector<D>>,
    pub bonds: Bonds,
    pub law: BondLaw,
    /// Step start: positions and velocities of its particles (`begin_step`).
    pub start_x: Vec<Vector<D>>,
    pub start_v: Vec<Vector<D>>,
    /// This step's bond forces on its particles, and the short-range
    /// repulsion if any particle is pressed (`physics::peridynamics::step_forces`).
    pub bond_force: Vec<Vector<D>>,
    pub repulsion: Option<Vec<Vector<D>>>,
    /// A correspondence body's stress state (`BondLaw::Correspondence`); None
    /// for the bond-based laws.
    pub stress: Option<StressState>,
    /// The repulsion of its particles that no intact bond joins, among
    /// themselves and with the other bodies' (`material::bond::short_range`);
    /// None: they pass through each other.
    pub short_range: Option<ShortRange>,
}

impl<const D: usize> PdBody<D> {
    /// Body `body` made of the particles `particles` (ascending) at reference
    /// positions `x` with reference volumes `volume`.
    pub fn new(
        body: usize,
        particles: Vec<usize>,
        x: &[Vector<D>],
        volume: Vec<f64>,
        law: BondLaw,
    ) -> Self {
        let bonds = Bonds::build(x, law.horizon());
        PdBody::with_bonds(body, particles, x, volume, law, bonds)
    }

    /// As [`PdBody::new`], with the bonds given (`Bonds::build_where`).
    pub fn with_bonds(
        body: usize,
        particles: Vec<usize>,
        x: &[Vector<D>],
        volume: Vec<f64>,
        law: BondLaw,
        bonds: Bonds,
    ) -> Self {
        PdBody {
            body,
            particles,
            volume,
            reference: x.to_vec(),
            bonds,
            law,
            start_x: Vec::new(),
            start_v: Vec::new(),
            bond_force: Vec::new(),
            repulsion: None,
            stress: None,
            short_range: None,
        }
    }

    /// With the short-range repulsion `short_range`.
    pub fn with_short_range(self, short_range: Option<ShortRange>) -> Self {
        PdBody {
            short_range,
            ..self
        }
    }

    /// With the stress state `stress` (a correspondence body).
    pub fn with_stress(self, stress: StressState) -> Self {
        PdBody {
            stress: Some(stress),
            ..self
        }
    }

    /// Damage φ_i = 1 − Σ_intact V_j / Σ_all V_j of each of its particles.
    pub fn damage(&self) -> Vec<f64> {
        (0..self.particles.len())
            .map(|i| self.bonds.damage(i, &self.volume))
            .collect()
    }

    /// The Silling–Askari stable step min_i √(2ρ_i / Σ_j V_j c/|ξ_ij|) (c the
    /// law's `stiffness`) of the
    /// body, ρ_i = m_i / V_i from the particles' masses `mass` (global).
    pub fn stable_dt(&self, mass: &[f64]) -> f64 {
        (0..self.particles.len())
            .map(|i| {
                let rho = mass[self.particles[i]] / self.volume[i];
                let stiffness = self.bonds.gather_scalar(i, |k, j| {
                    self.volume[j] * self.law.stiffness() / self.bonds.length[k]
                });
                BondLaw::stable_dt(rho, stiffness)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Keep the step-start positions and velocities of its particles.
    pub fn begin_step(&mut self, x: &[Vector<D>], v: &[Vector<D>]) {
        self.start_x = self.particles.iter().map(|&q| x[q]).collect();
        self.start_v = self.particles.iter().map(|&q| v[q]).collect();
    }
}

/// All peridynamic bodies of a model.
#[derive(Clone, Debug, Default)]
pub struct Peridynamics<const D: usize> {
    pub bodies: Vec<PdBody<D>>,
    /// The stable step of the bodies with all their bonds (`PdBody::stable_dt`,
    /// the smallest): a broken bond only raises it, so it holds for the run.
    pub stable_dt: f64,
}

impl<const D: usize> Peridynamics<D> {
    /// The bodies, with the particles' masses `mass` for their stable step.
    pub fn new(bodies: Vec<PdBody<D>>, mass: &[f64]) -> Self {
        let stable_dt = (bodies.iter())
            .map(|b| b.stable_dt(mass))
            .fold(f64::INFINITY, f64::min);
        Peridynamics { bodies, stable_dt }
    }

    /// Keep the step-start state of every body (`PdBody::begin_step`).
    pub fn begin_step(&mut self, x: &[Vector<D>], v: &[Vector<D>]) {
        self.bodies.iter_mut().for_each(|b| b.begin_step(x, v));
    }

    /// Per body, the ids of its broken bonds, ascending (checkpoints).
    pub fn broken_bonds(&self) -> Vec<Vec<u32>> {
        (self.bodies.iter())
            .map(|b| {
                (0..b.bonds.len() as u32)
                    .filter(|&k| !b.bonds.intact[k as usize])
                    .collect()
            })
            .collect()
    }

    /// Per body, its correspondence stress state as numbers (`StressState::numbers`;
    /// empty for a bond-based body), for checkpoints.
    pub fn stress_states(&self) -> Vec<Vec<f64>> {
        (self.bodies.iter())
            .map(|b| b.stress.as_ref().map_or_else(Vec::new, |s| s.numbers()))
            .collect()
    }

    /// The stress states `numbers` gives (`stress_states` of the same scene).
    pub fn restore_stress(&mut self, numbers: &[Vec<f64>]) -> Result<(), String> {
        let correspondence = self.bodies.iter().any(|b| b.stress.is_some());
        if numbers.len() != self.bodies.len() && (correspondence || !numbers.is_empty()) {
            return Err(format!(
                "it holds the stress states of {} peridynamic bodies, the scene has {}",
                numbers.len(),
                self.bodies.len()
            ));
        }
        for (k, b) in self.bodies.iter_mut().enumerate() {
            let n = numbers.get(k).map_or(&[][..], |n| &n[..]);
            match &mut b.stress {
                Some(s) => s.restore(n).map_err(|e| format!("body {}: {e}", b.body))?,
                None if !n.is_empty() => {
                    return Err(format!(
                        "it holds a stress state for body {}, which is bond-based here",
                        b.body
                    ))
                }
                None => {}
            }
        }
        Ok(())
    }

    /// Break the bonds `broken` lists (`broken_bonds` of the same scene).
    pub fn restore_broken(&mut self, broken: &[Vec<u32>]) -> Result<(), String> {
        if broken.len() != self.bodies.len() {
            return Err(format!(
                "it holds the bonds of {} peridynamic bodies, the scene has {}",
                broken.len(),
                self.bodies.len()
            ));
        }
        for (b, ids) in self.bodies.iter_mut().zip(broken) {
            for &k in ids {
                if k as usize >= b.bonds.len() {
                    return Err(format!("bond {k} of body {} does not exist", b.body));
                }
                b.bonds.break_bond(k as usize);
            }
        }
        Ok(())
    }

    /// Damage per particle of the model (`n` particles; 0 off the PD bodies).
    pub fn damage(&self, n: usize) -> Vec<f64> {
        let mut d = vec![0.0; n];
        for b in &self.bodies {
            for (i, phi) in b.damage().into_iter().enumerate() {
                d[b.particles[i]] = phi;
            }
        }
        d
    }
}
