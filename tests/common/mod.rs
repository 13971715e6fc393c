//! Helpers shared by the integration tests: run a scene into a temporary directory
//! and read its CSV outputs by column name.
#![allow(dead_code)]

use mpm::analyses::strength_reduction::{search, SearchError, SearchSummary};
use mpm::run::summary::Summary;
use mpm::run::{run, RunError, RunOptions};
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
) -> (Result<Summary, RunError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = Scene::load(&problem(name), &overrides).expect("scene loads");
    let result = one_thread(|| run(&scene, dir.path(), &RunOptions::default()));
    (result, dir)
}

/// `f` on a pool of one thread. The test harness already runs one test per core,
/// and results do not depend on the number of threads (tests/solvers/threads.rs
/// checks it byte for byte): two runs sharing the cores' two workers only wait
/// on each other.
pub fn one_thread<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    mpm::parallel::on_threads(1, f)
}

/// Run the strength-reduction search of `problems/NAME` with overrides.
pub fn search_problem(
    name: &str,
    overrides: &[&str],
) -> (Result<SearchSummary, SearchError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = Scene::load(&problem(name), &overrides).expect("scene loads");
    let result = one_thread(|| search(&scene, dir.path(), &RunOptions::default()));
    (result, dir)
}

/// CSV outputs by column name, and the zero crossings of a sampled signal: the
/// library's own (used by the error measures of `mpm bench`).
#[allow(unused_imports)]
pub use mpm::analyses::reference::bar::zero_crossings;
#[allow(unused_imports)]
pub use mpm::output::Table;

/// Run scene text (named `scene.toml` in errors) with overrides.
pub fn run_text(text: &str, overrides: &[&str]) -> (Result<Summary, RunError>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scene = Scene::parse("scene.toml", text, &overrides).expect("scene parses");
    let result = one_thread(|| run(&scene, dir.path(), &RunOptions::default()));
    (result, dir)
}

/// newton.csv (the library's Table also reads its text column, `linear_solver`).
pub fn read_newton(path: &Path) -> Table {
    Table::read(path).unwrap_or_else(|e| panic!("{e}"))
}

/// `mpm run problems/NAME --threads N --out DIR --set O …` through the program
/// itself; panics with its stderr unless it succeeds. Returns the output
/// directory (for thread-independence checks: compare its files byte by byte).
pub fn run_cli<S: AsRef<str>>(name: &str, threads: usize, overrides: &[S]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_mpm"));
    cmd.arg("run")
        .arg(problem(name))
        .args(["--threads", &threads.to_string(), "--out"])
        .arg(dir.path());
    for o in overrides {
        cmd.args(["--set", o.as_ref()]);
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "mpm run {name} --threads {threads}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

/// The bytes of an output file.
pub fn read_output(dir: &tempfile::TempDir, file: &str) -> Vec<u8> {
    std::fs::read(dir.path().join(file)).unwrap()
}

/// The normalised residuals of load step `step` in newton.csv, in order.
pub fn step_residuals(newton: &Table, step: f64) -> Vec<f64> {
    let (steps, res) = (newton.col("step"), newton.col("residual"));
    (0..steps.len())
        .filter(|&i| steps[i] == step)
        .map(|i| res[i])
        .collect()
}

/// Orders p_k = ln(r_{k+1}/r_k) / ln(r_k/r_{k−1}) of one step's residuals over
/// the iterations whose residuals lie well above the round-off floor (the last
/// residual) and that at least halved the residual (a stalled iteration,
/// r_k ≈ r_{k−1}, gives a meaningless quotient); the best, and the iterations.
pub fn newton_order(r: &[f64]) -> (f64, usize) {
    let floor = *r.last().unwrap();
    let informative = |x: f64| x > 1e3 * floor;
    let best = (1..r.len() - 1)
        .filter(|&k| informative(r[k - 1]) && informative(r[k]) && r[k] < 0.5 * r[k - 1])
        .map(|k| (r[k + 1] / r[k]).ln() / (r[k] / r[k - 1]).ln())
        .fold(f64::NAN, f64::max);
    (best, r.len() - 1)
}

/// A small valid 2D scene (explicit elastic bar on 4 × 1 cells) that the input
/// tests spoil one key at a time.
pub const GOOD: &str = r#"dimension = 2

[grid]
min = [0.0, 0.0]
max = [4.0, 1.0]
cells = [4, 1]

[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 100.0
poisson_ratio = 0.3

[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [2.0, 1.0]

[solver]
kind = "explicit"
end_time = 1.0
cfl = 0.5
"#;
