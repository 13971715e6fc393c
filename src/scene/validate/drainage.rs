//! Coupled pore flow (`drainage = "coupled"` on a material, `condition =
//! "drained"` on a face): the flow runs in explicit stages only, and a drained
//! face needs a material whose water flows.

use super::check::Check;
use crate::scene::{Condition, SceneConfig, SolverKind};

/// Explicit stages only with a coupled material; drained faces only with one.
pub fn drainage(s: &SceneConfig) -> Check {
    let coupled = (s.materials.iter().enumerate()).find(|(i, m)| {
        m.build(*i)
            .ok()
            .and_then(|m| m.pore_fluid())
            .is_some_and(|f| f.mobility > 0.0)
    });
    let drained = (s.boundaries.iter()).position(|b| b.condition == Condition::Drained);
    let Some((i, m)) = coupled else {
        return match drained {
            Some(j) => Err((
                format!("boundary.{j}.condition"),
                "a drained face needs a material with drainage = \"coupled\" (no pore \
                 water flows in this scene)"
                    .into(),
            )),
            None => Ok(()),
        };
    };
    let implicit = match &s.solver {
        Some(st) => (st.kind == SolverKind::Implicit).then(|| "solver.kind".to_string()),
        None => (s.stages.iter())
            .position(|st| st.kind == SolverKind::Implicit)
            .map(|k| format!("stage.{k}.kind")),
    };
    let implicit = implicit
        .or_else(|| (s.strength_reduction.is_some()).then(|| "strength_reduction".to_string()));
    match implicit {
        Some(key) => Err((
            key,
            format!(
                "material {i} (`{}`) has drainage = \"coupled\", whose pore flow runs on \
                 explicit stages only: implicit coupled consolidation is not built yet \
                 (issue 52); use drainage = \"undrained\" or \"drained\" for implicit stages",
                m.name
            ),
        )),
        None => Ok(()),
    }
}
