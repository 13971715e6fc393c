//! `mpm limit`: solve the lower and upper bounds at each refinement level and
//! write summary.json and refinement.csv.
//!
//! Footing: the bounds are on the limit pressure q (average footing pressure at
//! collapse) and on q/c. Slope: the bounds are on the strength-reduction factor
//! of safety, each the root of α(F) = 1 for the corresponding bound on the
//! collapse multiplier α on gravity.

use super::config::{LimitScene, Problem};
use super::lower_bound::lower_bound;
use super::model::Model;
use super::reduction::{factor_of_safety, FactorOfSafety, ReductionError};
use super::upper_bound::upper_bound;
use super::Bound;
use serde_json::{json, Value};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// The bounds at one refinement level.
#[derive(Clone, Debug)]
pub struct Level {
    pub refinements: u32,
    pub elements: usize,
    pub lower: f64,
    pub upper: f64,
    pub lower_seconds: f64,
    pub upper_seconds: f64,
    /// Slope only: the factor-of-safety searches.
    pub searches: Option<[FactorOfSafety; 2]>,
    /// Footing only: the two solves.
    pub solves: Option<[Bound; 2]>,
}

impl Level {
    /// (upper − lower) / mean.
    pub fn relative_gap(&self) -> f64 {
        (self.upper - self.lower) / (0.5 * (self.upper + self.lower))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum LimitError {
    #[error("{0}")]
    Solve(String),
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> LimitError + '_ {
    move |source| LimitError::Io {
        path: path.display().to_string(),
        source,
    }
}

fn solve_level(scene: &LimitScene, refinements: u32) -> Result<Level, LimitError> {
    let model: Model = scene.model(refinements);
    let elements = model.mesh.triangles.len();
    let what = |bound: &str, e: &dyn std::fmt::Display| {
        LimitError::Solve(format!(
            "{}: {bound} bound at refinement level {refinements} ({elements} triangles): {e}",
            scene.file
        ))
    };
    match scene.config.problem {
        Problem::Footing => {
            let lb = lower_bound(&model).map_err(|e| what("lower", &e))?;
            let ub = upper_bound(&model).map_err(|e| what("upper", &e))?;
            Ok(Level {
                refinements,
                elements,
                lower: lb.multiplier,
                upper: ub.multiplier,
                lower_seconds: lb.seconds,
                upper_seconds: ub.seconds,
                searches: None,
                solves: Some([lb, ub]),
            })
        }
        Problem::Slope => {
            let s = scene.config.slope.as_ref().expect("validated");
            let interval = [s.search[0], s.search[1]];
            let search = |bound, name| {
                factor_of_safety(&model, bound, interval, s.tolerance)
                    .map_err(|e: ReductionError| what(name, &e))
            };
            let lb = search(lower_bound, "lower")?;
            let ub = search(upper_bound, "upper")?;
            let seconds = |f: &FactorOfSafety| f.trials.iter().map(|t| t.seconds).sum();
            Ok(Level {
                refinements,
                elements,
                lower: lb.factor,
                upper: ub.factor,
                lower_seconds: seconds(&lb),
                upper_seconds: seconds(&ub),
                searches: Some([lb, ub]),
                solves: None,
            })
        }
    }
}

fn level_json(scene: &LimitScene, l: &Level) -> Value {
    let mut v = json!({
        "refinements": l.refinements,
        "elements": l.elements,
        "lower_bound": l.lower,
        "upper_bound": l.upper,
        "relative_gap": l.relative_gap(),
        "lower_seconds": l.lower_seconds,
        "upper_seconds": l.upper_seconds,
    });
    if let Some([lb, ub]) = &l.solves {
        let c = scene.config.soil.cohesion;
        v["bearing_capacity_factor_lower"] = json!(lb.multiplier / c);
        v["bearing_capacity_factor_upper"] = json!(ub.multiplier / c);
        v["lower_iterations"] = json!(lb.iterations);
        v["upper_iterations"] = json!(ub.iterations);
        v["variables"] = json!(lb.variables);
        v["lower_equalities"] = json!(lb.equalities);
        v["upper_equalities"] = json!(ub.equalities);
        v["cones"] = json!(lb.cones);
    }
    if let Some(searches) = &l.searches {
        for (name, s) in ["lower", "upper"].iter().zip(searches) {
            v[format!("factor_of_safety_{name}")] = json!(s.factor);
            v[format!("factor_of_safety_{name}_bracket")] = json!(s.bracket);
            v[format!("{name}_trials")] = json!(s
                .trials
                .iter()
                .map(|t| json!({"factor": t.factor, "multiplier": t.multiplier, "seconds": t.seconds}))
                .collect::<Vec<_>>());
        }
    }
    v
}

/// Solve every refinement level and write summary.json (the last level is the
/// headline) and refinement.csv into `out`. `progress` prints one line per level.
pub fn run_limit(scene: &LimitScene, out: &Path, progress: bool) -> Result<Value, LimitError> {
    std::fs::create_dir_all(out).map_err(io(out))?;
    let start = Instant::now();
    let mut levels = Vec::new();
    let csv_path = out.join("refinement.csv");
    let mut csv = std::fs::File::create(&csv_path).map_err(io(&csv_path))?;
    writeln!(
        csv,
        "refinements,elements,lower_bound,upper_bound,relative_gap,lower_seconds,upper_seconds"
    )
    .map_err(io(&csv_path))?;
    let mut refinements = scene.config.mesh.refinements.clone();
    refinements.sort_unstable();
    refinements.dedup();
    for r in refinements {
        let l = solve_level(scene, r)?;
        writeln!(
            csv,
            "{},{},{:.8e},{:.8e},{:.6e},{:.3},{:.3}",
            l.refinements,
            l.elements,
            l.lower,
            l.upper,
            l.relative_gap(),
            l.lower_seconds,
            l.upper_seconds
        )
        .map_err(io(&csv_path))?;
        if progress {
            println!(
                "level {}: {} triangles, {} ≤ {:.5} … {:.5} (gap {:.2} %), solver {:.2} s + {:.2} s",
                l.refinements,
                l.elements,
                match scene.config.problem {
                    Problem::Footing => "q",
                    Problem::Slope => "F",
                },
                l.lower,
                l.upper,
                100.0 * l.relative_gap(),
                l.lower_seconds,
                l.upper_seconds
            );
        }
        levels.push(l);
    }
    let last = levels.last().expect("at least one level");
    let mut summary = json!({
        "scene": scene.file,
        "problem": match scene.config.problem { Problem::Footing => "footing", Problem::Slope => "slope" },
        "quantity": match scene.config.problem { Problem::Footing => "limit_pressure", Problem::Slope => "factor_of_safety" },
        "lower_bound": last.lower,
        "upper_bound": last.upper,
        "relative_gap": last.relative_gap(),
        "elements": last.elements,
        "levels": levels.iter().map(|l| level_json(scene, l)).collect::<Vec<_>>(),
        "wall_seconds": start.elapsed().as_secs_f64(),
    });
    let headline = level_json(scene, last);
    for key in [
        "bearing_capacity_factor_lower",
        "bearing_capacity_factor_upper",
        "factor_of_safety_lower",
        "factor_of_safety_upper",
        "factor_of_safety_lower_bracket",
        "factor_of_safety_upper_bracket",
    ] {
        if let Some(v) = headline.get(key) {
            summary[key] = v.clone();
        }
    }
    let path = out.join("summary.json");
    std::fs::write(&path, serde_json::to_string_pretty(&summary).unwrap()).map_err(io(&path))?;
    Ok(summary)
}
