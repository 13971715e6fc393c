//! What a run is asked from outside the scene (the command line).

use crate::run::checkpoint::ParticleState;
use std::path::PathBuf;
use std::sync::Arc;

/// Options that do not belong in the scene.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Show a progress bar (only drawn when stderr is a terminal).
    pub progress: bool,
    /// Run with the strengths reduced by this factor (one trial of a strength
    /// reduction search; `None`: as given).
    pub strength_factor: Option<f64>,
    /// Report the displacement of the particle nearest to this point
    /// (summary.json `monitor_displacement`).
    pub monitor: Option<Vec<f64>>,
    /// The memory the run may take, in GiB (`None`: the machine's available
    /// memory; `model::memory`).
    pub memory_limit: Option<f64>,
    /// Continue from this checkpoint instead of starting at t = 0.
    pub restart: Option<PathBuf>,
    /// Start at t = 0 from these particles instead of the scene's initial
    /// state: the end state of an earlier run of the same scene (a strength
    /// reduction search's last stable trial, `analyses::strength_reduction`).
    /// No geostatic stresses are set and the history variables are those the
    /// particles carry.
    pub start_from: Option<Arc<ParticleState>>,
    /// Keep the particles' end state in `Summary::final_particles`.
    pub keep_final_particles: bool,
}
