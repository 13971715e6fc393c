//! Time integration: the explicit central-difference solver (USF, USL, MUSL) and
//! the implicit Newmark / quasi-static Newton solver, with the linear solvers of
//! the Newton corrections.

pub mod explicit;
pub mod implicit;
pub mod linear;
