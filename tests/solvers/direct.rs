//! The sparse direct path of the implicit solver: the pattern, its ordering and
//! the symbolic analysis are computed again only when a step's stencils,
//! constraints or ties change; METIS and AMD give the same solution; summary.json
//! reports what the direct solver did.

use crate::common::{run_problem, Table};
use mpm::run::summary::Summary;
use mpm::scene::DirectOrdering;

fn run(scene: &str, overrides: &[&str]) -> (Summary, Table) {
    let mut args: Vec<&str> = vec!["output.frames=0"];
    args.extend_from_slice(overrides);
    let (result, dir) = run_problem(scene, &args);
    let summary = result.unwrap_or_else(|e| panic!("{scene} {overrides:?}: {e}"));
    let particles = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    (summary, particles)
}

#[test]
fn steps_with_unchanged_stencils_keep_the_symbolic_analysis() {
    // The block under its own weight, 4 load steps: the particles leave the
    // initial lattice in step 1 (their uGIMP domains then touch 3×3 nodes, not
    // 2×2) and stay within their cells after, so steps 2–4 share one pattern.
    let (s, _) = run("bench/block.toml", &["grid.cells=[24,24]"]);
    let direct = s.solver.direct.expect("direct solver report");
    assert_eq!(s.steps, 4);
    assert_eq!(direct.symbolic_analyses, 2, "{direct:?}");
    assert_eq!(Some(direct.factorizations), s.solver.newton_iterations);
    assert_eq!(direct.ordering, DirectOrdering::Amd);
    assert!(direct.largest_factor_entries > 0 && direct.largest_factor_mib > 0.0);
}

#[test]
fn metis_and_amd_give_the_same_column() {
    let (amd, a) = run("column.toml", &["solver.direct_ordering=\"amd\""]);
    let (metis, m) = run("column.toml", &["solver.direct_ordering=\"metis\""]);
    let ordering = |s: &Summary| s.solver.direct.as_ref().map(|d| d.ordering);
    assert_eq!(ordering(&amd), Some(DirectOrdering::Amd));
    assert_eq!(ordering(&metis), Some(DirectOrdering::Metis));
    assert_eq!(amd.solver.newton_iterations, metis.solver.newton_iterations);
    let scale = a.col("syy").iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let worst = a
        .col("syy")
        .iter()
        .zip(m.col("syy"))
        .fold(0.0f64, |w, (x, y)| w.max((x - y).abs()));
    assert!(
        worst <= 1e-10 * scale,
        "syy differs by {worst:e} (scale {scale:e})"
    );
}
