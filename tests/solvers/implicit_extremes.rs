//! The implicit solver at the extremes: a 10⁶ stiffness contrast, a nearly
//! incompressible material, a step so large that Newton fails (cut-back and
//! recovery, and a clean stop when cut-backs are not allowed), and results that do
//! not depend on the number of threads.

use crate::common::{assert_within, run_problem, shape_functions, Table};
use mpm::scene::ShapeFunction;

fn syy_errors(dir: &std::path::Path, l0: f64) -> Vec<(f64, f64)> {
    let p = Table::read(&dir.join("particles_final.csv")).unwrap();
    p.col("Y0")
        .iter()
        .zip(p.col("syy"))
        .map(|(y, s)| ((s + 800.0 * (l0 - y)).abs(), *y))
        .collect()
}

/// The linear families (hats, GIMP, CPDI) keep every particle within about
/// ρ g h / 4 (= 100 Pa; measured 112 Pa at most) of the exact stress across the
/// 10⁶ jump; the B-splines, whose
/// support spans the interface, carry an error there (≈ 2.7 kPa of 8 kPa,
/// quadratic) but not away from it.
#[test]
fn stiffness_contrast_of_a_million() {
    // Measured with cubic B-splines: 15.9 kPa next to the interface (2.0 times
    // the base stress; quadratic 2.7 kPa), 2.5 kPa beyond 1 m, 1.0 kPa beyond
    // 2 m, falling to 30 Pa at 4 m (a finding, not yet explained).
    let cubic = "its error spreads beyond 1 m of the interface (2.5 kPa there)";
    for shape in shape_functions(&[(ShapeFunction::Bspline3, cubic)]) {
        let smooth = shape.degree() > 1;
        let shape = shape.name();
        let (result, dir) = run_problem(
            "two_layer_column.toml",
            &[&format!("grid.shape_function={shape}")],
        );
        let s = result.unwrap_or_else(|e| panic!("{shape}: {e}"));
        let e = syy_errors(dir.path(), 10.0);
        let worst = e.iter().map(|x| x.0).fold(0.0, f64::max);
        let far = e
            .iter()
            .filter(|(_, y)| (y - 5.0).abs() > 1.0)
            .map(|x| x.0)
            .fold(0.0, f64::max);
        println!("{shape}: max error {worst:.0} Pa, beyond 1 m of the interface {far:.0} Pa, {} Newton iterations", s.solver.newton_iterations.unwrap());
        if smooth {
            // Measured 297 Pa (quadratic, and averaged over the domains).
            assert_within(
                &format!("{shape}: error beyond 1 m of the interface (Pa)"),
                far,
                400.0,
            );
        } else {
            // Twice ρ g h / 4 (measured 100 to 112 Pa).
            assert_within(&format!("{shape}: max error (Pa)"), worst, 200.0);
        }
        assert!(
            s.solver.newton_iterations.unwrap() <= 40,
            "{shape}: {} Newton iterations for 10 steps",
            s.solver.newton_iterations.unwrap()
        );
    }
}

/// ν = 0.49 (Hencky): uniaxial strain under lateral rollers; σ_yy is still
/// −ρ g (l0 − Y). At 32 cells (h = 1.5625 m) every particle is within about the
/// linear basis' intrinsic ρ g h / 4 = 312 Pa of it (measured 313 and 323 Pa) at any ν (at ν = 0.49 the column barely
/// deforms, so all particles show that pattern; at ν = 0 the motion averages it
/// down), and Newton converges as fast as at ν = 0.
#[test]
fn nearly_incompressible_column() {
    let quarter_cell = 800.0 * (50.0 / 32.0) / 4.0;
    let run = |nu: &str| {
        let (result, dir) = run_problem(
            "column.toml",
            &[
                &format!("material.0.poisson_ratio={nu}"),
                "grid.shape_function=cpdi",
                "grid.cells=[1,32]",
                "output.frames=0",
            ],
        );
        let s = result.unwrap();
        let worst = syy_errors(dir.path(), 50.0)
            .iter()
            .map(|x| x.0)
            .fold(0.0, f64::max);
        (worst, s.solver.newton_iterations.unwrap())
    };
    let (w0, n0) = run("0.0");
    let (w49, n49) = run("0.49");
    println!("ν = 0: max error {w0:.0} Pa, {n0} Newton iterations; ν = 0.49: max error {w49:.0} Pa, {n49} iterations (ρgh/4 = {quarter_cell:.0} Pa)");
    // Measured 323 and 313 Pa: bounded at twice ρ g h / 4.
    assert_within("ν = 0: max error (Pa)", w0, 2.0 * quarter_cell);
    assert_within("ν = 0.49: max error (Pa)", w49, 2.0 * quarter_cell);
    assert!(n49 <= n0, "ν = 0.49 needs {n49} Newton iterations vs {n0}");
}

/// The large-deformation column (E = 10 kPa) in one load step: Newton fails on the
/// whole step (a particle inverts in the first iterate), the step is halved until
/// it converges, and the run completes with the right stresses. Without cut-backs
/// it stops cleanly, naming the reason, and keeps newton.csv.
#[test]
fn newton_failure_cuts_the_step_and_recovers() {
    let base = [
        "material.0.youngs_modulus=1e4",
        "solver.load_steps=1",
        "solver.max_iterations=8",
        "grid.cells=[1,32]",
        "grid.shape_function=cpdi",
        "output.frames=0",
    ];
    let (result, dir) = run_problem("column.toml", &base);
    let s = result.unwrap();
    let cutbacks = s.solver.cutbacks.unwrap();
    let e = syy_errors(dir.path(), 50.0);
    let l2 = (e.iter().map(|x| x.0 * x.0).sum::<f64>() / e.len() as f64).sqrt() / 40000.0;
    println!(
        "one load step: {cutbacks} cut-backs, {} Newton iterations, stress error {l2:.3e}",
        s.solver.newton_iterations.unwrap()
    );
    assert!(cutbacks >= 1, "the full step should need a cut-back");
    assert!(l2 < 1e-2, "stress error after recovery {l2:.3e}");
    let newton = std::fs::read_to_string(dir.path().join("newton.csv")).unwrap();
    assert!(
        newton
            .lines()
            .skip(1)
            .any(|l| l.split(',').nth(3) != Some("0")),
        "newton.csv records the cut-back level"
    );

    let mut no_cut: Vec<&str> = base.to_vec();
    no_cut.push("solver.max_cutbacks=0");
    let (result, dir) = run_problem("column.toml", &no_cut);
    match result {
        Err(mpm::run::RunError::Diverged { message: m, .. }) => assert!(
            m.contains("diverged at step 1") && m.contains("Newton iterate"),
            "{m}"
        ),
        other => panic!("expected a clean stop, got {other:?}"),
    }
    let summary = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    assert!(summary.contains("\"diverged\""), "{summary}");
    assert!(
        std::fs::read_to_string(dir.path().join("newton.csv"))
            .unwrap()
            .lines()
            .count()
            > 1
    );
}

/// Assembly, factorisation and transfers give byte-identical results with 1 and 2
/// threads, for the quasi-static column and the Newmark bar.
#[test]
fn implicit_results_do_not_depend_on_threads() {
    for (scene, extra) in [
        ("column.toml", "grid.cells=[1,64]"),
        ("vibrating_bar_implicit.toml", "solver.end_time=5"),
    ] {
        let run = |threads: usize| {
            let dir = crate::common::run_cli(scene, threads, &[extra, "output.frames=0"]);
            crate::common::read_output(&dir, "particles_final.csv")
        };
        assert!(
            run(1) == run(2),
            "{scene}: particles_final.csv differs between 1 and 2 threads"
        );
    }
}

/// The backtracking line search: the large-deformation column in 4 load steps
/// reaches the same state in fewer Newton iterations (measured 23 against 30).
#[test]
fn line_search_saves_newton_iterations() {
    let run = |ls: &str| {
        let (result, dir) = run_problem(
            "column.toml",
            &[
                "material.0.youngs_modulus=1e4",
                "solver.load_steps=4",
                "solver.max_iterations=30",
                "grid.cells=[1,32]",
                "grid.shape_function=cpdi",
                "output.frames=0",
                &format!("solver.line_search={ls}"),
            ],
        );
        let s = result.unwrap();
        let y = Table::read(&dir.path().join("particles_final.csv"))
            .unwrap()
            .col("y")
            .to_vec();
        (
            s.solver.newton_iterations.unwrap(),
            s.solver.cutbacks.unwrap(),
            y,
        )
    };
    let (n_plain, c_plain, y_plain) = run("false");
    let (n_ls, c_ls, y_ls) = run("true");
    println!("Newton iterations: {n_plain} without, {n_ls} with line search (cut-backs {c_plain}, {c_ls})");
    assert!(
        n_ls < n_plain && c_ls <= c_plain,
        "line search: {n_ls} vs {n_plain} iterations"
    );
    let dy = y_plain
        .iter()
        .zip(&y_ls)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    // Measured 1.4e-14 m (3e-16 of the height): round-off, with a floor.
    assert_within("the two paths' states apart (m)", dy, 1e-9);
}
