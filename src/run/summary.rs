//! summary.json of a run: written and read through these structs (the run writes
//! it; `mpm bench`, strength reduction and the tests read it back).

use crate::output::write_json;
use crate::run::particle_state::ParticleState;
use crate::scene::ShapeFunction;
use crate::solver::report::SolverReport;
use serde::{Deserialize, Deserializer, Serialize};
use std::io;
use std::path::Path;
use std::sync::Arc;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// It reached the end time.
    Completed,
    /// It stopped early on a divergence (`message`, `diverged_step`, …).
    Diverged,
    /// A signal (SIGINT, SIGTERM) stopped it at the end of a step; a checkpoint
    /// lets it go on (`message` says where).
    Interrupted,
    /// It could not go on: an output could not be written (`message`); for
    /// `mpm limit`, a refinement level could not be solved.
    Failed,
}

/// summary.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub scene: String,
    pub dimension: usize,
    /// `dimension = "axisymmetric"` (then `dimension` is 2); absent otherwise.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub axisymmetric: bool,
    pub shape_function: ShapeFunction,
    pub particles: usize,
    pub steps: usize,
    /// The last step taken.
    pub dt: f64,
    /// The explicit critical step at the start (2-45).
    pub dt_critical: f64,
    pub end_time: f64,
    pub wall_seconds: f64,
    pub particle_steps_per_second: f64,
    pub active_nodes_last_step: usize,
    pub status: Status,
    /// Why a run did not complete (absent when it did).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Where a diverged run stopped.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub divergence: Option<DivergenceReport>,
    /// The solver fields of the last stage that ran, with the Newton, cut-back and
    /// Krylov counts of the whole run when it has an implicit stage.
    #[serde(flatten)]
    pub solver: SolverReport,
    pub stages: Vec<StageSummary>,
    /// The limit pressure and its neighbours, when the scene has a footing.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub footing: Option<FootingSummary>,
    /// The particle nearest to the monitored point and its displacement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monitor_particle: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monitor_displacement: Option<f64>,
    /// The factor a strength-reduction trial divided the strengths by.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_factor: Option<f64>,
    /// The checkpoint a restarted run continued from (`wall_seconds` and
    /// `particle_steps_per_second` then count this run's part only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resumed_from: Option<ResumedFrom>,
    /// The stages' warnings, each naming its stage.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The particles at the end, when the run was asked to keep them
    /// (`RunOptions::keep_final_particles`; not written to summary.json).
    #[serde(skip)]
    pub final_particles: Option<Arc<ParticleState>>,
}

/// Where a restarted run began.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResumedFrom {
    pub checkpoint: String,
    pub step: usize,
    pub time: f64,
}

/// Where a run diverged (why: the summary's `message`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DivergenceReport {
    pub diverged_step: usize,
    /// The offending particle (null for a Newton failure).
    pub diverged_particle: Option<usize>,
}

/// One stage of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageSummary {
    pub name: String,
    pub start_time: f64,
    pub end_time: f64,
    pub steps: usize,
    pub dt: f64,
    pub wall_seconds: f64,
    pub active_nodes_last_step: usize,
    #[serde(flatten)]
    pub solver: SolverReport,
    /// The strengths' divisor from this stage on, when the stage sets one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_reduction_factor: Option<f64>,
    /// What the stage warned of at its start (an explicit fixed Δt above the
    /// critical step).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// The load–settlement curve of a footing, summarised.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FootingSummary {
    /// The pressure at the end of the run (the plateau, if the run went far
    /// enough).
    pub limit_pressure: f64,
    pub peak_pressure: f64,
    pub settlement: f64,
    /// Relative rise of the pressure over the last tenth of the settlement
    /// (null when the curve has no point there).
    #[serde(deserialize_with = "number_or_nan")]
    pub plateau_change: f64,
    /// limit_pressure / c of the material under the footing, when it has a
    /// cohesion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearing_capacity_factor: Option<f64>,
}

/// JSON has no NaN (serde_json writes null): read null back as NaN.
fn number_or_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Summary {
    /// Read a summary.json.
    pub fn read(path: &Path) -> Result<Summary, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    pub fn write(&self, path: &Path) -> io::Result<()> {
        write_json(path, self)
    }
}
