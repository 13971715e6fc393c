//! The solvers at their limits: matrix-free Newton–Krylov against the direct
//! path, time steps at and beyond the critical one, nearly incompressible
//! materials, stiffness contrasts, cut-backs, and results that do not depend on
//! the number of threads nor on the form a rigid body is written in.

#[path = "../common/mod.rs"]
mod common;

mod body_kinds;
mod direct;
mod ended;
mod extremes;
mod implicit_extremes;
mod krylov;
mod multigrid;
mod restart;
mod signals;
mod stability;
mod threads;
mod timeline;
mod transfers;
