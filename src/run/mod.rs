//! Running a scene: build the model, advance it to the end time, write the outputs
//! (history.csv, ParaView frames, particles_final.csv, summary.json). A divergence
//! stops the run cleanly: everything written so far is flushed and summary.json
//! records what happened where.

pub mod footing;

use crate::model::Model;
use crate::output::{
    body_centres, write_json, write_particles_csv_with, FrameWriter, HistoryWriter, Progress,
};
use crate::parallel::deterministic_sum;
use crate::run::footing::FootingCurve;
use crate::scene::SolverKind;
use crate::scene::{Scene, SceneError};
use crate::solver::divergence::{check_state, Divergence};
use crate::solver::explicit::Explicit;
use crate::solver::report::{NewtonRow, SolverReport};
use serde_json::json;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Scene(#[from] SceneError),
    #[error("cannot write outputs: {0}")]
    Io(#[from] std::io::Error),
    #[error("{0}")]
    Diverged(String),
}

/// What a finished run reports (also written to summary.json).
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub steps: usize,
    pub end_time: f64,
    pub particles: usize,
    pub wall_seconds: f64,
    pub json: serde_json::Value,
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
}

/// Run a scene, writing its outputs into `out`.
pub fn run(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<RunSummary, RunError> {
    std::fs::create_dir_all(out)?;
    match scene.config.dimension {
        2 => run_dim::<2>(scene, out, opts),
        3 => run_dim::<3>(scene, out, opts),
        d => unreachable!("validated dimension {d}"),
    }
}

/// Kinetic energy Σ ½ m |v|².
pub fn kinetic_energy<const D: usize>(m: &Model<D>) -> f64 {
    let p = &m.particles;
    deterministic_sum(p.len(), |q| 0.5 * p.mass[q] * p.v[q].norm_squared())
}

/// Stored energy Σ V_p w_p.
pub fn strain_energy<const D: usize>(m: &Model<D>) -> f64 {
    let p = &m.particles;
    deterministic_sum(p.len(), |q| {
        let mat = &m.materials[p.material[q] as usize];
        p.volume[q] * mat.strain_energy_density(&p.f[q], &p.stress[q], p.history.get(q))
    })
}

/// newton.csv, opened when the run has an implicit stage.
type NewtonLog = Option<std::io::BufWriter<std::fs::File>>;

pub const NEWTON_CSV_HEADER: &str =
    "step,time,dt,cutback,iteration,residual,increment,wall_seconds,krylov_iterations,forcing,linear_solver";

/// One row of newton.csv.
fn newton_csv(r: &NewtonRow) -> String {
    format!(
        "{},{},{},{},{},{:e},{:e},{:e},{},{:e},{}",
        r.step,
        r.time,
        r.dt,
        r.cutback,
        r.iteration,
        r.residual,
        r.increment,
        r.wall_seconds,
        r.krylov_iterations,
        r.forcing,
        r.linear_solver
    )
}

/// Write the solver fields of `report` into a summary.json object.
fn describe(report: &SolverReport, summary: &mut serde_json::Value) {
    let fields = serde_json::to_value(report).expect("a report serialises");
    if let serde_json::Value::Object(fields) = fields {
        for (key, value) in fields {
            summary[key] = value;
        }
    }
}

fn run_dim<const D: usize>(
    scene: &Scene,
    out: &Path,
    opts: &RunOptions,
) -> Result<RunSummary, RunError> {
    let cfg = &scene.config;
    let mut model = Model::<D>::build(scene)?;
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
    let stages = cfg.stages();
    let end_time = cfg.total_time();
    let n_bodies = model.n_bodies();
    let mut history = HistoryWriter::create(&out.join("history.csv"), D, n_bodies)?;
    let mut frames = FrameWriter::new(out, "particles")?;
    let mut newton_log: NewtonLog = None;
    if stages.iter().any(|s| s.kind == SolverKind::Implicit) {
        let mut log = std::io::BufWriter::new(std::fs::File::create(out.join("newton.csv"))?);
        writeln!(log, "{NEWTON_CSV_HEADER}")?;
        newton_log = Some(log);
    }
    // footing.csv: the load–settlement curve after every implicit step.
    let mut footing_curve = match &model.footing {
        Some(_) => Some(FootingCurve::create(&out.join("footing.csv"))?),
        None => None,
    };
    let mut settlement = 0.0;
    if let (Some(curve), Some(f)) = (&mut footing_curve, &model.footing) {
        curve.push(0.0, 0.0, 0.0, f.width)?;
    }
    let frame_interval = (cfg.output.frames > 0).then(|| end_time / cfg.output.frames as f64);
    let progress = opts.progress.then(|| Progress::new(end_time));
    let dt_critical = Explicit::critical_dt(&model);
    check_state(&model, 0, 0.0).map_err(|d| RunError::Diverged(d.to_string()))?;

    let started = Instant::now();
    let (mut t, mut step, mut external_work) = (0.0, 0usize, 0.0);
    let (mut next_history, mut next_frame) = (0.0, 0.0);
    let (mut last_history, mut last_frame) = (f64::NAN, f64::NAN);
    // Write a history row and a frame when they are due (or forced, at the start and
    // the end), never twice at the same time.
    let mut record =
        |model: &Model<D>, t: f64, external_work: f64, force: bool| -> std::io::Result<()> {
            if (force || t >= next_history) && t != last_history {
                last_history = t;
                let (com, vcom) = body_centres(&model.particles, n_bodies);
                history.write_row(
                    t,
                    kinetic_energy(model),
                    strain_energy(model),
                    external_work,
                    &com,
                    &vcom,
                )?;
                next_history = t + cfg.output.history_interval;
            }
            if let Some(interval) = frame_interval {
                if (force || t >= next_frame - 1e-12 * end_time) && t != last_frame {
                    last_frame = t;
                    let eps_p = model.plastic_strain();
                    let extra: Vec<(&str, &[f64])> =
                        eps_p.iter().map(|e| ("eps_p", e.as_slice())).collect();
                    frames.write_frame(t, &model.particles, &extra)?;
                    while next_frame <= t + 1e-12 * end_time {
                        next_frame += interval;
                    }
                }
            }
            Ok(())
        };
    record(&model, t, external_work, true)?;
    let mut stage_summaries = Vec::new();
    let mut outcome: Result<(), Divergence> = Ok(());
    let mut summary = json!({});
    let (mut newton_total, mut cutbacks_total, mut krylov_total) = (0u64, 0u64, 0u64);
    for (k, sc) in stages.iter().enumerate() {
        if let Some(f) = sc
            .strength_reduction_factor
            .filter(|&f| f != strength_factor)
        {
            model.reduce_strength(f);
            strength_factor = f;
        }
        let mut stepper = crate::solver::stepper::<D>(cfg.grid.shape_function, sc, t);
        let (stage_start, stage_end) = (t, t + sc.end_time);
        let (stage_clock, steps_before) = (Instant::now(), step);
        let mut last_dt = 0.0;
        outcome = loop {
            if t >= stage_end - 1e-12 * end_time {
                t = stage_end;
                break Ok(());
            }
            let dt = stepper.dt(&model).min(stage_end - t);
            last_dt = dt;
            let result = stepper.step(&mut model, t, dt, step);
            if let Some(log) = &mut newton_log {
                for row in stepper.take_newton_rows() {
                    writeln!(log, "{}", newton_csv(&row))?;
                }
                log.flush()?;
            }
            match result {
                Ok(work) => external_work += work,
                Err(d) => break Err(d),
            }
            t += dt;
            step += 1;
            if let Some(f) = &model.footing {
                settlement += f.settlement_rate() * dt;
                if let (Some(curve), Some(reaction)) = (&mut footing_curve, stepper.reaction()) {
                    curve.push(t, settlement, f.load(&model.grid, reaction), f.width)?;
                }
            }
            record(&model, t, external_work, false)?;
            if let Some(p) = &progress {
                p.set(t, step);
            }
        };
        let mut stage = json!({
            "name": sc.name.clone().unwrap_or_else(|| format!("stage{k}")),
            "start_time": stage_start,
            "end_time": t,
            "steps": step - steps_before,
            "dt": last_dt,
            "wall_seconds": stage_clock.elapsed().as_secs_f64(),
            "active_nodes_last_step": stepper.active_nodes(),
        });
        describe(&stepper.report(), &mut stage);
        if sc.strength_reduction_factor.is_some() {
            stage["strength_reduction_factor"] = json!(strength_factor);
        }
        newton_total += stage["newton_iterations"].as_u64().unwrap_or(0);
        cutbacks_total += stage["cutbacks"].as_u64().unwrap_or(0);
        krylov_total += stage["krylov_iterations"].as_u64().unwrap_or(0);
        // The top level carries the solver fields of the last stage that ran.
        describe(&stepper.report(), &mut summary);
        summary["dt"] = json!(last_dt);
        summary["active_nodes_last_step"] = json!(stepper.active_nodes());
        stage_summaries.push(stage);
        if outcome.is_err() {
            break;
        }
    }
    if let Some(p) = &progress {
        p.finish();
    }
    let wall = started.elapsed().as_secs_f64();
    let particles = model.particles.len();
    for (key, value) in [
        ("scene", json!(scene.file)),
        ("dimension", json!(D)),
        ("shape_function", json!(cfg.grid.shape_function.name())),
        ("particles", json!(particles)),
        ("steps", json!(step)),
        ("dt_critical", json!(dt_critical)),
        ("end_time", json!(t)),
        ("wall_seconds", json!(wall)),
        (
            "particle_steps_per_second",
            json!((particles * step) as f64 / wall.max(1e-9)),
        ),
        ("status", json!("completed")),
        ("stages", json!(stage_summaries)),
    ] {
        summary[key] = value;
    }
    if let (Some(curve), Some(f)) = (&footing_curve, &model.footing) {
        if let serde_json::Value::Object(fields) = curve.summary(f.cohesion) {
            for (key, value) in fields {
                summary[key] = value;
            }
        }
    }
    if newton_log.is_some() {
        summary["newton_iterations"] = json!(newton_total);
        summary["cutbacks"] = json!(cutbacks_total);
        summary["krylov_iterations"] = json!(krylov_total);
    }
    if let Some(q) = monitor {
        let p = &model.particles;
        summary["monitor_particle"] = json!(q);
        summary["monitor_displacement"] = json!((p.x[q] - p.x0[q]).norm());
    }
    if let Some(f) = opts.strength_factor {
        summary["strength_factor"] = json!(f);
    }
    if let Err(d) = outcome {
        summary["status"] = json!("diverged");
        summary["message"] = json!(d.to_string());
        summary["diverged_step"] = json!(d.step);
        summary["diverged_particle"] = json!(d.particle);
        write_json(&out.join("summary.json"), &summary)?;
        return Err(RunError::Diverged(format!(
            "{}: {d}; outputs written so far are in {}",
            scene.file,
            out.display()
        )));
    }
    record(&model, t, external_work, true)?;
    let eps_p = model.plastic_strain();
    let extra: Vec<(&str, &[f64])> = eps_p.iter().map(|e| ("eps_p", e.as_slice())).collect();
    write_particles_csv_with(&out.join("particles_final.csv"), &model.particles, &extra)?;
    write_json(&out.join("summary.json"), &summary)?;
    Ok(RunSummary {
        steps: step,
        end_time: t,
        particles,
        wall_seconds: wall,
        json: summary,
    })
}
