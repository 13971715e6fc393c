//! Time integration: the explicit central-difference solver (USF, USL, MUSL) and
//! the implicit Newmark / quasi-static Newton solver, with the linear solvers of
//! the Newton corrections. The run drives either through `Stepper`.

pub(crate) mod divergence;
pub mod explicit;
pub mod implicit;
pub mod linear;
pub mod report;
pub mod stepper;

use crate::scene::{ShapeFunction, SolverConfig, SolverKind};
use explicit::Explicit;
use implicit::Implicit;
use stepper::Stepper;

/// The stepper of a run or stage with these settings, starting at `t_start`.
pub fn stepper<const D: usize>(
    shape: ShapeFunction,
    s: &SolverConfig,
    t_start: f64,
) -> Box<dyn Stepper<D>> {
    match s.kind {
        SolverKind::Explicit => Box::new(Explicit::new(shape, s)),
        SolverKind::Implicit => Box::new(Implicit::new(shape, s, t_start)),
    }
}
