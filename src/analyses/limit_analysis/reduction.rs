//! Factor of safety in the strength-reduction sense from a bound on the collapse
//! multiplier α on gravity: for a trial F the strength is c/F, atan(tan φ/F);
//! the factor of safety is the F at which α(F) = 1.
//!
//! α(F) decreases with F. A lower bound α_LB(F) ≤ α(F) therefore gives
//! F_LB ≤ F, and an upper bound gives F_UB ≥ F. The root is bracketed and
//! narrowed by the Illinois variant of regula falsi on ln α(F) (nearly linear in
//! F), which keeps a bracket at every step.

use super::cone::SolverFailure;
use super::model::Model;
use super::Bound;

/// One evaluation α(F).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trial {
    pub factor: f64,
    pub multiplier: f64,
    pub seconds: f64,
}

/// The factor of safety with its bracket: α(low) ≥ 1 ≥ α(high).
#[derive(Clone, Debug)]
pub struct FactorOfSafety {
    pub factor: f64,
    pub bracket: [f64; 2],
    pub trials: Vec<Trial>,
}

#[derive(Debug)]
pub enum ReductionError {
    Solver(f64, SolverFailure),
    /// α(F) − 1 has the same sign at both ends of the search interval.
    NotBracketed {
        low: Trial,
        high: Trial,
    },
}

impl std::fmt::Display for ReductionError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReductionError::Solver(factor, e) => write!(f, "at F = {factor}: {e}"),
            ReductionError::NotBracketed { low, high } => write!(
                f,
                "the factor of safety is not inside the search interval: α({}) = {:.4}, α({}) = {:.4} (both on the same side of 1)",
                low.factor, low.multiplier, high.factor, high.multiplier
            ),
        }
    }
}

impl std::error::Error for ReductionError {}

/// The most regula-falsi steps of one search (the Illinois variant converges
/// superlinearly: a dozen is usual).
pub const MAX_NARROWINGS: usize = 100;

/// Find F with α(F) = 1 in [low, high] to a bracket narrower than `tolerance`, or
/// as narrow as round-off and [`MAX_NARROWINGS`] steps make it.
pub fn factor_of_safety(
    model: &Model,
    bound: fn(&Model) -> Result<Bound, SolverFailure>,
    interval: [f64; 2],
    tolerance: f64,
) -> Result<FactorOfSafety, ReductionError> {
    let base = model.strength;
    let mut trials = Vec::new();
    let mut eval = |factor: f64| -> Result<Trial, ReductionError> {
        let b = bound(&model.with_strength(base.reduced(factor)))
            .map_err(|e| ReductionError::Solver(factor, e))?;
        let t = Trial {
            factor,
            multiplier: b.multiplier,
            seconds: b.seconds,
        };
        trials.push(t.clone());
        Ok(t)
    };
    let g = |t: &Trial| t.multiplier.max(1e-300).ln();
    // Move the interval (up to four times) until it brackets the root: halve
    // the low end if α(low) < 1, step the high end up if α(high) > 1.
    let width = interval[1] - interval[0];
    let mut a = eval(interval[0])?;
    let mut b = eval(interval[1])?;
    for _ in 0..4 {
        if g(&a) < 0.0 {
            b = a;
            a = eval(0.5 * b.factor)?;
        } else if g(&b) > 0.0 {
            a = b;
            b = eval(a.factor + 2.0 * width)?;
        } else {
            break;
        }
    }
    if g(&a) < 0.0 || g(&b) > 0.0 {
        return Err(ReductionError::NotBracketed { low: a, high: b });
    }
    let (mut ga, mut gb) = (g(&a), g(&b));
    let mut side = 0;
    let mut narrowings = 0;
    while b.factor - a.factor > tolerance && ga != 0.0 && gb != 0.0 {
        let mut f = (a.factor * gb - b.factor * ga) / (gb - ga);
        // Never step closer than a tenth of the tolerance to an end.
        let margin = 0.1 * tolerance;
        f = f.clamp(a.factor + margin, b.factor - margin);
        // A tolerance below the round-off of F cannot be met: stop with the
        // bracket as it is (also after MAX_NARROWINGS solves).
        if !(f > a.factor && f < b.factor) || narrowings == MAX_NARROWINGS {
            break;
        }
        narrowings += 1;
        let t = eval(f)?;
        let gt = g(&t);
        if gt >= 0.0 {
            a = t;
            ga = gt;
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        } else {
            b = t;
            gb = gt;
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        }
    }
    let (ga, gb) = (g(&a), g(&b));
    let factor = if ga == gb {
        a.factor
    } else {
        (a.factor * gb - b.factor * ga) / (gb - ga)
    };
    Ok(FactorOfSafety {
        factor,
        bracket: [a.factor, b.factor],
        trials,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyses::limit_analysis::config::LimitScene;
    use std::sync::OnceLock;

    /// The cohesion of the unreduced model.
    static BASE_COHESION: OnceLock<f64> = OnceLock::new();

    /// A stand-in for a bound, α(F) = 1.37 / F (the cohesion is divided by F),
    /// so that the factor of safety is 1.37 and a solve costs nothing.
    fn inverse(m: &Model) -> Result<Bound, SolverFailure> {
        let base = BASE_COHESION.get().unwrap();
        Ok(Bound {
            multiplier: 1.37 * m.strength.cohesion / base,
            elements: 0,
            variables: 0,
            equalities: 0,
            cones: 0,
            iterations: 0,
            seconds: 0.0,
            field: Vec::new(),
        })
    }

    /// A tolerance below the round-off of F cannot be met: the search stops
    /// within MAX_NARROWINGS steps with a bracket around the root.
    #[test]
    fn an_unreachable_tolerance_ends_with_the_bracket_it_has() {
        let text = include_str!("../../../problems/limit_slope.toml");
        let scene = LimitScene::parse("limit_slope.toml", text, &[]).unwrap();
        let model = scene.model(0);
        BASE_COHESION.get_or_init(|| model.strength.cohesion);
        for tolerance in [0.0, 5e-324, 1e-300] {
            let f = factor_of_safety(&model, inverse, [1.0, 2.0], tolerance).unwrap();
            assert!(
                f.trials.len() <= 2 + 4 + MAX_NARROWINGS,
                "{}",
                f.trials.len()
            );
            assert!(
                f.bracket[0] <= 1.37 && 1.37 <= f.bracket[1],
                "{:?}",
                f.bracket
            );
            assert!((f.factor - 1.37).abs() < 1e-12, "{}", f.factor);
        }
    }
}
