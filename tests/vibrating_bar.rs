//! Axially vibrating bar (reference README item 1): fixed at x = 0, free at x = 25,
//! E = 100, ρ = 1, v0 = 0.1, so ω1 = π/50 · 10 = 0.6283 rad/s and the period is 10 s.
//! The period comes from the zero crossings of the bar's mean velocity, the energy
//! from history.csv (kinetic + strain; no external work).

mod common;
use common::{run_problem, zero_crossings, Table};

struct Bar {
    period: f64,
    /// max |E(t) − E(0)| / E(0)
    drift: f64,
    /// (E(0) − E(end)) / E(0)
    loss: f64,
}

fn bar(scheme: &str, shape: &str) -> Bar {
    let (result, dir) = run_problem(
        "vibrating_bar.toml",
        &[
            &format!("solver.scheme={scheme}"),
            &format!("grid.shape_function={shape}"),
            "output.frames=0",
        ],
    );
    result.unwrap();
    let h = Table::read(&dir.path().join("history.csv"));
    let (t, v) = (h.col("t"), h.col("body0_vx"));
    let zc = zero_crossings(t, v);
    assert!(
        zc.len() >= 5,
        "expected at least 5 zero crossings in 30 s, found {}",
        zc.len()
    );
    let period = 2.0 * (zc[zc.len() - 1] - zc[0]) / (zc.len() - 1) as f64;
    let e: Vec<f64> = h
        .col("kinetic")
        .iter()
        .zip(h.col("strain"))
        .map(|(k, s)| k + s)
        .collect();
    let e0 = e[0];
    let drift = e.iter().map(|x| (x - e0).abs()).fold(0.0, f64::max) / e0;
    let loss = (e0 - e[e.len() - 1]) / e0;
    println!("{scheme:>4} {shape:>8}: period {period:.5} s (error {:+.3} %), energy drift {:.3e}, final loss {:.3e}", (period / 10.0 - 1.0) * 100.0, drift, loss);
    Bar {
        period,
        drift,
        loss,
    }
}

/// Initial energy ½ ρ v0² ∫ sin²(βx) dx = ½ · 0.01 · 12.5 = 0.0625.
#[test]
fn initial_energy_matches_the_mode() {
    let (result, dir) = run_problem(
        "vibrating_bar.toml",
        &["solver.end_time=0.1", "output.frames=0"],
    );
    result.unwrap();
    let h = Table::read(&dir.path().join("history.csv"));
    let k0 = h.col("kinetic")[0];
    assert!(
        (k0 / 0.0625 - 1.0).abs() < 2e-3,
        "kinetic energy at t = 0: {k0} (expected 0.0625 to 0.2 %)"
    );
}

#[test]
fn usf_and_musl_period_within_one_percent_and_energy_conserved() {
    for scheme in ["usf", "musl"] {
        let b = bar(scheme, "linear");
        assert!(
            (b.period / 10.0 - 1.0).abs() < 0.01,
            "{scheme}: period {} s not within 1 % of 10 s",
            b.period
        );
        assert!(
            b.drift < 0.02,
            "{scheme}: energy drift {:.3e} above 2 %",
            b.drift
        );
    }
}

#[test]
fn usl_loses_energy_that_musl_keeps() {
    let usl = bar("usl", "linear");
    let musl = bar("musl", "linear");
    assert!(
        (usl.period / 10.0 - 1.0).abs() < 0.01,
        "usl period {}",
        usl.period
    );
    assert!(
        usl.loss > 2.0 * musl.loss.abs(),
        "USL loss {:.3e} should exceed MUSL's {:.3e} clearly",
        usl.loss,
        musl.loss
    );
}

#[test]
fn every_shape_function_gets_the_period() {
    for shape in ["ugimp", "cpgimp", "cpdi", "bspline2", "bspline3"] {
        let b = bar("musl", shape);
        assert!(
            (b.period / 10.0 - 1.0).abs() < 0.01,
            "{shape}: period {} s",
            b.period
        );
        assert!(b.drift < 0.02, "{shape}: energy drift {:.3e}", b.drift);
    }
}
