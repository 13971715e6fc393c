//! Solver configurations: a configuration is a name and a set of scene overrides
//! (`--set KEY=VALUE` syntax) plus keys to remove. The built-in ones:
//!
//! - `explicit`: the scene's `[solver]` as an explicit run (implicit keys removed);
//! - `direct`: the implicit solver with the sparse direct factorisation (the
//!   default linear solver: `linear_solver` and `preconditioner` removed);
//! - `gmres_P`, `cg_P` for P in none, jacobi, block_jacobi, lagged_direct, multigrid,
//!   lagged_multigrid: the Newton–Krylov path (`linear_solver`, `preconditioner` keys).
//!
//! An explicit scene run by an implicit configuration becomes Newmark (trapezoidal)
//! with Δt = 10 × the explicit critical step at t = 0. In a staged scene the
//! implicit configurations act on every implicit stage.

use crate::scene::{Integrator, LinearSolver, PreconditionerKind, SceneConfig, SolverKind};
use strum::IntoEnumIterator;
use toml_edit::DocumentMut;

/// The matrix-free linear solvers (every one but the direct solver), by name.
fn krylov_names() -> impl Iterator<Item = &'static str> {
    LinearSolver::iter()
        .filter(|&s| s != LinearSolver::Direct)
        .map(|s| s.name())
}

/// Solver-table keys kept when a configuration switches between explicit and
/// implicit; every other key of the table is removed.
const KEPT: [&str; 3] = ["name", "kind", "end_time"];

#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    pub name: String,
    pub set: Vec<String>,
    pub unset: Vec<String>,
}

impl Configuration {
    /// The overrides as one line for bench.csv: `KEY=VALUE; …; unset KEY; …`.
    pub fn describe(set: &[String], unset: &[String]) -> String {
        let unset = unset.iter().map(|k| format!("unset {k}"));
        set.iter()
            .cloned()
            .chain(unset)
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// Names of the built-in configurations.
pub fn builtin_names() -> Vec<String> {
    let mut names = vec!["explicit".to_string(), "direct".to_string()];
    for k in krylov_names() {
        names.extend(PreconditionerKind::iter().map(|p| format!("{k}_{}", p.name())));
    }
    names
}

/// The default configurations for a scene: the implicit ones for every scene, and
/// `explicit` first unless the scene is quasi-static or staged (an explicit
/// quasi-static run needs damping and a relaxation time: define it yourself).
pub fn default_names(base: &SceneConfig) -> Vec<String> {
    let names = builtin_names();
    let quasi_static_or_staged = match &base.solver {
        Some(s) => s.kind == SolverKind::Implicit && s.integrator() == Integrator::QuasiStatic,
        None => true,
    };
    if quasi_static_or_staged {
        names[1..].to_vec()
    } else {
        names
    }
}

/// A built-in configuration for this base scene (its text and parsed form), or the
/// reason it does not apply; None if `name` is not built in. `dt_critical` is the
/// explicit critical step of the scene at t = 0.
pub fn builtin(
    name: &str,
    base: &SceneConfig,
    base_text: &str,
    dt_critical: f64,
) -> Option<Result<Configuration, String>> {
    if !builtin_names().iter().any(|n| n == name) {
        return None;
    }
    let doc: DocumentMut = base_text.parse().ok()?;
    let mut c = Configuration {
        name: name.to_string(),
        set: Vec::new(),
        unset: Vec::new(),
    };
    if name == "explicit" {
        let Some(s) = &base.solver else {
            return Some(Err(
                "the explicit configuration needs a single [solver] table".into(),
            ));
        };
        if s.kind == SolverKind::Implicit {
            c.unset = other_keys(&doc, "solver");
            c.set.push("solver.kind=\"explicit\"".into());
        }
        return Some(Ok(c));
    }
    // Implicit configurations: switch an explicit [solver] to Newmark first.
    let prefixes: Vec<String> = match &base.solver {
        Some(s) => {
            if s.kind == SolverKind::Explicit {
                c.unset = other_keys(&doc, "solver");
                c.set.extend([
                    "solver.kind=\"implicit\"".to_string(),
                    "solver.integrator=\"newmark\"".to_string(),
                    format!("solver.dt={:?}", 10.0 * dt_critical),
                ]);
            }
            vec!["solver".into()]
        }
        None => (0..base.stages.len())
            .filter(|&k| base.stages[k].kind == SolverKind::Implicit)
            .map(|k| format!("stage.{k}"))
            .collect(),
    };
    if prefixes.is_empty() {
        return Some(Err("the scene has no implicit stage".into()));
    }
    for p in prefixes {
        match name.split_once('_') {
            Some((krylov, pre)) if krylov_names().any(|k| k == krylov) => {
                c.set.push(format!("{p}.linear_solver=\"{krylov}\""));
                c.set.push(format!("{p}.preconditioner=\"{pre}\""));
            }
            _ => c
                .unset
                .extend(["linear_solver", "preconditioner"].map(|k| format!("{p}.{k}"))),
        }
    }
    Some(Ok(c))
}

/// Every key of the table at `table` (`solver`) except those in KEPT, as dotted paths.
fn other_keys(doc: &DocumentMut, table: &str) -> Vec<String> {
    doc.get(table)
        .and_then(|t| t.as_table_like())
        .map(|t| {
            t.iter()
                .map(|(k, _)| k)
                .filter(|k| !KEPT.contains(k))
                .map(|k| format!("{table}.{k}"))
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    const NEWMARK: &str = r#"
dimension = 2
[grid]
min = [0.0, 0.0]
max = [4.0, 1.0]
cells = [4, 1]
[[material]]
name = "m"
model = "hencky"
density = 1.0
youngs_modulus = 100.0
poisson_ratio = 0.0
[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [3.0, 1.0]
[solver]
kind = "implicit"
end_time = 1.0
dt = 0.1
max_iterations = 10
"#;

    #[test]
    fn explicit_configuration_removes_the_implicit_keys() {
        let base = Scene::parse("s.toml", NEWMARK, &[]).unwrap();
        let c = builtin("explicit", &base.config, NEWMARK, 0.01)
            .unwrap()
            .unwrap();
        assert_eq!(c.set, ["solver.kind=\"explicit\""]);
        assert_eq!(c.unset, ["solver.dt", "solver.max_iterations"]);
        let text = crate::scene::overrides::unset("s.toml", NEWMARK, &c.unset).unwrap();
        let s = Scene::parse("s.toml", &text, &c.set).unwrap();
        assert_eq!(s.config.stages()[0].kind, SolverKind::Explicit);
        assert!(default_names(&base.config).contains(&"explicit".to_string()));
    }

    #[test]
    fn krylov_configurations_set_the_solver_keys() {
        let base = Scene::parse("s.toml", NEWMARK, &[]).unwrap();
        let c = builtin("cg_block_jacobi", &base.config, NEWMARK, 0.01)
            .unwrap()
            .unwrap();
        assert_eq!(
            c.set,
            [
                "solver.linear_solver=\"cg\"",
                "solver.preconditioner=\"block_jacobi\""
            ]
        );
        let d = builtin("direct", &base.config, NEWMARK, 0.01)
            .unwrap()
            .unwrap();
        assert!(d.set.is_empty());
        assert!(builtin("cholesky", &base.config, NEWMARK, 0.01).is_none());
        assert_eq!(builtin_names().len(), 14); // explicit, direct, 2 Krylov methods × 6 preconditioners
    }
}
