//! The stage loop of a run: each stage's stepper built from its settings and
//! driven step by step to the stage's end, recording as it goes and writing a
//! checkpoint when one is due or a signal asks for it.

use crate::dim::Vector;
use crate::model::staging::StageChanges;
use crate::model::Model;
use crate::output::Progress;
use crate::run::checkpoint::{self, Checkpoint, Kept, ParticleState};
use crate::run::interrupt;
use crate::run::recorders::{Moment, Recorders};
use crate::run::summary::StageSummary;
use crate::scene::{Integrator, LinearSystems, Scene, SolverConfig, SolverKind};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::report::SolverReport;
use crate::solver::stepper::Stepper;
use std::path::Path;
use std::time::Instant;

/// The run's course: where it is (time, step, the work done so far) and what it
/// writes as it goes.
pub(super) struct Timeline {
    pub t: f64,
    pub step: usize,
    pub external_work: f64,
    /// The run's total time (the time tolerance is relative to it).
    pub total_time: f64,
    pub recorders: Recorders,
    pub progress: Option<Progress>,
    /// The signal that stopped the run at the end of a step, if one did.
    pub interrupted: Option<i32>,
    pub checkpoints: Checkpoints,
}

/// When checkpoints are due and which ones are kept.
pub(super) struct Checkpoints {
    /// Simulation time between checkpoints, and when the next is due.
    pub interval: Option<f64>,
    pub next: f64,
    /// Wall-clock seconds between checkpoints, and when the last was written.
    pub wall_seconds: Option<f64>,
    pub last_written: Instant,
    pub kept: Kept,
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
    pub(super) fn moment<'a, const D: usize>(&self, model: &'a Model<D>) -> Moment<'a, D> {
        Moment {
            model,
            t: self.t,
            step: self.step,
            external_work: self.external_work,
        }
    }

    /// Advance the stage of `ctx`, of length `duration`, from where it is (its
    /// last step `last_dt`, 0 at its start): record, step, write a checkpoint
    /// when one is due, repeat. The state before a step is recorded knowing the
    /// step's length, so that each output time is taken at its nearest step
    /// (`run::schedule`). Returns how the stage ended and the last step the
    /// stepper asked for (the last one taken may be shortened to end the stage
    /// there); the outer error is an output failure.
    fn stage<const D: usize>(
        &mut self,
        ctx: &StageContext,
        model: &mut Model<D>,
        stepper: &mut dyn Stepper<D>,
        duration: f64,
        mut last_dt: f64,
    ) -> std::io::Result<(Result<(), Divergence>, f64)> {
        let end = ctx.start + duration;
        let tolerance = 1e-12 * self.total_time;
        while self.t < end - tolerance {
            let asked = stepper.dt(model);
            let (dt, last) = fit_to_end(asked, end - self.t, tolerance);
            last_dt = asked;
            // A step too small to move the clock would never end the stage.
            if !(dt > 0.0 && self.t + dt > self.t) {
                return Ok((Err(stalled(self.step, self.t, dt)), last_dt));
            }
            // The step's pore pressures, at the step-start positions.
            model.update_pore_pressure();
            self.recorders.state(&self.moment(model), Some(dt), false)?;
            let result = stepper.step(model, self.t, dt, self.step);
            self.recorders.newton(&stepper.take_newton_rows())?;
            self.recorders.contact(&stepper.take_contact());
            match result {
                Ok(work) => self.external_work += work,
                Err(d) => return Ok((Err(d), last_dt)),
            }
            self.t = if last { end } else { self.t + dt };
            self.step += 1;
            self.recorders
                .footing(model, self.t, dt, stepper.reaction())?;
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
            broken_bonds: (model.peridynamics.as_ref())
                .map_or_else(Vec::new, |pd| pd.broken_bonds()),
            peridynamic_stress: (model.peridynamics.as_ref())
                .map_or_else(Vec::new, |pd| pd.stress_states()),
            staged_particles: (model.staging.as_ref()).map(|s| s.built.clone()),
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

/// A step shorter than this fraction of the one asked for is merged into the
/// step before it, which then ends the stage at most 0.1 % longer than asked
/// (a fixed Δt that does not divide the stage leaves, after Σ Δt's round-off,
/// a sliver step of 1e-12 s; issue 56).
const SLIVER: f64 = 1e-3;

/// The step `asked` fitted to the `left` of the stage, and whether it ends the
/// stage: one that reaches the end (within the clock's `tolerance`), passes
/// it, or would leave less than a sliver of it, ends exactly there.
fn fit_to_end(asked: f64, left: f64, tolerance: f64) -> (f64, bool) {
    if left - asked <= tolerance {
        (asked.min(left), true)
    } else if left - asked < SLIVER * asked {
        (left, true)
    } else {
        (asked, false)
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

/// How the stages went: the outcome, each stage's summary, the last stage's
/// solver report, step and active nodes, its per-particle contact forces
/// (`Stepper::contact_forces`), and an output that could not be written.
pub(super) struct Ran<const D: usize> {
    pub outcome: Result<(), Divergence>,
    pub stages: Vec<StageSummary>,
    pub last: Option<(SolverReport, f64, usize)>,
    pub contact_forces: Option<Vec<Vector<D>>>,
    pub failure: Option<std::io::Error>,
}

/// The run's stages from the first (or the one a checkpoint `ck` was written
/// in) to the end: the model's initial state checked and recorded, then each
/// stage's stepper built and driven ([`Timeline::stage`]). The error is an
/// output that could not be written before the stepping began (the initial
/// state, the linear systems' folder); one that fails while stepping ends the
/// stages with `Ran::failure`.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_stages<const D: usize>(
    scene: &Scene,
    out: &Path,
    model: &mut Model<D>,
    line: &mut Timeline,
    strength_factor: &mut f64,
    dt_critical: f64,
    ck: Option<&Checkpoint>,
) -> std::io::Result<Ran<D>> {
    let cfg = &scene.config;
    let mut outcome = check_state(model, 0, 0.0);
    if outcome.is_ok() && ck.is_none() {
        line.recorders.state(&line.moment(model), None, true)?;
    }
    let first_stage = ck.map_or(0, |c| c.stage);
    let mut stages = ck.map_or_else(Vec::new, |c| c.stages_done.clone());
    let mut last: Option<(SolverReport, f64, usize)> = None;
    // The last stage's per-particle contact forces (`Stepper::contact_forces`).
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
            .filter(|&f| f != *strength_factor)
        {
            model.reduce_strength(f);
            *strength_factor = f;
        }
        if resumed.is_none() && !cfg.stages.is_empty() {
            outcome = change_model(model, cfg, k, line)?;
            if outcome.is_err() {
                break;
            }
        }
        let (mut stepper, start, steps_before, last_dt) =
            stage_stepper(scene, out, sc, resumed, model, line)?;
        let name = sc.name.clone().unwrap_or_else(|| format!("stage{k}"));
        let warnings = stage_warnings(scene, &name, stepper.as_ref(), model);
        let stage_clock = Instant::now();
        let ctx = StageContext {
            scene,
            index: k,
            start,
            first_step: steps_before,
            done: &stages,
            quasi_static: StageContext::quasi_static(sc),
            strength_factor: *strength_factor,
            dt_critical,
        };
        let ended = line.stage(&ctx, model, stepper.as_mut(), sc.end_time, last_dt);
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
            name,
            start_time: start,
            end_time: line.t,
            steps: line.step - steps_before,
            dt,
            wall_seconds: stage_clock.elapsed().as_secs_f64(),
            active_nodes_last_step: stepper.active_nodes(),
            solver: report.clone(),
            strength_reduction_factor: sc.strength_reduction_factor.map(|_| *strength_factor),
            warnings,
        });
        last = Some((report, dt, stepper.active_nodes()));
        contact_forces = stepper.contact_forces(model);
        if line.interrupted.is_some() {
            break;
        }
    }
    Ok(Ran {
        outcome,
        stages,
        last,
        contact_forces,
        failure,
    })
}

/// Stage k's changes of the model at its start (`model::staging`); a stage
/// that leaves no particle stops the run (the inner error). The outer error
/// is an output that could not be written.
fn change_model<const D: usize>(
    model: &mut Model<D>,
    cfg: &crate::scene::SceneConfig,
    k: usize,
    line: &mut Timeline,
) -> std::io::Result<Result<(), Divergence>> {
    let changes = StageChanges::of(cfg, k);
    if changes.is_empty() {
        return Ok(Ok(()));
    }
    // The state the last stage ended in is recorded before it changes (with
    // no step between: it is the nearest to an output time due now).
    line.recorders
        .state(&line.moment(model), Some(0.0), false)?;
    model.change(&changes);
    Ok(match model.particles.is_empty() {
        false => Ok(()),
        true => Err(Divergence {
            step: line.step,
            time: line.t,
            particle: None,
            message: format!(
                "stage {k} leaves no particle in the model (its deactivate and excavate)"
            ),
        }),
    })
}

/// What stage `name` warns of at its start (`Stepper::step_warning`; named
/// when the scene has [[stage]]s), said on stderr at once and kept for
/// summary.json.
fn stage_warnings<const D: usize>(
    scene: &Scene,
    name: &str,
    stepper: &dyn Stepper<D>,
    model: &Model<D>,
) -> Vec<String> {
    let staged = !scene.config.stages.is_empty();
    let warnings: Vec<String> = (stepper.step_warning(model).into_iter())
        .map(|w| match staged {
            true => format!("stage {name}: {w}"),
            false => w,
        })
        .collect();
    for w in &warnings {
        eprintln!("warning: {}: {w}", scene.file);
    }
    warnings
}

/// The stepper of stage `sc` and where the stage starts: its start time, its
/// first step and the last Δt taken (those of the checkpoint `resumed` it
/// continues, else now and 0). APIC's affine moments belong to the APIC
/// stages: a stage without them drops them, and an APIC stage after it forms
/// them anew.
fn stage_stepper<const D: usize>(
    scene: &Scene,
    out: &Path,
    sc: &SolverConfig,
    resumed: Option<&Checkpoint>,
    model: &mut Model<D>,
    line: &Timeline,
) -> std::io::Result<(Box<dyn Stepper<D>>, f64, usize, f64)> {
    let cfg = &scene.config;
    let (start, steps_before, last_dt) = resumed.map_or((line.t, line.step, 0.0), |c| {
        (c.stage_start, c.stage_first_step, c.dt)
    });
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
    Ok((stepper, start, steps_before, last_dt))
}
