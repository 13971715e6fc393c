//! The run's clock and what it records on the way (issue 56): history rows and
//! particle files at the step nearest each output time, written once; the last
//! step landing on the stage's end without a sliver step; summary.json's `dt`
//! the step asked for; a warning for a fixed explicit step above the critical one.

use crate::common::{run_text, Table, GOOD};
use mpm::run::summary::Summary;
use std::path::Path;

/// The `t` column of history.csv.
fn history_times(dir: &Path) -> Vec<f64> {
    Table::read(&dir.join("history.csv"))
        .unwrap()
        .col("t")
        .to_vec()
}

/// GOOD (an elastic bar whose critical step is 0.086) with overrides.
fn good(overrides: &[&str]) -> (Summary, tempfile::TempDir) {
    let (result, dir) = run_text(GOOD, overrides);
    (result.unwrap_or_else(|e| panic!("{e}")), dir)
}

/// Rows k × interval, each within half a step of its time, once: the times
/// summed step by step used to make every row after the first few one step late
/// (at 0.0101, 0.0202, … with Δt = 1e-4 against 0.01, 0.02, …).
#[test]
fn history_rows_fall_on_the_step_nearest_each_time() {
    let (dt, interval) = (1e-4, 0.01);
    let (_, dir) = good(&[
        "solver.dt=1e-4",
        "solver.end_time=1.0",
        "output.history_interval=0.01",
        "output.frames=0",
    ]);
    let t = history_times(dir.path());
    assert_eq!(t.len(), 101, "one row at each of 0, 0.01, …, 1: {t:?}");
    for (k, &tk) in t.iter().enumerate() {
        let asked = k as f64 * interval;
        assert!(
            (tk - asked).abs() <= 0.5 * dt * (1.0 + 1e-9),
            "row {k} at t = {tk}, for {asked}"
        );
    }
}

/// 10 quasi-static load steps of 0.1 sum to 0.9999999999999999: the last step
/// used to be recorded there and again at the end time 1.
#[test]
fn the_last_row_is_written_once_at_the_end() {
    for steps in [7, 10, 30] {
        let (result, dir) = crate::common::run_problem(
            "column.toml",
            &[&format!("solver.load_steps={steps}"), "output.frames=0"],
        );
        let summary = result.unwrap();
        let t = history_times(dir.path());
        assert_eq!(t.len(), summary.steps + 1, "{steps} load steps: {t:?}");
        assert_eq!(t.last(), Some(&1.0), "{steps} load steps: {t:?}");
        assert!(t.windows(2).all(|w| w[1] > w[0]), "{t:?}");
    }
}

/// Δt = 1e-5 over 0.99 s: 99,000 steps whose sum falls 1.9e-12 s short of the
/// end, which used to take a 99,001st step of 1.9e-12 s and report it as the
/// run's `dt`. A Δt that does not divide the stage ends it with a shorter step,
/// and summary.json still reports the one asked for.
#[test]
fn a_fixed_step_ends_the_stage_without_a_sliver_and_is_reported_as_asked() {
    let (summary, dir) = good(&[
        "solver.dt=1e-5",
        "solver.end_time=0.99",
        "output.history_interval=0.1",
        "output.frames=0",
    ]);
    assert_eq!(summary.steps, 99_000);
    assert_eq!((summary.dt, summary.stages[0].dt), (1e-5, 1e-5));
    assert_eq!(history_times(dir.path()).last(), Some(&0.99));

    let (summary, _) = good(&["solver.dt=3e-3", "solver.end_time=0.1"]);
    assert_eq!(summary.steps, 34, "33 steps of 3e-3 and one of 1e-3");
    assert_eq!(summary.dt, 3e-3);
}

/// A fixed explicit step above the critical one runs (stability studies need
/// it) and says so once, with the critical step; one below it says nothing.
#[test]
fn a_fixed_explicit_step_above_the_critical_one_is_warned_of() {
    let (summary, _) = good(&["solver.dt=0.1", "solver.end_time=0.5"]);
    assert_eq!(summary.steps, 5);
    assert_eq!(summary.warnings.len(), 1, "{:?}", summary.warnings);
    let w = &summary.warnings[0];
    let critical = format!("{:.6e}", summary.dt_critical);
    assert!(
        w.contains("dt = 1e-1") && w.contains(&critical) && w.contains("critical step"),
        "{w} (critical step {critical})"
    );
    assert_eq!(summary.stages[0].warnings, summary.warnings);

    let (summary, _) = good(&["solver.dt=0.08", "solver.end_time=0.5"]);
    assert_eq!(summary.warnings, Vec::<String>::new());
}

/// In a staged scene the warning names its stage, and each stage is judged on
/// its own step.
#[test]
fn a_stage_above_the_critical_step_is_named() {
    let staged = GOOD.replace(
        "[solver]\nkind = \"explicit\"\nend_time = 1.0\ncfl = 0.5\n",
        "[[stage]]\nname = \"safe\"\nkind = \"explicit\"\nend_time = 0.2\ndt = 0.05\n\n\
         [[stage]]\nname = \"bold\"\nkind = \"explicit\"\nend_time = 0.2\ndt = 0.1\n",
    );
    assert_ne!(staged, GOOD);
    let (result, _) = run_text(&staged, &[]);
    let summary = result.unwrap();
    assert_eq!(summary.warnings.len(), 1, "{:?}", summary.warnings);
    assert!(
        summary.warnings[0].starts_with("stage bold: "),
        "{:?}",
        summary.warnings
    );
    assert!(summary.stages[0].warnings.is_empty());
}

/// particles_NNNN.csv at the listed times and at k × interval, each the state
/// of the step nearest its time (the file at 0.5001 is the one a run ending at
/// 0.5 leaves as particles_final.csv), listed in particle_times.csv. Δt = 2⁻¹⁰
/// sums without round-off.
#[test]
fn particle_files_at_chosen_times() {
    let dt = 2f64.powi(-10);
    let step = format!("solver.dt={dt}");
    let (_, dir) = good(&[
        &step,
        "solver.end_time=1.0",
        "output.particle_times=[0.5001, 0.0]",
        "output.particle_interval=0.4",
        "output.frames=0",
    ]);
    let index = Table::read(&dir.path().join("particle_times.csv")).unwrap();
    let (t, steps) = (index.col("t"), index.col("step"));
    // 0 (listed, and k = 0 of the interval: one file), 0.4, 0.5001, 0.8 at
    // steps 409.6 → 410, 512.1 → 512, 819.2 → 819.
    let expected = [0.0, 410.0, 512.0, 819.0];
    assert_eq!(steps, expected, "{t:?}");
    for (k, &n) in expected.iter().enumerate() {
        assert_eq!(t[k], n * dt);
        assert!(dir.path().join(format!("particles_{k:04}.csv")).exists());
    }
    let (_, half) = good(&[&step, "solver.end_time=0.5", "output.frames=0"]);
    let dumped = std::fs::read(dir.path().join("particles_0002.csv")).unwrap();
    let final_ = std::fs::read(half.path().join("particles_final.csv")).unwrap();
    assert!(
        dumped == final_,
        "the file at 0.5001 is the state at step 512"
    );
}
