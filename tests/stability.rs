//! Stability at the extremes of the explicit time step. For the vibrating bar
//! (h = 1, c = √(E/ρ) = 10) the critical step of central difference with lumped mass
//! is h/c = 0.1 s. At 0.9 of it the bar runs; at 1.5 it diverges and the run stops
//! with a message naming the step and the particle, keeping what it wrote.

mod common;
use common::{run_problem, Table};
use mpm::run::RunError;

#[test]
fn critical_step_is_h_over_c() {
    let (result, _dir) = run_problem(
        "vibrating_bar.toml",
        &["solver.end_time=0.05", "output.frames=0"],
    );
    let s = result.unwrap();
    let dt_cr = s.json["dt_critical"].as_f64().unwrap();
    // min over particles of h / (c + |v|), |v| ≤ 0.1: between 1/10.1 and 1/10.
    assert!(
        dt_cr > 1.0 / 10.1 - 1e-12 && dt_cr <= 0.1,
        "dt_critical = {dt_cr}"
    );
}

#[test]
fn runs_at_nine_tenths_of_the_critical_step() {
    let (result, dir) = run_problem("vibrating_bar.toml", &["solver.dt=0.09", "output.frames=0"]);
    let s = result.unwrap();
    assert_eq!(s.json["status"], "completed");
    let h = Table::read(&dir.path().join("history.csv"));
    let e: Vec<f64> = h
        .col("kinetic")
        .iter()
        .zip(h.col("strain"))
        .map(|(k, s)| k + s)
        .collect();
    let growth = e.iter().cloned().fold(0.0, f64::max) / e[0];
    assert!(
        growth < 1.05,
        "energy grew by a factor {growth} at 0.9 dt_cr"
    );
}

#[test]
fn diverges_at_one_and_a_half_times_the_critical_step_and_stops_cleanly() {
    let (result, dir) = run_problem(
        "vibrating_bar.toml",
        &["solver.dt=0.15", "solver.end_time=300", "output.frames=4"],
    );
    let msg = match result {
        Err(RunError::Diverged(m)) => m,
        other => panic!("expected a divergence, got {other:?}"),
    };
    assert!(
        msg.contains("diverged at step") && msg.contains("particle"),
        "{msg}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["status"], "diverged");
    assert!(summary["diverged_step"].as_u64().unwrap() > 0);
    let h = Table::read(&dir.path().join("history.csv"));
    assert!(
        h.col("t").len() > 5,
        "history written before the divergence is kept"
    );
    assert!(
        dir.path().join("particles.pvd").exists(),
        "frames written before the divergence are kept"
    );
}
