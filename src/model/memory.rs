//! The memory a run will need, estimated from the scene before anything is
//! allocated, and the limit it is held to: a grid, particle set or tangent too
//! large for the machine is a scene error naming its key, not an abort on
//! allocation failure or a set-up that fills billions of lattice points.
//!
//! The estimate counts the large arrays, in bytes:
//! - particles: the lattice points `Model::build` visits (each body's bounding
//!   box at `particles_per_cell`, an upper bound of its particles; none for a
//!   body read from a file, `model::import`, which this estimate does not read) times the
//!   fields of `Particles` (vectors, F and σ, history, APIC's B_p) and a step's stencil (the
//!   shape function's support, a weight, a gradient and a node index each);
//! - grid: the nodes times a step's nodal arrays (mass, momentum, force,
//!   velocity and their implicit counterparts);
//! - tangent (implicit stages with the direct solver or the lagged-direct
//!   preconditioner): D² entries per node pair for the nodes within a support
//!   width of each other, index and value, with four times that again for the
//!   fill of the factor;
//! - bonds (peridynamic bodies): the lattice points times half a family, πm²
//!   (2D) or 4πm³/3 (3D) bonds for m = δ/Δx, each stored once at
//!   `BYTES_PER_BOND` (its upper end, length, intact flag and its entry at the
//!   upper end).
//!
//! It is an estimate to within a small factor, meant to catch the scenes that
//! cannot fit, not to predict the peak. The limit defaults to the machine's
//! available memory (`MemAvailable` of /proc/meminfo); `mpm run` and `mpm check`
//! take `--memory-limit GIB` to set another.

use crate::model::tensors::Layout;
use crate::scene::{BodyKindName, LinearSolver, PreconditionerKind, SceneConfig, SolverKind};
use std::f64::consts::PI;

/// The estimate's parts, in bytes, and the counts they come from.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    pub dim: usize,
    /// Lattice points visited when the bodies are filled, per body.
    pub lattice_points: Vec<f64>,
    /// Particles per cell (the product over the directions), per body.
    pub per_cell: Vec<f64>,
    pub grid_nodes: f64,
    pub particle_bytes: f64,
    pub grid_bytes: f64,
    pub tangent_bytes: f64,
    /// Bonds of each peridynamic body (0 for the others), and the key that
    /// sets their number (`horizon` or `horizon_factor`).
    pub bonds: Vec<f64>,
    pub bond_keys: Vec<&'static str>,
    pub bond_bytes: f64,
}

/// One bond of `model::peridynamics::bonds::Bonds`: its upper end u32, |ξ|
/// f64, intact bool, its entry at the upper end (bond id and lower end, u32
/// each).
pub const BYTES_PER_BOND: f64 = 4.0 + 8.0 + 1.0 + 8.0;

impl Estimate {
    pub fn of(c: &SceneConfig) -> Estimate {
        let dim = c.dimension.spatial();
        let d = dim as f64;
        let shape = c.grid.shape_function;
        let support = shape.max_support(dim) as f64;
        let cells = |k: usize| c.grid.cells.get(k).copied().unwrap_or(1) as f64;
        let h = |k: usize| (c.grid.max[k] - c.grid.min[k]) / cells(k);
        let grid_nodes: f64 = (0..dim).map(|k| cells(k) + shape.degree() as f64).product();
        let lattice_points: Vec<f64> = (c.bodies.iter())
            .map(|b| {
                // A body read from a file is counted once read: its particles
                // are the file's rows, its lattice the surface's box.
                let Some((lo, hi)) = b.bounds() else {
                    return 0.0;
                };
                (0..dim)
                    .map(|k| {
                        let spacing = h(k) / b.particles_per_cell.get(k) as f64;
                        ((hi[k] - lo[k]) / spacing).abs().ceil() + 1.0
                    })
                    .product()
            })
            .collect();
        let per_cell: Vec<f64> = (c.bodies.iter())
            .map(|b| {
                (0..dim)
                    .map(|k| b.particles_per_cell.get(k) as f64)
                    .product()
            })
            .collect();
        let particles: f64 = lattice_points.iter().sum();
        // x, x0, v, half-lengths and, in a scene with loads, the load and its ramp;
        // mass and volumes; F and σ (packed); ids; history; the stencil (weight,
        // gradient, node).
        let tensors = 8 * (Layout::gradient(dim).components() + Layout::stress(dim).components());
        // APIC's affine moment B_p (D × D) where a stage keeps one.
        let apic = c.stages().into_iter().any(|s| s.apic());
        let affine = if apic { 8.0 * d * d } else { 0.0 };
        let per_particle = affine
            + 4.0 * 8.0 * d
            + if c.loads.is_empty() {
                0.0
            } else {
                8.0 * d + 4.0
            }
            + 3.0 * 8.0
            + tensors as f64
            + 8.0
            + 80.0
            + support * (8.0 + 8.0 * d + 8.0);
        // Mass and momentum, force, velocity, acceleration; implicit unknowns.
        let per_node = 8.0 * (1.0 + 8.0 * d);
        let implicit_stages = || {
            c.stages()
                .into_iter()
                .filter(|s| s.kind == SolverKind::Implicit)
        };
        let assembles = implicit_stages().any(|s| {
            s.linear_solver() == LinearSolver::Direct
                || matches!(
                    s.preconditioner(),
                    PreconditionerKind::LaggedDirect
                        | PreconditionerKind::Multigrid
                        | PreconditionerKind::LaggedMultigrid
                )
        });
        let tangent_bytes = if assembles {
            let width = (support.powf(1.0 / d) * 2.0 - 1.0).powf(d);
            let active = grid_nodes.min(particles * support);
            let entries = active * d * d * width;
            5.0 * 12.0 * entries
        } else {
            let restart = implicit_stages()
                .map(|s| s.krylov_restart() as f64)
                .fold(0.0, f64::max);
            grid_nodes * d * 8.0 * restart
        };
        let bonds: Vec<f64> = (0..c.bodies.len())
            .map(|i| match c.body_kind(i) {
                BodyKindName::Peridynamic => {
                    let m = c.horizon(i) / c.particle_spacing(i);
                    let family = if dim == 3 {
                        4.0 * PI * m.powi(3) / 3.0
                    } else {
                        PI * m * m
                    };
                    0.5 * family * lattice_points[i]
                }
                _ => 0.0,
            })
            .collect();
        let bond_keys = (c.bodies.iter())
            .map(|b| {
                if b.horizon.is_some() {
                    "horizon"
                } else {
                    "horizon_factor"
                }
            })
            .collect();
        Estimate {
            dim,
            bond_keys,
            bond_bytes: bonds.iter().sum::<f64>() * BYTES_PER_BOND,
            bonds,
            particle_bytes: 2.0 * particles * per_particle,
            grid_bytes: 2.0 * grid_nodes * per_node,
            grid_nodes,
            lattice_points,
            per_cell,
            tangent_bytes,
        }
    }

    pub fn total(&self) -> f64 {
        self.particle_bytes + self.grid_bytes + self.tangent_bytes + self.bond_bytes
    }

    /// Within `limit` bytes, or an error at the key of the largest part.
    pub fn check(&self, limit: f64) -> Result<(), (String, String)> {
        let total = self.total();
        if total <= limit {
            return Ok(());
        }
        let gib = |b: f64| {
            let g = b / GIB;
            if g < 1e4 {
                format!("{g:.3}")
            } else {
                format!("{g:.3e}")
            }
        };
        let parts = format!(
            "particles {} GiB (up to {:.3e} lattice points), grid {} GiB ({:.3e} nodes), \
             tangent or Krylov basis {} GiB, bonds {} GiB ({:.3e})",
            gib(self.particle_bytes),
            self.lattice_points.iter().sum::<f64>(),
            gib(self.grid_bytes),
            self.grid_nodes,
            gib(self.tangent_bytes),
            gib(self.bond_bytes),
            self.bonds.iter().sum::<f64>()
        );
        // The particles of the largest body are blamed on its particles_per_cell
        // when that is large (more than 10 per direction), else on the grid.
        let body = (0..self.lattice_points.len())
            .max_by(|&a, &b| self.lattice_points[a].total_cmp(&self.lattice_points[b]));
        let most_bonds =
            (0..self.bonds.len()).max_by(|&a, &b| self.bonds[a].total_cmp(&self.bonds[b]));
        let key = match (body, most_bonds) {
            // The bonds of the body with most of them on its horizon.
            (_, Some(i)) if self.bond_bytes >= self.total() - self.bond_bytes => {
                format!("body.{i}.{}", self.bond_keys[i])
            }
            (Some(i), _)
                if self.particle_bytes >= self.grid_bytes + self.tangent_bytes
                    && self.per_cell[i] > 10f64.powi(self.dim as i32) =>
            {
                format!("body.{i}.particles_per_cell")
            }
            _ => "grid.cells".to_string(),
        };
        Err((
            key,
            format!(
                "the run would need about {} GiB ({parts}), more than the limit of \
                 {} GiB (the available memory, or --memory-limit GIB)",
                gib(total),
                gib(limit)
            ),
        ))
    }
}

pub const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The memory the machine has available now, in bytes (`MemAvailable` of
/// /proc/meminfo); `None` where that cannot be read.
pub fn available() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The limit: `given` GiB, else the available memory, else no limit.
pub fn limit(given: Option<f64>) -> f64 {
    given
        .map(|g| g * GIB)
        .or_else(available)
        .unwrap_or(f64::INFINITY)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::BLOCK;
    use crate::scene::Scene;

    /// `BLOCK` made a 10 m square of 100² cells with a 5 m body, implicit.
    const SCENE: [&str; 5] = [
        "grid.max=[10.0, 10.0]",
        "grid.cells=[100, 100]",
        "body.0.max=[5.0, 5.0]",
        "solver.kind=\"implicit\"",
        "solver.dt=0.1",
    ];

    fn estimate(overrides: &[&str]) -> Estimate {
        let o: Vec<String> = SCENE
            .iter()
            .chain(overrides)
            .map(|s| s.to_string())
            .collect();
        Estimate::of(&Scene::parse("s.toml", BLOCK, &o).unwrap().config)
    }

    #[test]
    fn counts_the_lattice_and_the_nodes() {
        let e = estimate(&[]);
        assert_eq!(e.grid_nodes, 101.0 * 101.0);
        // 50 cells of the body per direction at 2 particles per cell, and the
        // closing lattice line.
        assert_eq!(e.lattice_points, vec![101.0 * 101.0]);
        assert!(e.total() > 1e6 && e.total() < 1e9, "{e:?}");
        assert!(e.check(e.total()).is_ok());
    }

    #[test]
    fn a_huge_grid_or_particle_count_is_refused_at_its_key() {
        let e = estimate(&["body.0.particles_per_cell=100000"]);
        let (key, msg) = e.check(limit(Some(16.0))).unwrap_err();
        assert_eq!(key, "body.0.particles_per_cell", "{msg}");
        let e = estimate(&["grid.cells=[2147483648, 2147483648]"]);
        let (key, msg) = e.check(limit(Some(16.0))).unwrap_err();
        assert_eq!(key, "grid.cells", "{msg}");
        assert!(msg.contains("e") && msg.contains("16.000 GiB"), "{msg}");
        let e = estimate(&["grid.cells=[100000, 100000]", "body.0.max=[0.1, 0.1]"]);
        let (key, msg) = e.check(limit(Some(16.0))).unwrap_err();
        assert_eq!(key, "grid.cells", "{msg}");
        assert!(msg.contains("16.000 GiB"), "{msg}");
        // The same grid fits with a Krylov solver's basis only in more memory.
        let e = estimate(&[
            "grid.cells=[100000, 100000]",
            "body.0.max=[0.1, 0.1]",
            "solver.linear_solver=gmres",
        ]);
        assert!(e.tangent_bytes < estimate(&["grid.cells=[100000, 100000]"]).tangent_bytes);
    }

    /// A peridynamic block of 101² particles: its bonds estimated against the
    /// ones built (πm²/2 per lattice point in 2D, against the lattice's 28/2 at
    /// m = 3 inside and fewer near the faces: an upper bound), and a horizon
    /// too wide for the memory refused at its key.
    #[test]
    fn the_bonds_of_a_peridynamic_body_are_counted_and_a_huge_horizon_refused() {
        let pd = [
            "material.0.poisson_ratio=0.25",
            "body.0.kind=\"peridynamic\"",
            "solver.kind=\"explicit\"",
        ];
        let e = estimate(&pd);
        let scene = Scene::parse(
            "s.toml",
            BLOCK,
            &SCENE
                .iter()
                .chain(&pd)
                .map(|s| s.to_string())
                .collect::<Vec<_>>(),
        )
        .unwrap();
        let model = crate::model::Model::<2>::build(&scene).unwrap();
        let built = model.peridynamics.as_ref().unwrap().bodies[0].bonds.len() as f64;
        println!("bonds estimated {:.0}, built {built}", e.bonds[0]);
        assert!(
            e.bonds[0] >= built && e.bonds[0] < 1.1 * built,
            "{} vs {built}",
            e.bonds[0]
        );
        assert!(estimate(&[]).bonds == vec![0.0] && estimate(&[]).bond_bytes == 0.0);
        let wide: Vec<&str> = pd
            .iter()
            .copied()
            .chain(["body.0.horizon_factor=3000"])
            .collect();
        let (key, msg) = estimate(&wide).check(limit(Some(16.0))).unwrap_err();
        assert_eq!(key, "body.0.horizon_factor", "{msg}");
        assert!(msg.contains("bonds"), "{msg}");
    }

    #[test]
    fn the_available_memory_is_read() {
        let a = available().expect("/proc/meminfo on Linux");
        assert!(a > 1e6, "{a}");
        assert_eq!(limit(Some(2.0)), 2.0 * GIB);
    }
}
