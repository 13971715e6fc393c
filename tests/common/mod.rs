//! Helpers shared by the integration tests: run a scene into a temporary directory
//! and read its CSV outputs by column name.
#![allow(dead_code)]

use mpm::run::{run, RunError, RunOptions, RunSummary};
use mpm::scene::Scene;
use std::path::{Path, PathBuf};

pub fn problem(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("problems")
        .join(name)
}

/// Run `problems/NAME` with overrides; returns the summary and the output directory.
pub fn run_problem(
    name: &str,
    overrides: &[&str],
) -> (Result<RunSummary, RunError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = Scene::load(&problem(name), &overrides).expect("scene loads");
    let result = run(&scene, dir.path(), &RunOptions::default());
    (result, dir)
}

/// CSV outputs by column name, and the zero crossings of a sampled signal: the
/// library's own (used by the error measures of `mpm bench`).
#[allow(unused_imports)]
pub use mpm::output::Table;
#[allow(unused_imports)]
pub use mpm::reference::bar::zero_crossings;

/// Run scene text (named `scene.toml` in errors) with overrides.
pub fn run_text(
    text: &str,
    overrides: &[&str],
) -> (Result<RunSummary, RunError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = Scene::parse("scene.toml", text, &overrides).expect("scene parses");
    let result = run(&scene, dir.path(), &RunOptions::default());
    (result, dir)
}

/// newton.csv (the library's Table also reads its text column, `linear_solver`).
pub fn read_newton(path: &Path) -> Table {
    Table::read(path).unwrap_or_else(|e| panic!("{e}"))
}
