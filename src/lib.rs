//! Material point method (MPM) research code.
//!
//! One code path serves 2D plane strain (`D = 2`) and 3D (`D = 3`) through const
//! generics. Tensors that exist in 3D even in plane strain (deformation gradient,
//! Cauchy stress) are always stored as 3×3; vectors on the grid and particles have
//! `D` components.
//!
//! The modules are layers; each imports only from the layers listed before it
//! (`docs/architecture.md`; `tests/architecture.rs` checks it):
//!
//! | layer | modules | what it holds |
//! |---|---|---|
//! | 0 | `dim`, `parallel` | small tensors; deterministic parallel loops |
//! | 1 | `material` | constitutive models, each owning its scene keys |
//! | 2 | `scene` | the scene file: parsing, overrides, validation |
//! | 3 | `model` | the state every solver works on: grid, particles, bodies, loads, conditions |
//! | 4 | `physics`, `output` | what both solvers share: shape functions, transfers, stress update, F-bar, boundary laws; file formats |
//! | 5 | `solver` | explicit and implicit time stepping, linear solvers |
//! | 6 | `run` | the stage loop, recorders, the typed summary |
//! | 7 | `analyses` | strength reduction, analytical references, limit analysis, `mpm bench` |
//!
//! The command line (`src/bin/mpm.rs`) sits on top.
//!
//! # The interface
//!
//! What a program built on this crate may rely on:
//! - a scene: [`scene::Scene`] (`load`, `parse`, `--set` overrides), its
//!   configuration types and [`scene::SceneError`];
//! - a run: [`run::run`] with [`run::RunOptions`], giving a
//!   [`run::summary::Summary`] (summary.json) or a [`run::RunError`]; the
//!   energies [`run::kinetic_energy`], [`run::strain_energy`];
//! - the model a run works on: [`model::Model`] (built from a scene), its
//!   particles, grid and bodies;
//! - the solvers behind [`solver::stepper::Stepper`]: [`solver::explicit::Explicit`],
//!   [`solver::implicit::Implicit`];
//! - the materials: [`material::Material`], the registry, the single-point
//!   [`material::driver`];
//! - the analyses: strength reduction, the analytical references, limit
//!   analysis, `mpm bench`;
//! - [`dim`] (small tensors), [`parallel::on_threads`] and [`output::Table`].
//!
//! The integration tests and benchmarks also reach lower-level pieces: the
//! shape functions and transfers (`physics::{shape, transfer}`), the explicit
//! box scatter (`solver::explicit::node_box`), the implicit step and its
//! assembly (`solver::implicit::{step, residual, assembly, newton}`), the
//! linear solvers (`solver::linear`). They are public because the tests
//! measure them, not as a stable interface. Every other module is
//! `pub(crate)`: nothing outside the crate uses it, and the compiler reports
//! what inside it goes unused.

pub mod dim;
pub mod parallel;

pub mod material;

pub mod scene;

pub mod model;

pub mod output;
pub mod physics;

pub mod solver;

pub mod run;

pub mod analyses;
