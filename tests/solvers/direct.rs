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
    // Measured 1.2e-14: round-off, with a floor.
    crate::common::assert_within("σ_yy, AMD against METIS, relative", worst / scale, 1e-10);
}

/// Matrix Market coordinate file → (n, triplets, symmetric).
fn read_mtx(path: &std::path::Path) -> (usize, Vec<(usize, usize, f64)>, bool) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("%%MatrixMarket matrix coordinate real"));
    let size: Vec<usize> = lines
        .next()
        .unwrap()
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect();
    let entries: Vec<(usize, usize, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            let (r, c): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
            (r - 1, c - 1, f[2].parse().unwrap())
        })
        .collect();
    assert_eq!((size[0], size[2]), (size[1], entries.len()));
    (size[0], entries, header.ends_with("symmetric"))
}

#[test]
fn linear_systems_are_written_as_matrix_market() {
    use mpm::solver::linear::direct::{DirectSolver, Method, Structure};
    let (result, dir) = run_problem(
        "column.toml",
        &["output.frames=0", "output.linear_systems=\"all\""],
    );
    let s = result.unwrap();
    let systems = dir.path().join("linear_systems");
    let mut names: Vec<String> = std::fs::read_dir(&systems)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    let matrices: Vec<&String> = names
        .iter()
        .filter(|n| n.ends_with(".mtx") && !n.ends_with("_rhs.mtx"))
        .collect();
    // One system per Newton correction, one table of unknowns per step.
    assert_eq!(Some(matrices.len()), s.solver.newton_iterations);
    let tables = names
        .iter()
        .filter(|n| n.ends_with("_unknowns.csv"))
        .count();
    assert_eq!(tables, s.steps);
    assert_eq!(matrices[0], "step000001_cut0_iter00.mtx");
    // The first system: symmetric positive definite (LLᵀ), its right-hand side
    // and table sized to its unknowns, the solution finite.
    let (n, t, symmetric) = read_mtx(&systems.join(matrices[0]));
    assert!(symmetric && n > 10);
    assert!(t.iter().all(|&(r, c, _)| r >= c && r < n));
    let rhs_text = std::fs::read_to_string(systems.join("step000001_cut0_iter00_rhs.mtx")).unwrap();
    let rhs: Vec<f64> = rhs_text
        .lines()
        .skip(2)
        .map(|l| l.parse().unwrap())
        .collect();
    assert_eq!(rhs.len(), n);
    let unknowns = Table::read(&systems.join("step000001_cut0_unknowns.csv")).unwrap();
    assert_eq!(unknowns.col("unknown").len(), n);
    assert!(unknowns
        .col("component")
        .iter()
        .all(|&c| c == 0.0 || c == 1.0));
    let mut solver = DirectSolver::new();
    let method = solver
        .factorize_triplets(n, &t, Structure::Symmetric)
        .unwrap();
    assert_eq!(method, Method::Llt);
    assert!(solver.solve(&rhs).unwrap().iter().all(|x| x.is_finite()));
}

#[test]
fn linear_systems_need_the_direct_solver() {
    let sets = [
        "output.linear_systems=\"first\"".to_string(),
        "solver.linear_solver=\"gmres\"".to_string(),
    ];
    let e = mpm::scene::Scene::load(&crate::common::problem("column.toml"), &sets).unwrap_err();
    assert_eq!(e.key.as_deref(), Some("output.linear_systems"));
    assert!(e.to_string().contains("linear_solver = \"direct\""), "{e}");
}
