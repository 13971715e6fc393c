//! Peridynamic bodies (issue 51, first slice): bond-based prototype
//! microelastic brittle (PMB) bodies whose particles are advanced by the forces
//! of their bonds instead of the grid's internal force.
//!
//! - `bonds`: the families, built once in the reference configuration by cell
//!   binning in a deterministic order; each bond stored once for both ends
//!   (i < j), a CSR list of bond ids per particle; broken flags; damage.
//! - `pmb`: the PMB constants (micromodulus, critical stretch from G0), the
//!   pairwise force, bond breaking and the Silling–Askari stable step.
//!
//! One `PdBody` per `[[body]] kind = "peridynamic"`: its particles (global
//! indices, ascending), its bonds and its constants. A scene without a
//! peridynamic body has `Model::peridynamics = None` and allocates nothing.

pub mod bonds;
pub mod pmb;

use crate::dim::Vector;
use crate::parallel::MIN_PARALLEL_LEN;
use bonds::Bonds;
use pmb::Pmb;
use rayon::prelude::*;

/// One peridynamic body: its particles, bonds and PMB constants.
#[derive(Clone, Debug)]
pub struct PdBody<const D: usize> {
    /// The body's index among the scene's `[[body]]`.
    pub body: usize,
    /// Global indices of its particles, ascending (local index = position here).
    pub particles: Vec<usize>,
    /// Reference volumes V_j of its particles (per unit thickness in 2D).
    pub volume: Vec<f64>,
    pub bonds: Bonds,
    pub pmb: Pmb,
    /// Step start: positions and velocities of its particles (`begin_step`).
    start_x: Vec<Vector<D>>,
    start_v: Vec<Vector<D>>,
}

impl<const D: usize> PdBody<D> {
    /// Body `body` made of the particles `particles` (ascending) at reference
    /// positions `x` with reference volumes `volume`.
    pub fn new(
        body: usize,
        particles: Vec<usize>,
        x: &[Vector<D>],
        volume: Vec<f64>,
        pmb: Pmb,
    ) -> Self {
        let bonds = Bonds::build(x, pmb.horizon);
        PdBody {
            body,
            particles,
            volume,
            bonds,
            pmb,
            start_x: Vec::new(),
            start_v: Vec::new(),
        }
    }

    /// The bond force on each of its particles (V_i Σ_j f_ij V_j, `pmb::pair_force`)
    /// at positions `y` (local order), after breaking the bonds stretched past s0.
    pub fn forces(&mut self, y: &[Vector<D>]) -> Vec<Vector<D>> {
        self.bonds.break_stretched(y, self.pmb.critical_stretch);
        let (b, pmb, v) = (&self.bonds, &self.pmb, &self.volume);
        (0..y.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|i| {
                b.gather(i, |k, j| {
                    pmb.pair_force(&y[i], &y[j], b.length[k]) * (v[i] * v[j])
                })
            })
            .collect()
    }

    /// Damage φ_i = 1 − Σ_intact V_j / Σ_all V_j of each of its particles.
    pub fn damage(&self) -> Vec<f64> {
        (0..self.particles.len())
            .map(|i| self.bonds.damage(i, &self.volume))
            .collect()
    }

    /// The Silling–Askari stable step min_i √(2ρ_i / Σ_j V_j c/|ξ_ij|) of the
    /// body, ρ_i = m_i / V_i from the particles' masses `mass` (global).
    pub fn stable_dt(&self, mass: &[f64]) -> f64 {
        (0..self.particles.len())
            .map(|i| {
                let rho = mass[self.particles[i]] / self.volume[i];
                let stiffness = self.bonds.gather_scalar(i, |k, j| {
                    self.volume[j] * self.pmb.micromodulus / self.bonds.length[k]
                });
                self.pmb.stable_dt(rho, stiffness)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Keep the step-start positions and velocities of its particles.
    pub fn begin_step(&mut self, x: &[Vector<D>], v: &[Vector<D>]) {
        self.start_x = self.particles.iter().map(|&q| x[q]).collect();
        self.start_v = self.particles.iter().map(|&q| v[q]).collect();
    }

    /// Advance its particles over Δt from the step start (`begin_step`) by
    /// central differences, v_{n+1} = v_n + Δt (f_bond + f_applied)/m,
    /// x_{n+1} = x_n + Δt v_{n+1} (thesis 2-29, 2-30 with the bond force in
    /// place of the grid's), replacing what G2P gave them. `applied(q)` is the
    /// applied force on global particle q (gravity and loads).
    pub fn advance(
        &mut self,
        x: &mut [Vector<D>],
        v: &mut [Vector<D>],
        mass: &[f64],
        applied: impl Fn(usize) -> Vector<D>,
        dt: f64,
    ) {
        let y = std::mem::take(&mut self.start_x);
        let bond = self.forces(&y);
        for (i, &q) in self.particles.iter().enumerate() {
            v[q] = self.start_v[i] + (bond[i] + applied(q)) * (dt / mass[q]);
            x[q] = y[i] + v[q] * dt;
        }
        self.start_x = y;
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
                let bond = (b.bonds.intact.get_mut(k as usize))
                    .ok_or_else(|| format!("bond {k} of body {} does not exist", b.body))?;
                *bond = false;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::peridynamics::pmb::Space;

    /// Homogeneous uniaxial tension of a plane-stress plate 40Δx × 20Δx
    /// (m = 3, no surface or partial-volume correction): equal and opposite
    /// forces σW on its end columns, the static state found by dynamic
    /// relaxation (viscous damping), the strain between the columns at L/4
    /// and 3L/4, averaged over the plate's width, against σ/E.
    #[test]
    fn a_plane_stress_plate_in_tension_stretches_by_sigma_over_e_to_the_surface_error() {
        let (nx, ny, dx, e, sigma) = (40usize, 20usize, 1e-3, 70e9, 7e6);
        let x: Vec<Vector<2>> = (0..nx * ny)
            .map(|q| Vector::<2>::new((q % nx) as f64 * dx, (q / nx) as f64 * dx))
            .collect();
        let v0 = dx * dx;
        let pmb = Pmb::new(Space::PlaneStress, e, 3.0 * dx);
        let mut b = PdBody::new(0, (0..x.len()).collect(), &x, vec![v0; x.len()], pmb);
        let per = sigma * (ny as f64 * dx) / ny as f64;
        let load = |q: usize| match q % nx {
            0 => Vector::<2>::new(-per, 0.0),
            c if c == nx - 1 => Vector::<2>::new(per, 0.0),
            _ => Vector::zeros(),
        };
        let mass = vec![v0; x.len()]; // ρ = 1: a fictitious density
        let dt = b.stable_dt(&mass);
        let omega = std::f64::consts::PI / (nx as f64 * dx) * (e / 1.0f64).sqrt();
        let damping = 2.0 * omega * dt;
        let (mut y, mut v) = (x.clone(), vec![Vector::<2>::zeros(); x.len()]);
        let mut residual = f64::INFINITY;
        for _ in 0..40_000 {
            let f = b.forces(&y);
            residual = 0.0;
            for q in 0..y.len() {
                let total = f[q] + load(q);
                residual = f64::max(residual, total.norm() / per);
                v[q] = v[q] * (1.0 - damping) + total * (dt / mass[q]);
                y[q] += v[q] * dt;
            }
            if residual < 1e-6 {
                break;
            }
        }
        let mean_u = |c: usize| {
            (0..ny)
                .map(|r| y[r * nx + c][0] - x[r * nx + c][0])
                .sum::<f64>()
                / ny as f64
        };
        let (c1, c2) = (nx / 4, 3 * nx / 4);
        let strain = (mean_u(c2) - mean_u(c1)) / ((c2 - c1) as f64 * dx);
        let error = strain / (sigma / e) - 1.0;
        println!("residual {residual:.1e}; strain/(σ/E) − 1 = {error:+.4}");
        assert!(residual < 1e-6, "not converged: {residual:e}");
        assert!(error.abs() < 0.08, "{error}");
    }
}
