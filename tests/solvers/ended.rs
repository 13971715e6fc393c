//! How a run ended (issue 12, part 5): summary.json's `status` (completed,
//! diverged, interrupted, failed) with its `message`, and outputs replaced
//! atomically so that no half-written file is left behind.

use crate::common::{run_problem, Table};
use mpm::run::summary::{Status, Summary};
use mpm::run::RunError;

/// Files left with the `.part` suffix of an unfinished atomic write.
fn leftovers(dir: &std::path::Path) -> Vec<String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(leftovers(&path));
        } else if path.to_string_lossy().ends_with(".part") {
            found.push(path.display().to_string());
        }
    }
    found
}

#[test]
fn a_completed_run_says_so_and_leaves_no_partial_file() {
    let (result, dir) = run_problem("column.toml", &["output.frames=4"]);
    let summary = result.unwrap();
    assert_eq!(summary.status, Status::Completed);
    assert_eq!(summary.message, None);
    let text = std::fs::read_to_string(dir.path().join("summary.json")).unwrap();
    assert!(
        text.contains("\"status\": \"completed\"") && !text.contains("\"message\""),
        "{text}"
    );
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
    let particles = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    assert_eq!(particles.len(), summary.particles);
}

#[test]
fn a_diverged_run_gives_its_message_and_step() {
    let (result, dir) = run_problem(
        "column.toml",
        &[
            "solver.load_steps=1",
            "solver.max_iterations=1",
            "solver.max_cutbacks=0",
        ],
    );
    let Err(RunError::Diverged { message, .. }) = result else {
        panic!("expected a divergence, got {result:?}");
    };
    let s = Summary::read(&dir.path().join("summary.json")).unwrap();
    assert_eq!(s.status, Status::Diverged);
    let m = s.message.expect("a diverged run has a message");
    assert!(
        m.contains("diverged at step 1") && message.contains(&m),
        "{m}"
    );
    assert_eq!(s.divergence.map(|d| d.diverged_step), Some(1));
}

#[test]
fn an_output_that_cannot_be_written_fails_the_run_and_says_why() {
    // A directory in the way of particles_final.csv's temporary file.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("particles_final.csv.part")).unwrap();
    let scene = mpm::scene::Scene::load(&crate::common::problem("column.toml"), &[]).unwrap();
    let result = mpm::run::run(&scene, dir.path(), &Default::default());
    assert!(matches!(result, Err(RunError::Io(_))), "{result:?}");
    let s = Summary::read(&dir.path().join("summary.json")).unwrap();
    assert_eq!(s.status, Status::Failed);
    let m = s.message.unwrap();
    assert!(m.starts_with("cannot write outputs"), "{m}");
    // Nothing half-written took the place of the final particles.
    assert!(!dir.path().join("particles_final.csv").exists());
}
