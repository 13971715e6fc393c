//! Running a scene: build the model, advance it stage by stage to the end time,
//! record as it goes (history.csv, ParaView frames, newton.csv, footing.csv) and
//! finish with particles_final.csv and summary.json. A divergence stops the run
//! cleanly: everything written so far is flushed and summary.json records what
//! happened where. A run may write checkpoints as it goes and start from one
//! (`checkpoint.rs`): the restarted run writes the same bytes as one that was
//! never stopped.

pub mod checkpoint;
mod checks;
pub(crate) mod contact;
pub(crate) mod energy;
pub(crate) mod error;
mod finish;
pub(crate) mod footing;
pub mod interrupt;
pub(crate) mod options;
mod particle_dumps;
pub mod particle_state;
pub(crate) mod recorders;
mod schedule;
mod setup;
mod stages;
pub mod summary;

pub use checks::{set_up_check, MAX_STEPS};
pub use energy::{kinetic_energy, strain_energy};
pub use error::RunError;
pub use options::RunOptions;

use crate::scene::Scene;
use checkpoint::{matching_checkpoint, Resume};
use checks::{before_steps, check_memory};
use setup::SetUp;
use std::path::Path;
use std::time::Instant;
use summary::Summary;

/// Run a scene, writing its outputs into `out`. A scene error that an override
/// causes names the override (`Scene::blame`, replaying the checks before the
/// first step).
pub fn run(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    run_as_given(scene, out, opts).map_err(|e| match e {
        RunError::Scene(e) => RunError::Scene(scene.blame(e, |s| before_steps(s, opts))),
        e => e,
    })
}

/// [`run`] without naming the override a scene error comes from.
fn run_as_given(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    check_memory(scene, opts)?;
    let resume = match &opts.restart {
        Some(path) => Some(Resume {
            checkpoint: matching_checkpoint(scene, path)?,
            path: path.clone(),
        }),
        None => None,
    };
    std::fs::create_dir_all(out)?;
    // The run goes on a worker of the thread pool: each parallel loop then starts
    // there and is not handed over from a thread outside the pool, a wake-up and
    // a wait per loop (about 60 per explicit step).
    rayon::scope(|_| match scene.config.dimension.spatial() {
        2 => run_dim::<2>(scene, out, opts, resume),
        3 => run_dim::<3>(scene, out, opts, resume),
        d => unreachable!("validated dimension {d}"),
    })
}

/// A run in D dimensions: set up, the stages, the summary and the final outputs.
fn run_dim<const D: usize>(
    scene: &Scene,
    out: &Path,
    opts: &RunOptions,
    resume: Option<Resume>,
) -> Result<Summary, RunError> {
    let mut run = SetUp::<D>::new(scene, out, opts, resume.as_ref())?;
    let started = Instant::now();
    let ck = resume.as_ref().map(|r| &r.checkpoint);
    let SetUp {
        model,
        line,
        strength_factor,
        dt_critical,
        ..
    } = &mut run;
    let mut ran = stages::run_stages(scene, out, model, line, strength_factor, *dt_critical, ck)?;
    if let Some(p) = &run.line.progress {
        p.finish();
    }
    let wall = started.elapsed().as_secs_f64();
    let summary = finish::summary(scene, opts, resume.as_ref(), &run, &mut ran, wall);
    finish::finish(scene, out, &mut run, ran, summary)
}
