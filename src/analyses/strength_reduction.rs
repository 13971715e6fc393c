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
//! The search first makes sure that F_low holds and F_high fails (dividing F_low
//! or multiplying F_high by 1.25 until it does), then bisects until the bracket
//! [stable F, failed F] is narrower than `tolerance`. The factor of safety is the
//! middle of the bracket. Each trial writes its own outputs under `trials/`;
//! `strength_reduction.csv` lists the trials and summary.json carries
//! `factor_of_safety`, `factor_of_safety_bracket` and where the mechanism is
//! (the equivalent plastic strain `eps_p` of the last stable and the first failed
//! trial, in their ParaView frames and the stable one's particles_final.csv).

use crate::output::write_json;
use crate::run::{run, RunError, RunOptions, RunSummary};
use crate::scene::Scene;
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Growth of the search interval while F_low fails or F_high holds.
const WIDEN: f64 = 1.25;

/// What made a trial fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// Newton did not converge after the cut-backs.
    Newton,
    /// The monitored point moved further than `max_displacement`.
    Displacement,
}

/// One trial of the search.
#[derive(Clone, Debug)]
pub struct Trial {
    pub factor: f64,
    pub failure: Option<Failure>,
    pub steps: u64,
    pub newton_iterations: u64,
    pub cutbacks: u64,
    pub monitor_displacement: Option<f64>,
    pub wall_seconds: f64,
    pub dir: PathBuf,
    pub message: String,
}

impl Trial {
    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{}",
            self.factor,
            match self.failure {
                None => "stable",
                Some(Failure::Newton) => "failed_newton",
                Some(Failure::Displacement) => "failed_displacement",
            },
            self.steps,
            self.newton_iterations,
            self.cutbacks,
            self.monitor_displacement
                .map_or(String::new(), |d| d.to_string()),
            self.wall_seconds,
            self.dir.file_name().unwrap().to_string_lossy()
        )
    }
}

const CSV_HEADER: &str =
    "factor,status,steps,newton_iterations,cutbacks,monitor_displacement,wall_seconds,dir";

/// Run one trial with the strengths divided by `factor` into `dir`.
pub fn trial(scene: &Scene, dir: &Path, factor: f64) -> Result<Trial, RunError> {
    let cfg = scene.config.strength_reduction.as_ref().expect("caller");
    let opts = RunOptions {
        progress: false,
        strength_factor: Some(factor),
        monitor: cfg.monitor.clone(),
    };
    let started = Instant::now();
    let (json, mut failure, message) = match run(scene, dir, &opts) {
        Ok(s) => (s.json, None, String::new()),
        Err(RunError::Diverged(m)) => {
            let text = std::fs::read_to_string(dir.join("summary.json"))?;
            let json = serde_json::from_str(&text).map_err(std::io::Error::other)?;
            (json, Some(Failure::Newton), m)
        }
        Err(e) => return Err(e),
    };
    let monitor_displacement = json["monitor_displacement"].as_f64();
    if let (None, Some(d), Some(limit)) = (failure, monitor_displacement, cfg.max_displacement) {
        if d > limit {
            failure = Some(Failure::Displacement);
        }
    }
    Ok(Trial {
        factor,
        failure,
        steps: json["steps"].as_u64().unwrap_or(0),
        newton_iterations: json["newton_iterations"].as_u64().unwrap_or(0),
        cutbacks: json["cutbacks"].as_u64().unwrap_or(0),
        monitor_displacement,
        wall_seconds: started.elapsed().as_secs_f64(),
        dir: dir.to_path_buf(),
        message,
    })
}

/// Search for the factor of safety; outputs into `out` (module docs).
pub fn search(scene: &Scene, out: &Path, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let cfg = scene.config.strength_reduction.as_ref().expect("caller");
    let started = Instant::now();
    let mut csv =
        std::io::BufWriter::new(std::fs::File::create(out.join("strength_reduction.csv"))?);
    writeln!(csv, "{CSV_HEADER}")?;
    let mut trials: Vec<Trial> = Vec::new();
    let mut run_trial = |factor: f64, trials: &mut Vec<Trial>| -> Result<bool, RunError> {
        let dir = out
            .join("trials")
            .join(format!("{:02}_F{factor:.4}", trials.len()));
        let t = trial(scene, &dir, factor)?;
        writeln!(csv, "{}", t.csv())?;
        csv.flush()?;
        if opts.progress {
            eprintln!(
                "strength reduction: F = {factor:.4} {} ({} steps, {} Newton iterations, {} cut-backs, {:.1} s)",
                match t.failure {
                    None => "holds",
                    Some(Failure::Newton) => "fails (Newton)",
                    Some(Failure::Displacement) => "fails (displacement)",
                },
                t.steps,
                t.newton_iterations,
                t.cutbacks,
                t.wall_seconds
            );
        }
        let failed = t.failure.is_some();
        trials.push(t);
        Ok(failed)
    };
    let (mut lo, mut hi) = (cfg.search[0], cfg.search[1]);
    let (mut stable, mut failed): (Option<f64>, Option<f64>) = (None, None);
    let budget = cfg.max_trials();
    while stable.is_none() && trials.len() < budget {
        if run_trial(lo, &mut trials)? {
            failed = Some(lo);
            lo /= WIDEN;
        } else {
            stable = Some(lo);
        }
    }
    while stable.is_some() && failed.is_none() && trials.len() < budget {
        if run_trial(hi, &mut trials)? {
            failed = Some(hi);
        } else {
            stable = Some(hi);
            hi *= WIDEN;
        }
    }
    while let (Some(s), Some(f)) = (stable, failed) {
        if f - s <= cfg.tolerance() || trials.len() >= budget {
            break;
        }
        let mid = 0.5 * (s + f);
        if run_trial(mid, &mut trials)? {
            failed = Some(mid);
        } else {
            stable = Some(mid);
        }
    }
    let wall = started.elapsed().as_secs_f64();
    let newton: u64 = trials.iter().map(|t| t.newton_iterations).sum();
    let steps: u64 = trials.iter().map(|t| t.steps).sum();
    let rel = |t: &Trial| {
        t.dir
            .strip_prefix(out)
            .unwrap_or(&t.dir)
            .display()
            .to_string()
    };
    let find = |f: Option<f64>| {
        f.and_then(|f| trials.iter().find(|t| t.factor == f))
            .map(rel)
    };
    let mut summary = json!({
        "scene": scene.file,
        "analysis": "strength_reduction",
        "failure_criterion": if cfg.max_displacement.is_some() {
            "Newton non-convergence after cut-backs, or monitored displacement above max_displacement"
        } else {
            "Newton non-convergence after cut-backs"
        },
        "trials": trials.iter().map(|t| json!({
            "factor": t.factor,
            "status": match t.failure {
                None => "stable",
                Some(Failure::Newton) => "failed_newton",
                Some(Failure::Displacement) => "failed_displacement",
            },
            "steps": t.steps,
            "newton_iterations": t.newton_iterations,
            "cutbacks": t.cutbacks,
            "monitor_displacement": t.monitor_displacement,
            "wall_seconds": t.wall_seconds,
            "dir": rel(t),
            "message": t.message,
        })).collect::<Vec<_>>(),
        "newton_iterations": newton,
        "steps": steps,
        "wall_seconds": wall,
        "mechanism_stable": find(stable),
        "mechanism_failed": find(failed),
    });
    let particles = trials
        .first()
        .and_then(|t| {
            let text = std::fs::read_to_string(t.dir.join("summary.json")).ok()?;
            serde_json::from_str::<serde_json::Value>(&text).ok()
        })
        .and_then(|j| j["particles"].as_u64())
        .unwrap_or(0);
    summary["particles"] = json!(particles);
    match (stable, failed) {
        (Some(s), Some(f)) => {
            summary["status"] = json!("completed");
            summary["factor_of_safety"] = json!(0.5 * (s + f));
            summary["factor_of_safety_bracket"] = json!([s, f]);
            write_json(&out.join("summary.json"), &summary)?;
            Ok(RunSummary {
                steps: steps as usize,
                end_time: scene.config.total_time(),
                particles: particles as usize,
                wall_seconds: wall,
                json: summary,
            })
        }
        _ => {
            let msg = format!(
                "{}: no bracket [stable F, failed F] found in {} trials (stable: {stable:?}, failed: {failed:?}); see {}",
                scene.file,
                trials.len(),
                out.join("strength_reduction.csv").display()
            );
            summary["status"] = json!("no_bracket");
            summary["message"] = json!(msg);
            write_json(&out.join("summary.json"), &summary)?;
            Err(RunError::Diverged(msg))
        }
    }
}
