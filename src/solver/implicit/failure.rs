//! Why one attempt at an implicit step failed: the caller halves the step and
//! tries again, or reports the failure as the run's divergence.

/// The particle at fault, if there is one, and what went wrong.
#[derive(Clone, Debug)]
pub struct Failure {
    pub particle: Option<usize>,
    pub message: String,
}
