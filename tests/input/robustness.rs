//! No panic, abort or hang on hostile input (issue 12, part 4): degenerate
//! geometry, deeply nested expressions, grids and particle sets too large for the
//! memory, iteration counts without end; and `mpm check` rejects what `mpm run`
//! would reject at set-up. Each case goes through the program itself, so an abort
//! would show as a signal rather than pass unnoticed.

use mpm::scene::Scene;
use std::process::Command;

use crate::common::{refusals, GOOD};

/// `mpm check` and `mpm run` on `text` with `args`: exit code 2 and stderr naming
/// `key` and containing `words`.
fn refused(text: &str, args: &[&str], key: &str, words: &str) {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, text).unwrap();
    for (command, stderr) in refusals(&file, args) {
        assert!(
            stderr.contains(&format!("key `{key}`")) && stderr.contains(words),
            "mpm {command}: {stderr}"
        );
    }
}

fn accepted(text: &str, args: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_mpm"))
        .arg("check")
        .arg(&file)
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
}

#[test]
fn the_reference_scene_is_accepted() {
    accepted(GOOD, &[]);
}

#[test]
fn degenerate_grids_are_refused() {
    // A grid whose cells vanish in round-off at its coordinates, or are denormal.
    refused(
        &GOOD.replace(
            "min = [0.0, 0.0]\nmax = [4.0, 1.0]",
            "min = [1e6, 0.0]\nmax = [1.000000000001e6, 1.0]",
        ),
        &[],
        "grid.cells",
        "too small to resolve",
    );
    refused(
        &GOOD.replace("max = [4.0, 1.0]", "max = [1e-310, 1.0]"),
        &[],
        "grid.cells",
        "too small to resolve",
    );
    refused(
        &GOOD.replace(
            "min = [0.0, 0.0]\nmax = [4.0, 1.0]",
            "min = [-1e308, 0.0]\nmax = [1e308, 1.0]",
        ),
        &[],
        "grid.max",
        "finite",
    );
}

#[test]
fn degenerate_bodies_are_refused() {
    // A body too thin to hold a particle: `mpm run` finds it when it fills the
    // body, `mpm check` must too.
    refused(
        &GOOD.replace("max = [2.0, 1.0]", "max = [2.0, 0.01]"),
        &[],
        "body.0.shape",
        "holds no particle",
    );
    // A collinear polygon has no area.
    refused(
        &GOOD.replace(
            "shape = \"rectangle\"\nmin = [0.0, 0.0]\nmax = [2.0, 1.0]",
            "shape = \"polygon\"\nvertices = [[0.0, 0.0], [1.0, 0.5], [2.0, 1.0]]",
        ),
        &[],
        "body.0.shape",
        "holds no particle",
    );
}

#[test]
fn an_absorbing_face_without_material_is_refused_by_check() {
    let text = GOOD.to_string() + "\n[[boundary]]\nface = \"xmax\"\ncondition = \"absorbing\"\n";
    refused(
        &text,
        &[],
        "boundary.0.face",
        "no material next to the absorbing face",
    );
}

#[test]
fn deeply_nested_expressions_are_refused_without_overflowing_the_stack() {
    for expr in [
        format!("{}x{}", "(".repeat(50_000), ")".repeat(50_000)),
        format!("{}x", "-".repeat(100_000)),
    ] {
        let text = GOOD.replace(
            "max = [2.0, 1.0]",
            &format!("max = [2.0, 1.0]\nvelocity_expr = [\"{expr}\", \"0\"]"),
        );
        refused(&text, &[], "body.0.velocity_expr.0", "the expression");
    }
}

#[test]
fn a_scene_too_large_for_the_memory_is_refused_before_allocating() {
    refused(
        GOOD,
        &["--set", "grid.cells=[4000000000, 1000000000]"],
        "grid.cells",
        "the run would need about",
    );
    refused(
        GOOD,
        &["--set", "body.0.particles_per_cell=1000000"],
        "body.0.particles_per_cell",
        "the run would need about",
    );
    // The limit can be set: lowered it refuses the small scene, raised it lets
    // a larger one through `mpm check` (which builds the model).
    refused(
        GOOD,
        &["--memory-limit", "1e-6"],
        "grid.cells",
        "more than the limit",
    );
    accepted(
        GOOD,
        &["--memory-limit", "64", "--set", "grid.cells=[400, 100]"],
    );
}

#[test]
fn iteration_counts_without_end_are_refused() {
    let implicit = GOOD.replace(
        "kind = \"explicit\"\nend_time = 1.0\ncfl = 0.5",
        "kind = \"implicit\"\nend_time = 1.0\ndt = 0.1",
    );
    accepted(&implicit, &[]);
    for (set, key) in [
        (
            "solver.max_iterations=9223372036854775807",
            "solver.max_iterations",
        ),
        (
            "solver.krylov_max_iterations=100000000",
            "solver.krylov_max_iterations",
        ),
    ] {
        let mut args = vec!["--set", set];
        if set.starts_with("solver.krylov") {
            args.extend(["--set", "solver.linear_solver=gmres"]);
        }
        refused(&implicit, &args, key, "must be at most");
    }
    refused(
        &implicit,
        &["--set", "solver.max_cutbacks=100000"],
        "solver.max_cutbacks",
        "at most 50",
    );
    // A stage of more steps than any run could take.
    refused(
        &implicit,
        &["--set", "solver.dt=1e-12"],
        "solver.end_time",
        "steps of Δt",
    );
    refused(
        GOOD,
        &["--set", "solver.end_time=1e15"],
        "solver.end_time",
        "critical step",
    );
}

#[test]
fn a_scene_with_a_deep_expression_is_refused_by_the_library_too() {
    let text = GOOD.replace(
        "max = [2.0, 1.0]",
        &format!(
            "max = [2.0, 1.0]\nvelocity_expr = [\"{}x{}\", \"0\"]",
            "(".repeat(65),
            ")".repeat(65)
        ),
    );
    let e = Scene::parse("scene.toml", &text, &[]).unwrap_err();
    assert_eq!(e.key.as_deref(), Some("body.0.velocity_expr.0"), "{e}");
}
