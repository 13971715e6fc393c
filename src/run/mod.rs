//! Running a scene: build the model, advance it stage by stage to the end time,
//! record as it goes (history.csv, ParaView frames, newton.csv, footing.csv) and
//! finish with particles_final.csv and summary.json. A divergence stops the run
//! cleanly: everything written so far is flushed and summary.json records what
//! happened where.

pub mod energy;
pub mod footing;
pub mod interrupt;
pub mod recorders;
pub mod summary;

pub use energy::{kinetic_energy, strain_energy};

use crate::model::memory::{self, Estimate};
use crate::model::Model;
use crate::output::{write_particles_csv_with, Progress};
use crate::scene::{Scene, SceneError, SolverKind};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::explicit::Explicit;
use crate::solver::report::SolverReport;
use crate::solver::stepper::Stepper;
use recorders::{Moment, Recorders};
use std::path::Path;
use std::time::Instant;
use summary::{DivergenceReport, StageSummary, Status, Summary};

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Scene(#[from] SceneError),
    #[error("cannot write outputs: {0}")]
    Io(#[from] std::io::Error),
    /// The run stopped early; its summary (also in summary.json) says where.
    #[error("{message}")]
    Diverged {
        message: String,
        summary: Box<Summary>,
    },
    /// A signal stopped the run at the end of a step; its outputs so far are
    /// written (`interrupt.rs`).
    #[error("{message}")]
    Interrupted {
        signal: i32,
        message: String,
        summary: Box<Summary>,
    },
}

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
}

/// What a run checks before it allocates and steps: the memory estimate, then the
/// model's build (a body that holds no particle, an absorbing face with no
/// material, …). `mpm check` calls it, so it rejects what `mpm run` would.
pub fn set_up_check(scene: &Scene, opts: &RunOptions) -> Result<(), SceneError> {
    check_memory(scene, opts)?;
    match scene.config.dimension {
        2 => check_steps(scene, &Model::<2>::build(scene)?),
        3 => check_steps(scene, &Model::<3>::build(scene)?),
        d => unreachable!("validated dimension {d}"),
    }
}

/// The most steps a stage may take: more is a mistake in the scene (a run of
/// 10⁹ steps of the smallest scene takes hours), refused before it starts.
pub const MAX_STEPS: f64 = 1e9;

/// Each stage's step count, from its Δt (explicit: cfl × the critical step of
/// the model as built), within [`MAX_STEPS`].
fn check_steps<const D: usize>(scene: &Scene, model: &Model<D>) -> Result<(), SceneError> {
    let dt_critical = Explicit::critical_dt(model);
    let c = &scene.config;
    for (k, sc) in c.stages().into_iter().enumerate() {
        let prefix = match c.solver {
            Some(_) => "solver".to_string(),
            None => format!("stage.{k}"),
        };
        let dt = match sc.kind {
            SolverKind::Explicit => sc.dt.unwrap_or(sc.cfl() * dt_critical),
            SolverKind::Implicit => sc.implicit_dt(),
        };
        let steps = sc.end_time / dt;
        if steps.is_nan() || steps > MAX_STEPS {
            let why = match (sc.kind, sc.dt) {
                (SolverKind::Explicit, None) => format!(
                    " (cfl × the critical step min h/(c + |v|) = {dt_critical:.3e} of the model as built)"
                ),
                _ => String::new(),
            };
            return Err(scene.at_key(
                &format!("{prefix}.end_time"),
                format!(
                    "the stage would take {steps:.3e} steps of Δt = {dt:.3e}{why}, more than \
                     {MAX_STEPS:e}: shorten it or take larger steps"
                ),
            ));
        }
    }
    Ok(())
}

fn check_memory(scene: &Scene, opts: &RunOptions) -> Result<(), SceneError> {
    Estimate::of(&scene.config)
        .check(memory::limit(opts.memory_limit))
        .map_err(|(key, m)| scene.at_key(&key, m))
}

/// Run a scene, writing its outputs into `out`.
pub fn run(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    check_memory(scene, opts)?;
    std::fs::create_dir_all(out)?;
    match scene.config.dimension {
        2 => run_dim::<2>(scene, out, opts),
        3 => run_dim::<3>(scene, out, opts),
        d => unreachable!("validated dimension {d}"),
    }
}

/// The run's course: where it is (time, step, the work done so far) and what it
/// writes as it goes.
struct Timeline {
    t: f64,
    step: usize,
    external_work: f64,
    /// The run's total time (the time tolerance is relative to it).
    total_time: f64,
    recorders: Recorders,
    progress: Option<Progress>,
    /// The signal that stopped the run at the end of a step, if one did.
    interrupted: Option<i32>,
}

impl Timeline {
    fn moment<'a, const D: usize>(&self, model: &'a Model<D>) -> Moment<'a, D> {
        Moment {
            model,
            t: self.t,
            external_work: self.external_work,
        }
    }

    /// Advance one stage of length `duration`: step, record, repeat. Returns how
    /// the stage ended and its last step; the outer error is an output failure.
    fn stage<const D: usize>(
        &mut self,
        model: &mut Model<D>,
        stepper: &mut dyn Stepper<D>,
        duration: f64,
    ) -> std::io::Result<(Result<(), Divergence>, f64)> {
        let end = self.t + duration;
        let mut last_dt = 0.0;
        while self.t < end - 1e-12 * self.total_time {
            let dt = stepper.dt(model).min(end - self.t);
            last_dt = dt;
            // A step too small to move the clock would never end the stage.
            if !(dt > 0.0 && self.t + dt > self.t) {
                return Ok((Err(stalled(self.step, self.t, dt)), last_dt));
            }
            let result = stepper.step(model, self.t, dt, self.step);
            self.recorders.newton(&stepper.take_newton_rows())?;
            match result {
                Ok(work) => self.external_work += work,
                Err(d) => return Ok((Err(d), last_dt)),
            }
            self.t += dt;
            self.step += 1;
            self.recorders
                .footing(model, self.t, dt, stepper.reaction())?;
            self.recorders.state(&self.moment(model), false)?;
            if let Some(p) = &self.progress {
                p.set(self.t, self.step);
            }
            if let Some(signal) = interrupt::requested() {
                self.interrupted = Some(signal);
                return Ok((Ok(()), last_dt));
            }
        }
        self.t = end;
        Ok((Ok(()), last_dt))
    }
}

fn stalled(step: usize, time: f64, dt: f64) -> Divergence {
    Divergence {
        step,
        time,
        particle: None,
        message: format!("the time step {dt:e} no longer advances the time"),
    }
}

fn run_dim<const D: usize>(
    scene: &Scene,
    out: &Path,
    opts: &RunOptions,
) -> Result<Summary, RunError> {
    let cfg = &scene.config;
    let mut model = Model::<D>::build(scene)?;
    check_steps(scene, &model)?;
    // A search trial's factor holds for the whole run; otherwise each stage may
    // set its own (validation keeps the two apart).
    let mut strength_factor = opts.strength_factor.unwrap_or(1.0);
    if strength_factor != 1.0 {
        model.reduce_strength(strength_factor);
    }
    if let Some(g) = &cfg.geostatic {
        crate::physics::geostatic::initialise(&mut model, g);
    }
    let monitor = opts
        .monitor
        .as_deref()
        .and_then(|x| model.nearest_particle(x));
    let mut line = Timeline {
        t: 0.0,
        step: 0,
        external_work: 0.0,
        total_time: cfg.total_time(),
        recorders: Recorders::create(out, cfg, &model)?,
        progress: opts.progress.then(|| Progress::new(cfg.total_time())),
        interrupted: None,
    };
    let dt_critical = Explicit::critical_dt(&model);
    let started = Instant::now();
    let mut outcome = check_state(&model, 0, 0.0);
    if outcome.is_ok() {
        line.recorders.state(&line.moment(&model), true)?;
    }
    let mut stages = Vec::new();
    let mut last: Option<(SolverReport, f64, usize)> = None;
    // An output that cannot be written ends the run as failed.
    let mut failure: Option<std::io::Error> = None;
    for (k, sc) in cfg.stages().into_iter().enumerate() {
        if outcome.is_err() {
            break;
        }
        if let Some(f) = sc
            .strength_reduction_factor
            .filter(|&f| f != strength_factor)
        {
            model.reduce_strength(f);
            strength_factor = f;
        }
        let mut stepper = crate::solver::stepper::<D>(cfg.grid.shape_function, sc, line.t);
        let (start, steps_before, stage_clock) = (line.t, line.step, Instant::now());
        let (result, dt) = match line.stage(&mut model, stepper.as_mut(), sc.end_time) {
            Ok(ended) => ended,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        outcome = result;
        let report = stepper.report();
        stages.push(StageSummary {
            name: sc.name.clone().unwrap_or_else(|| format!("stage{k}")),
            start_time: start,
            end_time: line.t,
            steps: line.step - steps_before,
            dt,
            wall_seconds: stage_clock.elapsed().as_secs_f64(),
            active_nodes_last_step: stepper.active_nodes(),
            solver: report.clone(),
            strength_reduction_factor: sc.strength_reduction_factor.map(|_| strength_factor),
        });
        last = Some((report, dt, stepper.active_nodes()));
        if line.interrupted.is_some() {
            break;
        }
    }
    if let Some(p) = &line.progress {
        p.finish();
    }
    let wall = started.elapsed().as_secs_f64();
    let particles = model.particles.len();
    // A run that stopped before its first step reports its first stage's solver.
    let (solver, dt, active_nodes) = last.unwrap_or_else(|| {
        let first = cfg.stages()[0];
        let report = crate::solver::stepper::<D>(cfg.grid.shape_function, first, 0.0).report();
        (report, 0.0, 0)
    });
    let implicit = cfg.stages().iter().any(|s| s.kind == SolverKind::Implicit);
    let mut summary = Summary {
        scene: scene.file.clone(),
        dimension: D,
        shape_function: cfg.grid.shape_function,
        particles,
        steps: line.step,
        dt,
        dt_critical,
        end_time: line.t,
        wall_seconds: wall,
        particle_steps_per_second: (particles * line.step) as f64 / wall.max(1e-9),
        active_nodes_last_step: active_nodes,
        status: Status::Completed,
        message: None,
        divergence: None,
        solver: run_totals(solver, &stages, implicit),
        stages,
        footing: line.recorders.footing_summary(&model),
        monitor_particle: monitor,
        monitor_displacement: monitor
            .map(|q| (model.particles.x[q] - model.particles.x0[q]).norm()),
        strength_factor: opts.strength_factor,
    };
    let summary_path = out.join("summary.json");
    if let Some(e) = failure {
        return Err(failed(summary, &summary_path, e));
    }
    if let Err(d) = outcome {
        summary.status = Status::Diverged;
        summary.message = Some(d.to_string());
        summary.divergence = Some(DivergenceReport {
            diverged_step: d.step,
            diverged_particle: d.particle,
        });
        summary.write(&summary_path)?;
        return Err(RunError::Diverged {
            message: format!(
                "{}: {d}; outputs written so far are in {}",
                scene.file,
                out.display()
            ),
            summary: Box::new(summary),
        });
    }
    let finish = line
        .recorders
        .state(&line.moment(&model), true)
        .and_then(|()| {
            let eps_p = model.plastic_strain();
            let extra: Vec<(&str, &[f64])> =
                eps_p.iter().map(|e| ("eps_p", e.as_slice())).collect();
            write_particles_csv_with(&out.join("particles_final.csv"), &model.particles, &extra)
        });
    if let Err(e) = finish {
        return Err(failed(summary, &summary_path, e));
    }
    if let Some(signal) = line.interrupted {
        let message = format!(
            "interrupted by {} at step {} (t = {:.6e}); outputs written so far are in {}",
            interrupt::name(signal),
            line.step,
            line.t,
            out.display()
        );
        summary.status = Status::Interrupted;
        summary.message = Some(message.clone());
        summary.write(&summary_path)?;
        return Err(RunError::Interrupted {
            signal,
            message: format!("{}: {message}", scene.file),
            summary: Box::new(summary),
        });
    }
    summary.write(&summary_path)?;
    Ok(summary)
}

/// A run that could not write an output: summary.json says so if it still can be
/// written, and the error goes up.
fn failed(mut summary: Summary, path: &Path, e: std::io::Error) -> RunError {
    summary.status = Status::Failed;
    summary.message = Some(format!("cannot write outputs: {e}"));
    summary.write(path).ok();
    RunError::Io(e)
}

/// The run's solver fields: the last stage's, with the Newton, cut-back and
/// Krylov counts summed over the stages when the run has an implicit stage.
fn run_totals(mut last: SolverReport, stages: &[StageSummary], implicit: bool) -> SolverReport {
    if implicit {
        let sum = |f: fn(&SolverReport) -> Option<usize>| -> Option<usize> {
            Some(stages.iter().filter_map(|s| f(&s.solver)).sum())
        };
        last.newton_iterations = sum(|r| r.newton_iterations);
        last.cutbacks = sum(|r| r.cutbacks);
        last.krylov_iterations = sum(|r| r.krylov_iterations);
    }
    last
}
