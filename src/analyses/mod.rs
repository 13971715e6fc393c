//! Analyses built on runs: the strength-reduction search for a factor of safety,
//! analytical reference solutions and their error measures, limit analysis (a
//! separate finite-element program with its own scene format), and `mpm bench`.

pub mod bench;
pub mod limit_analysis;
pub mod reference;
pub mod strength_reduction;
