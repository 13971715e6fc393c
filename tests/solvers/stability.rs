//! Stability at the extremes of the explicit time step, on the vibrating bar
//! (h = 1, c = √(E/ρ) = 10, so the CFL step h/c of eq. 2-45 is 0.1 s).
//!
//! Measured behaviour (see the printed thresholds): USF and MUSL with FLIP stay
//! stable up to about 1.5 h/c — the projection of particle velocities to the grid
//! damps the node-to-node mode that limits lumped-mass central difference at h/c —
//! while USL needs a step below h/c. A run past the limit stops with a message
//! naming the step and the particle and keeps what it wrote.

use crate::common::{run_problem, schemes, Table};
use mpm::run::summary::Status;
use mpm::run::RunError;
use mpm::scene::Scheme;
use strum::IntoEnumIterator;

fn runs(scheme: &str, factor: f64, end_time: f64) -> bool {
    let (result, _dir) = run_problem(
        "vibrating_bar.toml",
        &[
            &format!("solver.scheme={scheme}"),
            &format!("solver.dt={}", 0.1 * factor),
            &format!("solver.end_time={end_time}"),
            "output.frames=0",
            "output.history_interval=10",
        ],
    );
    match result {
        Ok(_) => true,
        Err(RunError::Diverged { .. }) => false,
        Err(e) => panic!("{e}"),
    }
}

/// Largest stable factor on h/c, to ±1/64, over 200 s (≥ 1000 steps).
fn threshold(scheme: &str) -> f64 {
    let (mut lo, mut hi) = (0.25, 3.0);
    assert!(
        runs(scheme, lo, 200.0) && !runs(scheme, hi, 200.0),
        "{scheme}: threshold outside [0.25, 3]"
    );
    while hi - lo > 1.0 / 64.0 {
        let mid = 0.5 * (lo + hi);
        if runs(scheme, mid, 200.0) {
            lo = mid
        } else {
            hi = mid
        }
    }
    println!("{scheme}: stable at {lo:.3} h/c, diverges at {hi:.3} h/c within 200 s");
    lo
}

#[test]
fn critical_step_is_h_over_c() {
    let (result, _dir) = run_problem(
        "vibrating_bar.toml",
        &["solver.end_time=0.05", "output.frames=0"],
    );
    let s = result.unwrap();
    let dt_cr = s.dt_critical;
    // min over particles of h / (c + |v|), |v| ≤ 0.1: between 1/10.1 and 1/10.
    assert!(
        dt_cr > 1.0 / 10.1 - 1e-12 && dt_cr <= 0.1,
        "dt_critical = {dt_cr}"
    );
}

#[test]
fn measured_stability_limits() {
    for scheme in Scheme::iter() {
        let range = match scheme {
            Scheme::Usf | Scheme::Musl => 1.0..2.0,
            Scheme::Usl => 0.5..1.0,
        };
        let t = threshold(scheme.name());
        assert!(
            range.contains(&t),
            "{}: stability limit {t} h/c outside {range:?}",
            scheme.name()
        );
    }
}

#[test]
fn runs_at_nine_tenths_of_the_critical_step() {
    let usl = "its limit lies below h/c (measured_stability_limits)";
    for scheme in schemes(&[(Scheme::Usl, usl)]) {
        let scheme = scheme.name();
        let (result, dir) = run_problem(
            "vibrating_bar.toml",
            &[
                "solver.dt=0.09",
                "output.frames=0",
                &format!("solver.scheme={scheme}"),
            ],
        );
        assert_eq!(result.unwrap().status, Status::Completed);
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let e: Vec<f64> = h
            .col("kinetic")
            .iter()
            .zip(h.col("strain"))
            .map(|(k, s)| k + s)
            .collect();
        let growth = e.iter().cloned().fold(0.0, f64::max) / e[0];
        assert!(
            growth < 1.05,
            "{scheme}: energy grew by a factor {growth} at 0.9 h/c"
        );
    }
}

#[test]
fn diverges_at_twice_the_critical_step_and_stops_cleanly() {
    let (result, dir) = run_problem(
        "vibrating_bar.toml",
        &["solver.dt=0.2", "solver.end_time=300", "output.frames=300"],
    );
    let msg = match result {
        Err(RunError::Diverged { message: m, .. }) => m,
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
    let step = summary["diverged_step"].as_u64().unwrap();
    assert!(step > 1);
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    assert_eq!(
        h.col("t").len() as u64,
        step,
        "one history row per completed step (and t = 0) is kept"
    );
    let pvd = std::fs::read_to_string(dir.path().join("particles.pvd")).unwrap();
    assert!(
        pvd.matches("<DataSet").count() >= 2,
        "frames written before the divergence are listed"
    );
    assert!(
        !dir.path().join("particles_final.csv").exists(),
        "no final state is claimed for a diverged run"
    );
}
