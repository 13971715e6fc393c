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
