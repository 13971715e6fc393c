//! The multigrid preconditioner (`preconditioner = "multigrid"`) against the
//! direct solver: the same particle state on the column, the two-layer column,
//! the block (also with F-bar through GMRES, an unsymmetric tangent), the
//! cantilever (quadratic B-splines with tied nodes) and a plastic slope
//! (Mohr–Coulomb, ψ = 0, F-bar: GMRES); results independent of the
//! thread count; a Krylov failure handled like a Newton failure. The scenes are
//! small, so `multigrid_coarse_unknowns` is lowered to give them three to five
//! levels.

use crate::common::{
    assert_within, read_newton, read_output, run_cli, run_problem, run_text, Table,
};
use mpm::run::RunError;

fn particles(scene: &str, overrides: &[&str]) -> (Table, usize, usize) {
    let mut args: Vec<&str> = vec!["output.frames=0"];
    args.extend_from_slice(overrides);
    let (result, dir) = run_problem(scene, &args);
    let summary = result.unwrap_or_else(|e| panic!("{scene} {overrides:?}: {e}"));
    (
        Table::read(&dir.path().join("particles_final.csv")).unwrap(),
        summary.solver.newton_iterations.unwrap(),
        summary.solver.krylov_iterations.unwrap_or(0),
    )
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |a, x| a.max(x.abs()))
}

/// Largest difference of the positions (relative to the largest displacement)
/// and of `stresses` (relative to each one's largest value) between two runs.
fn difference(direct: &Table, other: &Table, stresses: &[&str]) -> f64 {
    let displacement = max_abs(["x", "y"].iter().flat_map(|c| {
        let x0 = if *c == "x" { "X0" } else { "Y0" };
        direct
            .col(c)
            .iter()
            .zip(direct.col(x0))
            .map(|(a, b)| a - b)
            .collect::<Vec<_>>()
    }));
    let mut worst: f64 = 0.0;
    for c in ["x", "y"] {
        let d = max_abs(direct.col(c).iter().zip(other.col(c)).map(|(a, b)| a - b));
        worst = worst.max(d / displacement);
    }
    for s in stresses {
        let scale = max_abs(direct.col(s).iter().copied());
        let d = max_abs(direct.col(s).iter().zip(other.col(s)).map(|(a, b)| a - b));
        worst = worst.max(d / scale);
    }
    worst
}

const MULTIGRID: [&str; 3] = [
    "solver.preconditioner=multigrid",
    "solver.krylov_tolerance=1e-10",
    "solver.multigrid_coarse_unknowns=8",
];

/// Each scene with the direct solver and with CG (GMRES for F-bar) and the
/// multigrid solved to a relative linear residual of 1e-10: Newton takes the
/// same iterations on both paths, so the states agree to round-off (measured
/// 5.7e-13 of the largest displacement and stress at most); stated tolerance
/// 1e-10, a floor (round-off moves with any change of summation order).
#[test]
fn scenes_same_state_as_direct() {
    let block = ["grid.cells=[16,16]", "solver.load_steps=2"];
    let fbar_block = [
        "grid.cells=[16,16]",
        "solver.load_steps=2",
        "solver.fbar=true",
    ];
    let cantilever = ["load.0.force=[0,-100]", "solver.load_steps=1"];
    let cases: [(&str, &[&str], &str, &[&str]); 5] = [
        ("column.toml", &[], "cg", &["syy"]),
        ("two_layer_column.toml", &[], "cg", &["syy"]),
        ("bench/block.toml", &block, "cg", &["syy", "sxy"]),
        ("bench/block.toml", &fbar_block, "gmres", &["syy", "sxy"]),
        ("cantilever.toml", &cantilever, "cg", &["sxx", "sxy"]),
    ];
    for (scene, base, method, stresses) in cases {
        let (direct, newton_direct, _) = particles(scene, base);
        let linear = format!("solver.linear_solver={method}");
        let mut args: Vec<&str> = base.to_vec();
        args.push(&linear);
        args.extend(MULTIGRID);
        let (mg, newton_mg, krylov) = particles(scene, &args);
        let d = difference(&direct, &mg, stresses);
        println!(
            "{scene} {base:?} {method}/multigrid: difference {d:.1e}; {newton_mg} Newton and \
             {krylov} Krylov iterations (direct: {newton_direct} Newton)"
        );
        assert_within(&format!("{scene} {base:?}: difference"), d, 1e-10);
        assert!(krylov > 0);
    }
}

/// The Griffiths & Lane slope of `problems/slope_griffiths_lane.toml` on a coarse
/// grid without the strength-reduction search, at F = 1.3 (plastic zones, not yet
/// failing): Mohr–Coulomb with ψ = 0 and F-bar give an unsymmetric tangent, solved
/// by GMRES with the multigrid and by the direct solver's LU; the same state to
/// 1e-10 of the largest displacement and stress (Newton to 1e-10 on both paths;
/// measured 2.7e-12).
#[test]
fn slope_same_state_as_direct() {
    let slope = r#"
dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [40.0, 12.0]
cells = [40, 12]
[[material]]
name = "soil"
model = "mohr_coulomb"
density = 2.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
cohesion = 10.0
friction_angle = 20.0
dilation_angle = 0.0
[[body]]
name = "slope"
material = "soil"
shape = "polygon"
vertices = [[0.0, 0.0], [35.0, 0.0], [15.0, 10.0], [0.0, 10.0]]
particles_per_cell = 2
[[boundary]]
face = "xmin"
condition = "roller"
[[boundary]]
face = "ymin"
condition = "fixed"
[geostatic]
[solver]
kind = "implicit"
integrator = "quasi_static"
end_time = 1.0
load_steps = 1
gravity_ramp = false
residual_tolerance = 1e-10
line_search = true
max_iterations = 50
fbar = true
strength_reduction_factor = 1.3
[output]
frames = 0
"#;
    let run = |overrides: &[&str]| {
        let (result, dir) = run_text(slope, overrides);
        let summary = result.unwrap_or_else(|e| panic!("slope {overrides:?}: {e}"));
        let table = Table::read(&dir.path().join("particles_final.csv")).unwrap();
        let s = &summary.solver;
        let counts = (
            s.krylov_iterations.unwrap_or(0),
            s.newton_iterations.unwrap(),
        );
        (table, counts, s.multigrid)
    };
    let (direct, _, none) = run(&[]);
    assert_eq!(none, None, "no multigrid counts without multigrid");
    // Down to 8 coarse unknowns, and down to ≤ 200: its 147-unknown level is
    // singular at every refresh (two coarse basis functions coincide on the
    // active fine nodes) and is factorized shifted (docs/multigrid.md).
    for (coarse, singular) in [("8", false), ("200", true)] {
        let set = format!("solver.multigrid_coarse_unknowns={coarse}");
        let args = [
            "solver.linear_solver=gmres",
            "solver.preconditioner=multigrid",
            "solver.krylov_tolerance=1e-10",
            &set,
        ];
        let (mg, (krylov, newton), counts) = run(&args);
        let counts = counts.expect("summary.json reports the multigrid");
        let d = difference(&direct, &mg, &["sxx", "syy", "sxy"]);
        println!(
            "slope gmres/multigrid to ≤ {coarse}: difference {d:.1e}, {krylov} Krylov \
             iterations in {newton} Newton iterations, {counts:?}"
        );
        // Measured 2.7e-12; a round-off floor as above.
        assert_within("slope: difference", d, 1e-10);
        // A Krylov iteration per Newton iteration would mean a direct solve of
        // the fine level, which is what the hierarchy fell back to before
        // singular coarse operators were shifted.
        assert!(
            krylov > 2 * newton,
            "{krylov} Krylov for {newton} Newton iterations"
        );
        assert!(
            counts.refreshes == newton && counts.truncated == 0,
            "{counts:?}"
        );
        let shifted = if singular { newton } else { 0 };
        assert_eq!(counts.shifted, shifted, "{counts:?}");
    }
}

/// CG with the multigrid gives byte-identical particles with 1 and 2 threads
/// (row-parallel products and Galerkin rows summed in a fixed order).
#[test]
fn multigrid_results_do_not_depend_on_threads() {
    let overrides = [
        "load.0.force=[0,-100]",
        "solver.load_steps=1",
        "solver.linear_solver=cg",
        "solver.preconditioner=multigrid",
        "solver.multigrid_coarse_unknowns=8",
        "output.frames=0",
    ];
    let run = |threads: usize| {
        read_output(
            &run_cli("cantilever.toml", threads, &overrides),
            "particles_final.csv",
        )
    };
    assert!(
        run(1) == run(2),
        "particles_final.csv differs between 1 and 2 threads"
    );
}

/// A multigrid-preconditioned solve that does not converge is a Newton failure:
/// the step is cut back, then the run stops with a message naming the solver.
#[test]
fn multigrid_krylov_failure_cuts_back_then_stops_cleanly() {
    let args = [
        "load.0.force=[0,-100]",
        "solver.load_steps=1",
        "solver.linear_solver=cg",
        "solver.preconditioner=multigrid",
        "solver.multigrid_coarse_unknowns=8",
        "solver.krylov_tolerance=1e-12",
        "solver.krylov_max_iterations=1",
        "solver.max_cutbacks=2",
        "output.frames=0",
    ];
    let (result, dir) = run_problem("cantilever.toml", &args);
    match result {
        Err(RunError::Diverged { message: m, .. }) => assert!(
            m.contains("CG (multigrid preconditioner)")
                && m.contains("krylov_max_iterations = 1")
                && m.contains("after 2 cut-backs"),
            "{m}"
        ),
        other => panic!("expected a clean stop, got {other:?}"),
    }
    let newton = read_newton(&dir.path().join("newton.csv"));
    assert_eq!(newton.col("cutback").last(), Some(&2.0));
}
