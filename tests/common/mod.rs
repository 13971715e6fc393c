//! Helpers shared by the integration tests: run a scene into a temporary directory
//! and read its CSV outputs by column name.
#![allow(dead_code)]

use mpm::run::{run, RunError, RunOptions, RunSummary};
use mpm::scene::Scene;
use std::collections::HashMap;
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

/// A CSV file as columns keyed by header name.
pub struct Table {
    pub columns: HashMap<String, Vec<f64>>,
    pub header: Vec<String>,
}

impl Table {
    pub fn read(path: &Path) -> Table {
        Table::read_columns(path, |_| true)
    }

    pub fn col(&self, name: &str) -> &[f64] {
        self.columns
            .get(name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header))
    }
}

/// Times at which a sampled signal crosses zero downwards/upwards (linear interpolation).
pub fn zero_crossings(t: &[f64], y: &[f64]) -> Vec<f64> {
    (1..t.len())
        .filter(|&i| (y[i - 1] > 0.0) != (y[i] > 0.0))
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * y[i - 1] / (y[i - 1] - y[i]))
        .collect()
}

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

/// newton.csv without its text column (`linear_solver`).
pub fn read_newton(path: &Path) -> Table {
    let mut t = Table::read_columns(path, |h| h != "linear_solver");
    t.header.retain(|h| h != "linear_solver");
    t
}

impl Table {
    /// Only the columns whose header passes `keep` (the others may hold text).
    pub fn read_columns(path: &Path, keep: impl Fn(&str) -> bool) -> Table {
        let text =
            std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut lines = text.lines();
        let header: Vec<String> = lines
            .next()
            .unwrap()
            .split(',')
            .map(|s| s.trim().to_string())
            .collect();
        let mut columns: HashMap<String, Vec<f64>> = header
            .iter()
            .filter(|h| keep(h))
            .map(|h| (h.clone(), Vec::new()))
            .collect();
        for line in lines.filter(|l| !l.trim().is_empty()) {
            for (h, v) in header.iter().zip(line.split(',')) {
                if let Some(c) = columns.get_mut(h) {
                    c.push(v.trim().parse().unwrap());
                }
            }
        }
        Table { columns, header }
    }
}
