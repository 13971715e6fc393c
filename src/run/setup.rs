//! A run's set-up: the model built (from the scene, or its particles from a
//! checkpoint), the strength factor in force, the geostatic stresses, the
//! monitored particle, and the recorders and clock the stages go on with.

use crate::model::Model;
use crate::output::Progress;
use crate::run::checkpoint::{restore_bonds, restore_staging, restored_particles, Kept, Resume};
use crate::run::checks::check_steps;
use crate::run::error::RunError;
use crate::run::options::RunOptions;
use crate::run::recorders::Recorders;
use crate::run::stages::{Checkpoints, Timeline};
use crate::scene::Scene;
use crate::solver::explicit::Explicit;
use std::path::Path;
use std::time::Instant;

/// A run ready for its first stage, or for the stage its checkpoint was
/// written in.
pub(super) struct SetUp<const D: usize> {
    pub model: Model<D>,
    /// The strength-reduction factor in force (1: as given).
    pub strength_factor: f64,
    /// The particle whose displacement summary.json reports, by its index as
    /// built (`Model::built_index`).
    pub monitor: Option<usize>,
    pub line: Timeline,
    /// The run's step number at the start (a restart's).
    pub first_step: usize,
    /// The critical explicit step of the model as built (summary.json).
    pub dt_critical: f64,
}

impl<const D: usize> SetUp<D> {
    pub fn new(
        scene: &Scene,
        out: &Path,
        opts: &RunOptions,
        resume: Option<&Resume>,
    ) -> Result<Self, RunError> {
        let cfg = &scene.config;
        let mut model = Model::<D>::build(scene)?;
        check_steps(scene, &model)?;
        // A search trial's factor holds for the whole run; otherwise each stage may
        // set its own (validation keeps the two apart).
        let mut strength_factor = opts.strength_factor.unwrap_or(1.0);
        if let Some(r) = resume {
            strength_factor = r.checkpoint.strength_factor;
            restore_staging(&r.checkpoint, &r.path, cfg, &mut model)?;
            model.particles = restored_particles(&r.checkpoint, &r.path, model.particles.len())?;
            restore_bonds(&r.checkpoint, &r.path, &mut model)?;
            model.update_pore_pressure();
        }
        let started_from = match (&opts.start_from, resume) {
            (Some(state), None) => {
                model.particles = (state.particles::<D>())
                    .ok()
                    .filter(|p| p.len() == model.particles.len())
                    .ok_or_else(|| {
                        RunError::Checkpoint(format!(
                            "{}: the state to start from does not fit the {} particles the scene builds",
                            scene.file,
                            model.particles.len()
                        ))
                    })?;
                model.update_pore_pressure();
                true
            }
            _ => false,
        };
        if strength_factor != 1.0 {
            model.reduce_strength(strength_factor);
        }
        let fresh = resume.is_none() && !started_from;
        if let (Some(g), true) = (&cfg.geostatic, fresh) {
            crate::physics::geostatic::initialise(&mut model, g);
        }
        if fresh {
            model.initialise_history();
        }
        let monitor = opts
            .monitor
            .as_deref()
            .and_then(|x| model.nearest_particle(x))
            .map(|q| model.built_index(q));
        let ck = resume.map(|r| &r.checkpoint);
        let recorders = match resume {
            Some(r) => {
                let from = r.path.parent().unwrap_or(Path::new("."));
                let from = if from.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    from
                };
                Recorders::resume(out, from, cfg, &model, r.checkpoint.recorders.clone())?
            }
            None => Recorders::create(out, cfg, &model)?,
        };
        let line = Timeline {
            t: ck.map_or(0.0, |c| c.time),
            step: ck.map_or(0, |c| c.step),
            external_work: ck.map_or(0.0, |c| c.external_work),
            total_time: cfg.total_time(),
            recorders,
            progress: opts.progress.then(|| Progress::new(cfg.total_time())),
            interrupted: None,
            checkpoints: Checkpoints {
                interval: cfg.output.checkpoint_interval,
                next: ck.map_or(cfg.output.checkpoint_interval.unwrap_or(0.0), |c| {
                    c.next_checkpoint
                }),
                wall_seconds: cfg.output.checkpoint_wall_seconds,
                last_written: Instant::now(),
                kept: Kept::default(),
            },
        };
        let first_step = line.step;
        let dt_critical = ck.map_or_else(|| Explicit::critical_dt(&model), |c| c.dt_critical);
        Ok(SetUp {
            model,
            strength_factor,
            monitor,
            line,
            first_step,
            dt_critical,
        })
    }
}
