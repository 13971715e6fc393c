//! Running a scene: build the model, advance it stage by stage to the end time,
//! record as it goes (history.csv, ParaView frames, newton.csv, footing.csv) and
//! finish with particles_final.csv and summary.json. A divergence stops the run
//! cleanly: everything written so far is flushed and summary.json records what
//! happened where. A run may write checkpoints as it goes and start from one
//! (`checkpoint.rs`): the restarted run writes the same bytes as one that was
//! never stopped.

pub mod checkpoint;
pub mod contact;
pub mod energy;
pub mod footing;
pub mod interrupt;
pub mod recorders;
pub mod summary;

use crate::dim::Vector;
pub use energy::{kinetic_energy, strain_energy};

use crate::model::memory::{self, Estimate};
use crate::model::Model;
use crate::output::{write_particles_csv_with, Progress};
use crate::scene::{Integrator, LinearSystems, Scene, SceneError, SolverConfig, SolverKind};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::explicit::Explicit;
use crate::solver::report::SolverReport;
use crate::solver::stepper::Stepper;
use checkpoint::{Checkpoint, Kept, ParticleState};
use recorders::{Moment, Recorders};
use std::path::{Path, PathBuf};
use std::time::Instant;
use summary::{DivergenceReport, ResumedFrom, StageSummary, Status, Summary};

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Scene(#[from] SceneError),
    #[error("cannot write outputs: {0}")]
    Io(#[from] std::io::Error),
    /// A checkpoint to restart from that cannot be used (unreadable, of another
    /// format version, damaged, or of another scene).
    #[error("{0}")]
    Checkpoint(String),
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
    /// Continue from this checkpoint instead of starting at t = 0.
    pub restart: Option<PathBuf>,
}

/// What a run checks before it allocates and steps: the memory estimate, then the
/// model's build (a body that holds no particle, an absorbing face with no
/// material, …). `mpm check` calls it, so it rejects what `mpm run` would.
pub fn set_up_check(scene: &Scene, opts: &RunOptions) -> Result<(), SceneError> {
    check_memory(scene, opts)?;
    match scene.config.dimension.spatial() {
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

/// A checkpoint to continue from, and where it was read.
struct Resume {
    checkpoint: Checkpoint,
    path: PathBuf,
}

/// The checkpoint at `path`, if it was written by a run of this scene (the same
/// text after overrides, hence the same dimension) and this build can read it.
fn matching_checkpoint(scene: &Scene, path: &Path) -> Result<Checkpoint, RunError> {
    let ck = Checkpoint::read(path).map_err(RunError::Checkpoint)?;
    let name = path.display();
    if ck.dimension != scene.config.dimension.spatial() {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} is of a {}D run, {} is {}D",
            ck.dimension,
            scene.file,
            scene.config.dimension.spatial()
        )));
    }
    if ck.scene_text != scene.text {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} was written by a run of another scene ({}, or other --set \
             overrides): restart with the scene text and overrides it was written with",
            ck.scene_file
        )));
    }
    Ok(ck)
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
    checkpoints: Checkpoints,
}

/// When checkpoints are due and which ones are kept.
struct Checkpoints {
    /// Simulation time between checkpoints, and when the next is due.
    interval: Option<f64>,
    next: f64,
    /// Wall-clock seconds between checkpoints, and when the last was written.
    wall_seconds: Option<f64>,
    last_written: Instant,
    kept: Kept,
}

/// What a checkpoint records about the stage under way and the run around it.
struct StageContext<'a> {
    scene: &'a Scene,
    index: usize,
    start: f64,
    first_step: usize,
    done: &'a [StageSummary],
    /// The stage's duration when it is quasi-static (its load factor is reported).
    quasi_static: Option<f64>,
    strength_factor: f64,
    dt_critical: f64,
}

impl<'a> StageContext<'a> {
    fn quasi_static(sc: &SolverConfig) -> Option<f64> {
        (sc.kind == SolverKind::Implicit && sc.integrator() == Integrator::QuasiStatic)
            .then_some(sc.end_time)
    }
}

impl Timeline {
    fn moment<'a, const D: usize>(&self, model: &'a Model<D>) -> Moment<'a, D> {
        Moment {
            model,
            t: self.t,
            external_work: self.external_work,
        }
    }

    /// Advance the stage of `ctx`, of length `duration`, from where it is (its
    /// last step `last_dt`, 0 at its start): step, record, write a checkpoint
    /// when one is due, repeat. Returns how the stage ended and its last step;
    /// the outer error is an output failure.
    fn stage<const D: usize>(
        &mut self,
        ctx: &StageContext,
        model: &mut Model<D>,
        stepper: &mut dyn Stepper<D>,
        duration: f64,
        mut last_dt: f64,
    ) -> std::io::Result<(Result<(), Divergence>, f64)> {
        let end = ctx.start + duration;
        while self.t < end - 1e-12 * self.total_time {
            let dt = stepper.dt(model).min(end - self.t);
            last_dt = dt;
            // A step too small to move the clock would never end the stage.
            if !(dt > 0.0 && self.t + dt > self.t) {
                return Ok((Err(stalled(self.step, self.t, dt)), last_dt));
            }
            let result = stepper.step(model, self.t, dt, self.step);
            self.recorders.newton(&stepper.take_newton_rows())?;
            self.recorders.contact(&stepper.take_contact());
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
            let signal = interrupt::requested();
            if signal.is_some() || self.checkpoint_due() {
                self.checkpoint(ctx, model, stepper, last_dt)?;
            }
            if let Some(signal) = signal {
                self.interrupted = Some(signal);
                return Ok((Ok(()), last_dt));
            }
        }
        self.t = end;
        Ok((Ok(()), last_dt))
    }

    /// Whether a checkpoint is due now (by simulation time or wall clock); the
    /// next one by time is then set past now.
    fn checkpoint_due(&mut self) -> bool {
        let c = &mut self.checkpoints;
        let tolerance = 1e-12 * self.total_time;
        let by_time = match c.interval {
            Some(interval) if self.t >= c.next - tolerance => {
                while c.next <= self.t + tolerance {
                    c.next += interval;
                }
                true
            }
            _ => false,
        };
        let by_clock = c
            .wall_seconds
            .is_some_and(|s| c.last_written.elapsed().as_secs_f64() >= s);
        by_time || by_clock
    }

    /// Write the checkpoint of this moment into the output directory, keeping
    /// the last two.
    fn checkpoint<const D: usize>(
        &mut self,
        ctx: &StageContext,
        model: &Model<D>,
        stepper: &dyn Stepper<D>,
        last_dt: f64,
    ) -> std::io::Result<()> {
        let ck = Checkpoint {
            scene_file: ctx.scene.file.clone(),
            scene_text: ctx.scene.text.clone(),
            dimension: D,
            stage: ctx.index,
            stage_start: ctx.start,
            stage_first_step: ctx.first_step,
            stages_done: ctx.done.to_vec(),
            time: self.t,
            step: self.step,
            dt: last_dt,
            load_factor: ctx
                .quasi_static
                .map(|d| ((self.t - ctx.start) / d).clamp(0.0, 1.0)),
            strength_factor: ctx.strength_factor,
            external_work: self.external_work,
            dt_critical: ctx.dt_critical,
            next_checkpoint: self.checkpoints.next,
            particles: ParticleState::of(&model.particles),
            solver: stepper.state(),
            recorders: self.recorders.saved()?,
        };
        let path = (self.recorders.directory()).join(checkpoint::file_name(self.step));
        ck.write(&path)?;
        self.checkpoints.kept.push(path);
        self.checkpoints.last_written = Instant::now();
        Ok(())
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
    resume: Option<Resume>,
) -> Result<Summary, RunError> {
    let cfg = &scene.config;
    let mut model = Model::<D>::build(scene)?;
    check_steps(scene, &model)?;
    // A search trial's factor holds for the whole run; otherwise each stage may
    // set its own (validation keeps the two apart).
    let mut strength_factor = opts.strength_factor.unwrap_or(1.0);
    if let Some(r) = &resume {
        strength_factor = r.checkpoint.strength_factor;
        model.particles = restored_particles(&r.checkpoint, &r.path, model.particles.len())?;
    }
    if strength_factor != 1.0 {
        model.reduce_strength(strength_factor);
    }
    if let (Some(g), None) = (&cfg.geostatic, &resume) {
        crate::physics::geostatic::initialise(&mut model, g);
    }
    let monitor = opts
        .monitor
        .as_deref()
        .and_then(|x| model.nearest_particle(x));
    let ck = resume.as_ref().map(|r| &r.checkpoint);
    let recorders = match &resume {
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
    let mut line = Timeline {
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
    let started = Instant::now();
    let mut outcome = check_state(&model, 0, 0.0);
    if outcome.is_ok() && resume.is_none() {
        line.recorders.state(&line.moment(&model), true)?;
    }
    let first_stage = ck.map_or(0, |c| c.stage);
    let mut stages = ck.map_or_else(Vec::new, |c| c.stages_done.clone());
    let mut last: Option<(SolverReport, f64, usize)> = None;
    // The last stage's per-particle contact forces (implicit contact only).
    let mut contact_forces: Option<Vec<Vector<D>>> = None;
    // An output that cannot be written ends the run as failed.
    let mut failure: Option<std::io::Error> = None;
    for (k, sc) in cfg.stages().into_iter().enumerate().skip(first_stage) {
        if outcome.is_err() {
            break;
        }
        // The stage a checkpoint was written in continues where it was.
        let resumed = ck.filter(|c| c.stage == k);
        if let Some(f) = sc
            .strength_reduction_factor
            .filter(|&f| f != strength_factor)
        {
            model.reduce_strength(f);
            strength_factor = f;
        }
        let (start, steps_before, last_dt) = resumed.map_or((line.t, line.step, 0.0), |c| {
            (c.stage_start, c.stage_first_step, c.dt)
        });
        // APIC's affine moments belong to the APIC stages: a stage without them
        // drops them, and an APIC stage after it forms them anew.
        if !sc.apic() {
            model.particles.affine = Vec::new();
        }
        let mut stepper = crate::solver::stepper::<D>(cfg.grid.shape_function, sc, start);
        if let Some(c) = resumed {
            stepper.restore(&c.solver);
        }
        if cfg.output.linear_systems != LinearSystems::None {
            let dir = out.join("linear_systems");
            std::fs::create_dir_all(&dir)?;
            stepper.export_linear_systems(&dir, cfg.output.linear_systems);
        }
        let stage_clock = Instant::now();
        let ctx = StageContext {
            scene,
            index: k,
            start,
            first_step: steps_before,
            done: &stages,
            quasi_static: StageContext::quasi_static(sc),
            strength_factor,
            dt_critical,
        };
        let ended = line.stage(&ctx, &mut model, stepper.as_mut(), sc.end_time, last_dt);
        let (result, dt) = match ended {
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
        contact_forces = stepper.contact_forces(model.particles.len());
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
        axisymmetric: cfg.dimension.is_axisymmetric(),
        shape_function: cfg.grid.shape_function,
        particles,
        steps: line.step,
        dt,
        dt_critical,
        end_time: line.t,
        wall_seconds: wall,
        particle_steps_per_second: (particles * (line.step - first_step)) as f64 / wall.max(1e-9),
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
        resumed_from: resume.as_ref().map(|r| ResumedFrom {
            checkpoint: r.path.display().to_string(),
            step: r.checkpoint.step,
            time: r.checkpoint.time,
        }),
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
            let mut extra: Vec<(&str, &[f64])> =
                eps_p.iter().map(|e| ("eps_p", e.as_slice())).collect();
            // Implicit contact with rigid bodies: each particle's contact force.
            let components: Vec<Vec<f64>> = (contact_forces.iter())
                .flat_map(|f| (0..D).map(move |d| f.iter().map(|v| v[d]).collect()))
                .collect();
            let names = ["contact_fx", "contact_fy", "contact_fz"];
            extra.extend(
                names
                    .iter()
                    .zip(&components)
                    .map(|(n, c)| (*n, c.as_slice())),
            );
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

/// The particles of a checkpoint, which must be as many as the scene builds.
fn restored_particles<const D: usize>(
    ck: &Checkpoint,
    path: &Path,
    built: usize,
) -> Result<crate::model::particles::Particles<D>, RunError> {
    let name = path.display();
    let p = (ck.particles.particles::<D>())
        .map_err(|e| RunError::Checkpoint(format!("checkpoint {name}: {e}")))?;
    if p.len() != built {
        return Err(RunError::Checkpoint(format!(
            "checkpoint {name} holds {} particles, the scene builds {built}",
            p.len()
        )));
    }
    Ok(p)
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
