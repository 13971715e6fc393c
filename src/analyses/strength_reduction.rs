//! Factor of safety by strength reduction (Griffiths & Lane 1999).
//!
//! A trial with factor F re-creates every frictional material with c/F, tan φ/F
//! and tan ψ/F (`Material::with_reduced_strength`) and runs the scene's stages
//! from the start (normally: quasi-static gravity loading, after an optional
//! geostatic initialisation). The trial fails when
//! 1. Newton does not converge in a step even after the solver's cut-backs
//!    (`max_cutbacks` halvings): no equilibrium was found under the reduced
//!    strength, the criterion of Griffiths & Lane; or
//! 2. the particle nearest to `monitor` has moved further than
//!    `max_displacement` (when given): a converged but runaway mechanism.
//!
//! The search takes [F_low, F_high] as a presumed bracket (F_low holds, F_high
//! fails) and bisects it until the bracket [stable F, failed F] is narrower
//! than `tolerance`, running a presumed end only when the bracket has closed
//! on it (so a range that brackets the factor costs two trials fewer); an end
//! that turns out wrong widens the range beyond it (F_low divided or F_high
//! multiplied by 1.25) and the bisection goes on there. The factor of safety is the
//! middle of the bracket. Each trial writes its own outputs under `trials/`;
//! `strength_reduction.csv` lists the trials and summary.json carries
//! `factor_of_safety`, `factor_of_safety_bracket` and where the mechanism is
//! (the equivalent plastic strain `eps_p` of the last stable and the first failed
//! trial, in their ParaView frames and the stable one's particles_final.csv).

use crate::output::{write_json, CsvWriter, Field};
use crate::run::checkpoint::ParticleState;
use crate::run::summary::Summary;
use crate::run::{run, RunError, RunOptions};
use crate::scene::{BodyKindName, Integrator, Scene, SolverKind};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Growth of the search interval while F_low fails or F_high holds.
const WIDEN: f64 = 1.25;

/// How a trial ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, strum::IntoStaticStr)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum TrialStatus {
    Stable,
    /// Newton did not converge after the cut-backs.
    FailedNewton,
    /// The monitored point moved further than `max_displacement`.
    FailedDisplacement,
}

impl TrialStatus {
    pub fn failed(self) -> bool {
        self != TrialStatus::Stable
    }
}

/// One trial of the search: a row of strength_reduction.csv and an entry of
/// summary.json's `trials`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    pub factor: f64,
    pub status: TrialStatus,
    pub steps: usize,
    pub newton_iterations: usize,
    pub cutbacks: usize,
    pub monitor_displacement: Option<f64>,
    pub wall_seconds: f64,
    /// Its output directory, relative to the search's (`trials/NN_F…`).
    pub dir: String,
    /// The stable trial whose end state it started from (none: the scene's
    /// initial state).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<String>,
    /// Why it failed (empty when stable).
    pub message: String,
}

/// How the search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchStatus {
    Completed,
    /// No [stable F, failed F] bracket within `max_trials`.
    NoBracket,
}

/// summary.json of a strength-reduction search.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SearchSummary {
    pub scene: String,
    /// Always `strength_reduction`.
    pub analysis: String,
    pub failure_criterion: String,
    pub trials: Vec<Trial>,
    pub newton_iterations: usize,
    pub steps: usize,
    pub wall_seconds: f64,
    /// Output directories of the last stable and the first failed trial (their
    /// `eps_p` shows the mechanism).
    pub mechanism_stable: Option<String>,
    pub mechanism_failed: Option<String>,
    pub particles: usize,
    /// Whether the trials started from the last stable trial's end state.
    pub continuation: bool,
    pub status: SearchStatus,
    /// The middle of the bracket.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety_bracket: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    #[error(transparent)]
    Run(#[from] RunError),
    #[error("cannot write outputs: {0}")]
    Io(#[from] std::io::Error),
    /// No bracket was found; the summary (also in summary.json) lists the trials.
    #[error("{message}")]
    NoBracket {
        message: String,
        summary: Box<SearchSummary>,
    },
}

const CSV_COLUMNS: [&str; 9] = [
    "factor",
    "status",
    "steps",
    "newton_iterations",
    "cutbacks",
    "monitor_displacement",
    "wall_seconds",
    "dir",
    "from",
];

/// Where a trial starts when it continues: the end state of the stable trial
/// `dir` at `factor` (module docs).
#[derive(Clone)]
pub struct Start {
    pub factor: f64,
    pub dir: String,
    pub particles: Arc<ParticleState>,
}

/// Whether the trials of `scene` may continue from each other, and if not, why:
/// the scene is one implicit quasi-static stage (a staged scene's trial re-runs
/// its stages) whose bodies carry no state besides their particles (continuum
/// bodies only, no contact).
pub fn continues(scene: &Scene) -> Result<(), &'static str> {
    let cfg = &scene.config;
    let Some(s) = cfg.solver.as_ref().filter(|_| cfg.stages.is_empty()) else {
        return Err("a staged scene's trials re-run its stages");
    };
    if s.kind != SolverKind::Implicit || s.integrator() != Integrator::QuasiStatic {
        return Err("only a quasi-static implicit solver is in equilibrium at its end");
    }
    // The implicit contact keeps state in the stepper (its contact points and
    // tangential forces), which a trial's end state does not carry.
    let plain = (0..cfg.bodies.len()).all(|i| cfg.body_kind(i) == BodyKindName::Continuum);
    if !plain || !cfg.contacts.is_empty() {
        return Err("rigid and peridynamic bodies and contact keep state besides the particles");
    }
    Ok(())
}

/// Run one trial with the strengths divided by `factor` into `out/dir`, from
/// the scene's initial state or, with `from`, from a stable trial's end state;
/// also returns the run's summary (with its end state when `keep`).
pub fn trial(
    scene: &Scene,
    out: &Path,
    dir: &str,
    factor: f64,
    from: Option<&Start>,
    keep: bool,
) -> Result<(Trial, Summary), RunError> {
    let cfg = scene.config.strength_reduction.as_ref().expect("caller");
    let opts = RunOptions {
        progress: false,
        strength_factor: Some(factor),
        monitor: cfg.monitor.clone(),
        start_from: from.map(|s| s.particles.clone()),
        keep_final_particles: keep,
        ..Default::default()
    };
    let started = Instant::now();
    let (summary, mut status, message) = match run(scene, &out.join(dir), &opts) {
        Ok(s) => (s, TrialStatus::Stable, String::new()),
        Err(RunError::Diverged { message, summary }) => {
            (*summary, TrialStatus::FailedNewton, message)
        }
        Err(e) => return Err(e),
    };
    let moved = summary.monitor_displacement;
    if let (TrialStatus::Stable, Some(d), Some(limit)) = (status, moved, cfg.max_displacement) {
        if d > limit {
            status = TrialStatus::FailedDisplacement;
        }
    }
    let trial = Trial {
        factor,
        status,
        steps: summary.steps,
        newton_iterations: summary.solver.newton_iterations.unwrap_or(0),
        cutbacks: summary.solver.cutbacks.unwrap_or(0),
        monitor_displacement: moved,
        wall_seconds: started.elapsed().as_secs_f64(),
        dir: dir.to_string(),
        from: from.map(|s| s.dir.clone()),
        message,
    };
    Ok((trial, summary))
}

/// A trial gives up once Newton's residual has risen in this many consecutive
/// iterations (`[solver] max_rising_iterations`, unless the scene sets it).
pub const TRIAL_RISING_ITERATIONS: usize = 2;

/// A trial gives up once Newton's residual has fallen by less than 10 % over
/// this many iterations (`[solver] stall_iterations`, unless the scene sets it).
pub const TRIAL_STALL_ITERATIONS: usize = 10;

/// The scene as its trials run it: every implicit stage with the trial's
/// `max_rising_iterations` and `stall_iterations` unless the scene gives its own.
fn trial_scene(scene: &Scene) -> Scene {
    let mut trial = scene.clone();
    let cfg = &mut trial.config;
    for s in cfg.solver.iter_mut().chain(cfg.stages.iter_mut()) {
        if s.kind == SolverKind::Implicit {
            s.max_rising_iterations
                .get_or_insert(TRIAL_RISING_ITERATIONS);
            s.stall_iterations.get_or_insert(TRIAL_STALL_ITERATIONS);
        }
    }
    trial
}

/// Search for the factor of safety; outputs into `out` (module docs).
pub fn search(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<SearchSummary, SearchError> {
    let scene = &trial_scene(scene);
    let cfg = scene.config.strength_reduction.as_ref().expect("caller");
    let started = Instant::now();
    std::fs::create_dir_all(out)?;
    let mut csv = CsvWriter::create(&out.join("strength_reduction.csv"), &CSV_COLUMNS)?;
    let mut trials: Vec<Trial> = Vec::new();
    let mut particles = 0;
    let continuation = cfg.continuation() && continues(scene).is_ok();
    // The stable trial with the largest factor, when the trials continue.
    let mut last_stable: Option<Start> = None;
    let mut run_trial = |factor: f64, trials: &mut Vec<Trial>| -> Result<bool, SearchError> {
        let dir = format!("trials/{:02}_F{factor:.4}", trials.len());
        let from = last_stable.as_ref().filter(|s| s.factor < factor);
        let (t, summary) = trial(scene, out, &dir, factor, from, continuation)?;
        particles = summary.particles;
        if let (TrialStatus::Stable, Some(p)) = (t.status, summary.final_particles) {
            if last_stable.as_ref().is_none_or(|s| s.factor < factor) {
                last_stable = Some(Start {
                    factor,
                    dir: dir.clone(),
                    particles: p,
                });
            }
        }
        let name = Path::new(&t.dir)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        csv.row([
            Field::from(t.factor),
            Field::Text(t.status.into()),
            t.steps.into(),
            t.newton_iterations.into(),
            t.cutbacks.into(),
            t.monitor_displacement.into(),
            t.wall_seconds.into(),
            Field::Text(&name),
            Field::Text(
                t.from
                    .as_deref()
                    .and_then(|f| f.strip_prefix("trials/"))
                    .unwrap_or(""),
            ),
        ])?;
        csv.flush()?;
        if opts.progress {
            eprintln!(
                "strength reduction: F = {factor:.4} {} ({} steps, {} Newton iterations, {} cut-backs, {:.1} s{})",
                match t.status {
                    TrialStatus::Stable => "holds",
                    TrialStatus::FailedNewton => "fails (Newton)",
                    TrialStatus::FailedDisplacement => "fails (displacement)",
                },
                t.steps,
                t.newton_iterations,
                t.cutbacks,
                t.wall_seconds,
                match &t.from {
                    Some(f) => format!(", from {f}"),
                    None => String::new(),
                }
            );
        }
        let failed = t.status.failed();
        trials.push(t);
        Ok(failed)
    };
    // The search range is a presumed bracket: `lo` holds and `hi` fails until
    // a trial says otherwise. Bisect it, and run a presumed end only when the
    // bracket has closed on it; one that turns out wrong widens the range
    // beyond it (by WIDEN) and the bisection goes on there.
    let (mut lo, mut hi) = (cfg.search[0], cfg.search[1]);
    let (mut stable, mut failed): (Option<f64>, Option<f64>) = (None, None);
    let budget = cfg.max_trials();
    while trials.len() < budget {
        let (s, f) = (stable.unwrap_or(lo), failed.unwrap_or(hi));
        if f - s > cfg.tolerance() {
            let mid = 0.5 * (s + f);
            match run_trial(mid, &mut trials)? {
                true => failed = Some(mid),
                false => stable = Some(mid),
            }
        } else if stable.is_none() {
            if run_trial(lo, &mut trials)? {
                (failed, hi, lo) = (Some(lo), lo, lo / WIDEN);
            } else {
                stable = Some(lo);
            }
        } else if failed.is_none() {
            if run_trial(hi, &mut trials)? {
                failed = Some(hi);
            } else {
                (stable, lo, hi) = (Some(hi), hi, hi * WIDEN);
            }
        } else {
            break;
        }
    }
    let find = |f: Option<f64>| {
        f.and_then(|f| trials.iter().find(|t| t.factor == f))
            .map(|t| t.dir.clone())
    };
    let mut summary = SearchSummary {
        scene: scene.file.clone(),
        analysis: "strength_reduction".into(),
        failure_criterion: if cfg.max_displacement.is_some() {
            "Newton non-convergence after cut-backs, or monitored displacement above max_displacement"
        } else {
            "Newton non-convergence after cut-backs"
        }
        .into(),
        newton_iterations: trials.iter().map(|t| t.newton_iterations).sum(),
        steps: trials.iter().map(|t| t.steps).sum(),
        wall_seconds: started.elapsed().as_secs_f64(),
        mechanism_stable: find(stable),
        mechanism_failed: find(failed),
        trials,
        particles,
        continuation,
        status: SearchStatus::Completed,
        factor_of_safety: None,
        factor_of_safety_bracket: None,
        message: None,
    };
    match (stable, failed) {
        (Some(s), Some(f)) => {
            summary.factor_of_safety = Some(0.5 * (s + f));
            summary.factor_of_safety_bracket = Some([s, f]);
            write_json(&out.join("summary.json"), &summary)?;
            Ok(summary)
        }
        _ => {
            let message = format!(
                "{}: no bracket [stable F, failed F] found in {} trials (stable: {stable:?}, failed: {failed:?}); see {}",
                scene.file,
                summary.trials.len(),
                out.join("strength_reduction.csv").display()
            );
            summary.status = SearchStatus::NoBracket;
            summary.message = Some(message.clone());
            write_json(&out.join("summary.json"), &summary)?;
            Err(SearchError::NoBracket {
                message,
                summary: Box::new(summary),
            })
        }
    }
}
