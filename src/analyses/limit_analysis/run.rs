//! `mpm limit`: solve the lower and upper bounds at each refinement level and
//! write summary.json and refinement.csv. A level that cannot be solved ends the
//! run: summary.json then has status `failed`, the message and the levels before.
//!
//! Footing: the bounds are on the limit pressure q (average footing pressure at
//! collapse) and on q/c. Slope: the bounds are on the strength-reduction factor
//! of safety, each the root of α(F) = 1 for the corresponding bound on the
//! collapse multiplier α on gravity.

use super::config::{LimitScene, Problem};
use super::lower_bound::lower_bound;
use super::model::Model;
use super::reduction::Trial;
use super::reduction::{factor_of_safety, FactorOfSafety, ReductionError};
use super::upper_bound::upper_bound;
use super::Bound;
use crate::output::{write_json, CsvWriter, Field};
use crate::run::summary::Status;
use serde::{Deserialize, Serialize};
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
    /// A level could not be solved; summary.json (written) says so.
    #[error("{message}")]
    Solve {
        message: String,
        summary: Box<LimitSummary>,
    },
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

/// The bounds at one refinement level, or why they could not be found (the
/// bound, the level and the solver's status).
fn solve_level(scene: &LimitScene, refinements: u32) -> Result<Level, String> {
    let model: Model = scene.model(refinements);
    let elements = model.mesh.triangles.len();
    let what = |bound: &str, e: &dyn std::fmt::Display| {
        format!("{bound} bound at refinement level {refinements} ({elements} triangles): {e}")
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

/// summary.json of `mpm limit`: the bounds of the finest level solved (the
/// headline) and every level solved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LimitSummary {
    pub scene: String,
    pub problem: Problem,
    /// What is bounded: `limit_pressure` or `factor_of_safety`.
    pub quantity: String,
    /// `failed` when a level could not be solved; absent when every level was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status: Option<Status>,
    /// Why it failed: the bound, the level and the solver's status.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Absent when the first level failed.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub finest: Option<Finest>,
    pub levels: Vec<LevelSummary>,
    pub wall_seconds: f64,
}

/// The bounds of the finest level solved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Finest {
    pub lower_bound: f64,
    pub upper_bound: f64,
    pub relative_gap: f64,
    pub elements: usize,
    #[serde(flatten)]
    pub headline: Headline,
}

/// The bounds of the finest level in the units of the problem.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Headline {
    /// Footing: q/c.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearing_capacity_factor_lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearing_capacity_factor_upper: Option<f64>,
    /// Slope: the factors of safety and the brackets of their searches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety_lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety_upper: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety_lower_bracket: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub factor_of_safety_upper_bracket: Option<[f64; 2]>,
}

/// One refinement level in summary.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelSummary {
    pub refinements: u32,
    pub elements: usize,
    pub lower_bound: f64,
    pub upper_bound: f64,
    pub relative_gap: f64,
    pub lower_seconds: f64,
    pub upper_seconds: f64,
    #[serde(flatten)]
    pub headline: Headline,
    /// Footing: the sizes of the two cone programs and their iterations.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub programs: Option<Programs>,
    /// Slope: the trials of the two factor-of-safety searches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_trials: Option<Vec<Trial>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_trials: Option<Vec<Trial>>,
}

/// The two cone programs of a footing level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Programs {
    pub lower_iterations: u32,
    pub upper_iterations: u32,
    pub variables: usize,
    pub lower_equalities: usize,
    pub upper_equalities: usize,
    pub cones: usize,
}

fn level_summary(scene: &LimitScene, l: &Level) -> LevelSummary {
    let mut headline = Headline::default();
    let mut programs = None;
    if let Some([lb, ub]) = &l.solves {
        let c = scene.config.soil.cohesion;
        headline.bearing_capacity_factor_lower = Some(lb.multiplier / c);
        headline.bearing_capacity_factor_upper = Some(ub.multiplier / c);
        programs = Some(Programs {
            lower_iterations: lb.iterations,
            upper_iterations: ub.iterations,
            variables: lb.variables,
            lower_equalities: lb.equalities,
            upper_equalities: ub.equalities,
            cones: lb.cones,
        });
    }
    let searches = l.searches.as_ref();
    if let Some([lb, ub]) = searches {
        headline.factor_of_safety_lower = Some(lb.factor);
        headline.factor_of_safety_upper = Some(ub.factor);
        headline.factor_of_safety_lower_bracket = Some(lb.bracket);
        headline.factor_of_safety_upper_bracket = Some(ub.bracket);
    }
    LevelSummary {
        refinements: l.refinements,
        elements: l.elements,
        lower_bound: l.lower,
        upper_bound: l.upper,
        relative_gap: l.relative_gap(),
        lower_seconds: l.lower_seconds,
        upper_seconds: l.upper_seconds,
        headline,
        programs,
        lower_trials: searches.map(|[lb, _]| lb.trials.clone()),
        upper_trials: searches.map(|[_, ub]| ub.trials.clone()),
    }
}

/// The columns of refinement.csv, one row per level solved.
const CSV_COLUMNS: [&str; 7] = [
    "refinements",
    "elements",
    "lower_bound",
    "upper_bound",
    "relative_gap",
    "lower_seconds",
    "upper_seconds",
];

fn csv_row(l: &Level) -> [Field<'static>; 7] {
    [
        Field::from(l.refinements),
        l.elements.into(),
        l.lower.into(),
        l.upper.into(),
        l.relative_gap().into(),
        l.lower_seconds.into(),
        l.upper_seconds.into(),
    ]
}

fn print_level(scene: &LimitScene, l: &Level) {
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

/// summary.json of the levels solved; `failure` is why the next one was not.
fn limit_summary(
    scene: &LimitScene,
    levels: &[Level],
    failure: Option<String>,
    wall_seconds: f64,
) -> LimitSummary {
    let quantity = match scene.config.problem {
        Problem::Footing => "limit_pressure",
        Problem::Slope => "factor_of_safety",
    };
    LimitSummary {
        scene: scene.file.clone(),
        problem: scene.config.problem,
        quantity: quantity.into(),
        status: failure.as_ref().map(|_| Status::Failed),
        message: failure,
        finest: levels.last().map(|last| Finest {
            lower_bound: last.lower,
            upper_bound: last.upper,
            relative_gap: last.relative_gap(),
            elements: last.elements,
            headline: level_summary(scene, last).headline,
        }),
        levels: levels.iter().map(|l| level_summary(scene, l)).collect(),
        wall_seconds,
    }
}

/// Solve every refinement level and write summary.json (the last level is the
/// headline) and refinement.csv into `out`. `progress` prints one line per level.
/// A level that cannot be solved ends the run with [`LimitError::Solve`] after
/// summary.json (status `failed`) and refinement.csv are written with the
/// levels before it.
pub fn run_limit(
    scene: &LimitScene,
    out: &Path,
    progress: bool,
) -> Result<LimitSummary, LimitError> {
    std::fs::create_dir_all(out).map_err(io(out))?;
    let start = Instant::now();
    let csv_path = out.join("refinement.csv");
    let mut csv = CsvWriter::create(&csv_path, &CSV_COLUMNS).map_err(io(&csv_path))?;
    let mut refinements = scene.config.mesh.refinements.clone();
    refinements.sort_unstable();
    refinements.dedup();
    let mut levels = Vec::new();
    let mut failure = None;
    for r in refinements {
        let l = match solve_level(scene, r) {
            Ok(l) => l,
            Err(message) => {
                failure = Some(message);
                break;
            }
        };
        csv.row(csv_row(&l))
            .and_then(|_| csv.flush())
            .map_err(io(&csv_path))?;
        if progress {
            print_level(scene, &l);
        }
        levels.push(l);
    }
    let wall_seconds = start.elapsed().as_secs_f64();
    let summary = limit_summary(scene, &levels, failure.clone(), wall_seconds);
    let path = out.join("summary.json");
    write_json(&path, &summary).map_err(io(&path))?;
    match failure {
        None => Ok(summary),
        Some(message) => Err(LimitError::Solve {
            message: format!(
                "{}: {message}; summary.json (status failed) and the levels solved so far are in {}",
                scene.file,
                out.display()
            ),
            summary: Box::new(summary),
        }),
    }
}
