//! Elastic column under self-weight by dynamic relaxation (reference README item 2).
//! At the material point from height Y the exact Cauchy stress is
//! σ_yy = −ρ g (l0 − Y) (the weight above it over an unchanged cross-section, so it
//! holds at finite strain too). Error measure (normalised L2 over the reference
//! volume): e = √(Σ V0_p (σ_yy,p − σ_a(Y_p))²) / (ρ g l0 √(Σ V0_p)).

mod common;
use common::{run_problem, Table};

const RHO_G_L0: f64 = 80.0 * 10.0 * 50.0;

fn column_error(shape: &str, cells: usize) -> f64 {
    let (result, dir) = run_problem(
        "column_explicit.toml",
        &[
            &format!("grid.shape_function={shape}"),
            &format!("grid.cells=[1,{cells}]"),
            "output.frames=0",
            "output.history_interval=1.0",
        ],
    );
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv"));
    let (y0, syy, v0) = (p.col("Y0"), p.col("syy"), p.col("volume0"));
    let (mut num, mut vol) = (0.0, 0.0);
    for i in 0..y0.len() {
        let exact = -80.0 * 10.0 * (50.0 - y0[i]);
        num += v0[i] * (syy[i] - exact).powi(2);
        vol += v0[i];
    }
    (num / vol).sqrt() / RHO_G_L0
}

fn study(shape: &str, cells: &[usize]) -> Vec<f64> {
    let errors: Vec<f64> = cells.iter().map(|&n| column_error(shape, n)).collect();
    for i in 0..cells.len() {
        let rate = if i > 0 {
            (errors[i - 1] / errors[i]).log2()
        } else {
            f64::NAN
        };
        println!(
            "{shape:>8} cells {:>4}: error {:.4e}  rate {rate:.2}",
            cells[i], errors[i]
        );
    }
    errors
}

fn rate(e: &[f64]) -> f64 {
    (e[0] / e[e.len() - 1]).log2() / (e.len() - 1) as f64
}

#[test]
fn gimp_converges() {
    let e = study("ugimp", &[8, 16, 32, 64]);
    assert!(rate(&e) > 0.8, "uGIMP mean rate {:.2} below 0.8", rate(&e));
}

#[test]
fn cpdi_converges() {
    let e = study("cpdi", &[8, 16, 32, 64]);
    assert!(rate(&e) > 0.8, "CPDI mean rate {:.2} below 0.8", rate(&e));
}

#[test]
fn bsplines_converge() {
    let e = study("bspline2", &[8, 16, 32, 64]);
    assert!(
        rate(&e) > 0.8,
        "quadratic B-spline mean rate {:.2} below 0.8",
        rate(&e)
    );
}

/// Standard MPM: particles cross cells as the column settles, and the error stalls.
#[test]
fn standard_mpm_does_not_converge() {
    let e = study("linear", &[8, 16, 32, 64]);
    assert!(
        rate(&e) < 0.5,
        "linear MPM mean rate {:.2}: expected no convergence",
        rate(&e)
    );
    let gimp = column_error("ugimp", 64);
    assert!(
        e[3] > 2.0 * gimp,
        "at 64 cells linear MPM ({:.3e}) should be clearly worse than GIMP ({gimp:.3e})",
        e[3]
    );
}
