//! How a run finishes: summary.json from the stages' outcome (completed,
//! diverged, interrupted, or failed to write an output), and on completion the
//! last frame and particles_final.csv.

use crate::model::Model;
use crate::output::write_particles_csv_with;
use crate::run::checkpoint::{ParticleState, Resume};
use crate::run::error::RunError;
use crate::run::interrupt;
use crate::run::options::RunOptions;
use crate::run::setup::SetUp;
use crate::run::stages::Ran;
use crate::run::summary::{DivergenceReport, ResumedFrom, StageSummary, Status, Summary};
use crate::scene::{Scene, SolverKind};
use crate::solver::report::SolverReport;
use std::path::Path;

/// The summary of the run set up as `run` whose stages went as `ran`, in
/// `wall` seconds of stepping.
pub(super) fn summary<const D: usize>(
    scene: &Scene,
    opts: &RunOptions,
    resume: Option<&Resume>,
    run: &SetUp<D>,
    ran: &mut Ran<D>,
    wall: f64,
) -> Summary {
    let cfg = &scene.config;
    let (model, line) = (&run.model, &run.line);
    let particles = model.particles.len();
    // A run that stopped before its first step reports its first stage's solver.
    let (solver, dt, active_nodes) = ran.last.take().unwrap_or_else(|| {
        let first = cfg.stages()[0];
        let report = crate::solver::stepper::<D>(cfg.grid.shape_function, first, 0.0).report();
        (report, 0.0, 0)
    });
    let implicit = cfg.stages().iter().any(|s| s.kind == SolverKind::Implicit);
    let monitor = run.monitor;
    Summary {
        scene: scene.file.clone(),
        dimension: D,
        axisymmetric: cfg.dimension.is_axisymmetric(),
        shape_function: cfg.grid.shape_function,
        particles,
        steps: line.step,
        dt,
        dt_critical: run.dt_critical,
        end_time: line.t,
        wall_seconds: wall,
        particle_steps_per_second: (particles * (line.step - run.first_step)) as f64
            / wall.max(1e-9),
        active_nodes_last_step: active_nodes,
        status: Status::Completed,
        message: None,
        divergence: None,
        solver: run_totals(solver, &ran.stages, implicit),
        warnings: ran.stages.iter().flat_map(|s| s.warnings.clone()).collect(),
        stages: std::mem::take(&mut ran.stages),
        footing: line.recorders.footing_summary(model),
        monitor_particle: monitor,
        monitor_displacement: (monitor.and_then(|b| model.particle_built_as(b)))
            .map(|q| (model.particles.x[q] - model.particles.x0[q]).norm()),
        strength_factor: opts.strength_factor,
        resumed_from: resume.map(|r| ResumedFrom {
            checkpoint: r.path.display().to_string(),
            step: r.checkpoint.step,
            time: r.checkpoint.time,
        }),
        final_particles: (opts.keep_final_particles)
            .then(|| std::sync::Arc::new(ParticleState::of(&model.particles))),
    }
}

/// Write summary.json with the run's outcome and, when the stages ended
/// without a divergence, the last frame and particles_final.csv; a run that
/// did not complete comes back as its error, carrying the summary.
pub(super) fn finish<const D: usize>(
    scene: &Scene,
    out: &Path,
    run: &mut SetUp<D>,
    ran: Ran<D>,
    mut summary: Summary,
) -> Result<Summary, RunError> {
    let summary_path = out.join("summary.json");
    if let Some(e) = ran.failure {
        return Err(failed(summary, &summary_path, e));
    }
    if let Err(d) = ran.outcome {
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
    let written = final_outputs(out, run, ran.contact_forces.as_deref());
    if let Err(e) = written {
        return Err(failed(summary, &summary_path, e));
    }
    let line = &run.line;
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

/// The last state's records (the last frame, history) and particles_final.csv,
/// with the plastic strain and, from implicit contact with rigid bodies, each
/// particle's contact force.
fn final_outputs<const D: usize>(
    out: &Path,
    run: &mut SetUp<D>,
    contact_forces: Option<&[crate::dim::Vector<D>]>,
) -> std::io::Result<()> {
    let (model, line): (&Model<D>, _) = (&run.model, &mut run.line);
    line.recorders.state(&line.moment(model), None, true)?;
    let fields = model.point_fields();
    let mut extra: Vec<(&str, &[f64])> = (fields.iter()).map(|(n, v)| (*n, v.as_slice())).collect();
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
    write_particles_csv_with(
        &out.join("particles_final.csv"),
        &model.output_particles(),
        &extra,
    )
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
