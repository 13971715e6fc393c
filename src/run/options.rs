//! What a run is asked from outside the scene (the command line).

use std::path::PathBuf;

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
}
