//! Coupled pore flow in explicit runs (`drainage = "coupled"`,
//! `physics::pore_flow`, docs/pore_water.md "Coupled flow"): Terzaghi's
//! one-dimensional consolidation of problems/terzaghi.toml, and the flow's
//! stable step.
//!
//! Terzaghi (1943, *Theoretical Soil Mechanics*, §§ 100–101): a layer of
//! height H drained at its top, impermeable at its base, under a load applied
//! at once, with the undrained start p0 = B q, B = K_f/(K_f + M):
//!
//!   p(z, t) = p0 Σ_m (2/M_m) sin(M_m z/H) exp(−M_m² T_v),   M_m = π(2m + 1)/2,
//!   U(T_v) = 1 − Σ_m (2/M_m²) exp(−M_m² T_v),   T_v = c_v t/H²,
//!
//! z the depth below the drained face, c_v = (k/γ_w)/(1/M + 1/K_f) (with a
//! compressible pore fluid the same diffusion equation holds with this c_v
//! and p0 = B q). U is the mean of 1 − p/p0 over the layer.

use crate::common::{assert_within, run_problem, Table};
use mpm::run::summary::Status;
use mpm::run::RunError;
use std::path::Path;

/// The scene's closed-form data (problems/terzaghi.toml).
const H: f64 = 1.0;
const Q: f64 = 1.0e4;
const M: f64 = 1.0e7;
const K_F: f64 = 8.0e7 / 0.4;
const MOBILITY: f64 = 1.0e-4 / 1.0e4;

/// B q and c_v.
fn p0() -> f64 {
    Q * K_F / (K_F + M)
}

fn c_v() -> f64 {
    MOBILITY / (1.0 / M + 1.0 / K_F)
}

/// The published degrees of consolidation (Terzaghi's table, e.g. Craig's
/// *Soil Mechanics*, table 7.1) at T_v = 0.01 … 1.0, the times of the scene's
/// particle files.
const U_TABLE: [(f64, f64); 7] = [
    (0.01, 0.1128),
    (0.05, 0.2523),
    (0.1, 0.3568),
    (0.2, 0.5041),
    (0.5, 0.7640),
    (0.8, 0.8874),
    (1.0, 0.9313),
];

/// Terzaghi's series at depth z and T_v (400 terms: converged for T_v ≥ 0.01).
fn terzaghi(z: f64, tv: f64) -> f64 {
    let sum: f64 = (0..400)
        .map(|m| {
            let mm = std::f64::consts::PI * (2 * m + 1) as f64 / 2.0;
            2.0 / mm * (mm * z / H).sin() * (-mm * mm * tv).exp()
        })
        .sum();
    p0() * sum
}

/// Per particle file of `dir`: T_v, U (volume mean of 1 − p/p0) and the
/// largest |p − p_exact|/q over the particles.
fn measured(dir: &Path) -> Vec<(f64, f64, f64)> {
    let index = Table::read(&dir.join("particle_times.csv")).unwrap();
    let files = index.text_column("file").unwrap();
    (index.col("t").iter().zip(files))
        .map(|(&t, file)| {
            let tv = c_v() * t / (H * H);
            let p = Table::read(&dir.join(file)).unwrap();
            let (y0, v0, pex) = (p.col("Y0"), p.col("volume0"), p.col("p_excess"));
            let volume: f64 = v0.iter().sum();
            let mean = (pex.iter().zip(v0)).map(|(p, v)| p * v).sum::<f64>() / volume;
            let worst = (y0.iter().zip(pex))
                .map(|(y, p)| (p - terzaghi(H - y, tv)).abs() / Q)
                .fold(0.0, f64::max);
            (tv, 1.0 - mean / p0(), worst)
        })
        .collect()
}

/// The shipped column (20 cells, 2 × 2 particles per cell): U within 0.01 of
/// the table at every T_v (the bound; measured ≤ 0.0055, at T_v =
/// 0.01), the pressure within 3 % of q from T_v = 0.2 on (measured 2.9 %,
/// 1.3 %, 0.59 %, 0.34 % at T_v = 0.2, 0.5, 0.8, 1: the largest at the
/// particle next to the drained face) and within 14 % at T_v ≤ 0.1 (13.2 %,
/// 5.9 %, 4.2 %: the steep start of the isochrone across the first cells).
/// Halving h halves the pressure error at T_v = 0.5 (first order at the
/// drained face): 10 → 20 cells.
#[test]
fn terzaghi_column_consolidates_as_the_closed_form() {
    let (summary, dir) = run_problem("terzaghi.toml", &[]);
    assert_eq!(summary.unwrap().status, Status::Completed);
    let rows = measured(dir.path());
    assert_eq!(rows.len(), U_TABLE.len());
    for (&(tv, u, _), &(tv_table, u_table)) in rows.iter().zip(&U_TABLE) {
        assert!(
            (tv - tv_table).abs() < 1e-4 * tv_table,
            "T_v {tv} against {tv_table}"
        );
        println!("T_v = {tv:.3}: U = {u:.4} (Terzaghi {u_table:.4})");
        assert_within(
            &format!("U − U_Terzaghi at T_v = {tv_table}"),
            u - u_table,
            0.01,
        );
    }
    for &(tv, _, worst) in &rows {
        let bound = if tv > 0.15 { 0.03 } else { 0.14 };
        assert_within(
            &format!("max |p − p_exact|/q at T_v = {tv:.2}"),
            worst,
            bound,
        );
    }
    let (coarse, coarse_dir) = run_problem(
        "terzaghi.toml",
        &[
            "grid.cells=[1,10]",
            "load.0.region_min=[0.0,0.95]",
            "output.particle_times=[5.25]",
        ],
    );
    assert_eq!(coarse.unwrap().status, Status::Completed);
    let (e_coarse, e_fine) = (measured(coarse_dir.path())[0].2, rows[4].2);
    let rate = (e_coarse / e_fine).log2();
    println!("T_v = 0.5: max |p − p_exact|/q {e_coarse:.4} (10 cells), {e_fine:.4} (20 cells): rate {rate:.2}");
    assert!(rate > 0.8, "rate {rate:.2} (measured 1.0)");
}

/// The flow's stable step h²/(2 D c_f) (`Drainage::stable_dt`) where it binds
/// (k ten times the scene's: c_f = 200 m²/s, the bound 3.125e-6 s against the
/// waves' 1.5e-4 s): the default step runs; a fixed step at 5 × the bound
/// still runs (measured: stable up to 5 ×, diverging at 6 ×), and one at 8 ×
/// stops cleanly with a diverged status, its warning naming the flow.
#[test]
fn pore_flow_runs_within_its_stable_step_and_stops_cleanly_beyond_it() {
    let base = [
        "material.0.hydraulic_conductivity=1e-2",
        "solver.end_time=0.02",
        "output.particle_times=[]",
    ];
    let bound = (0.05f64 * 0.05) / (2.0 * 2.0 * K_F * 1.0e-2 / 1.0e4);
    let run = |factor: Option<f64>| {
        let mut o: Vec<String> = base.iter().map(|s| s.to_string()).collect();
        if let Some(f) = factor {
            o.push(format!("solver.dt={}", f * bound));
        }
        let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
        match run_problem("terzaghi.toml", &o).0 {
            Ok(summary) => summary,
            Err(RunError::Diverged { summary, .. }) => *summary,
            Err(e) => panic!("{e}"),
        }
    };
    let default = run(None);
    assert_eq!(default.status, Status::Completed);
    assert!(
        (default.dt - bound).abs() < 1e-12 * bound,
        "dt {} against {bound}",
        default.dt
    );
    assert_eq!(run(Some(5.0)).status, Status::Completed);
    let beyond = run(Some(8.0));
    assert_eq!(beyond.status, Status::Diverged, "{beyond:?}");
    assert!(
        beyond
            .warnings
            .iter()
            .any(|w| w.contains("coupled pore flow")),
        "{:?}",
        beyond.warnings
    );
}

/// The same column undrained in an explicit run (`drainage = "undrained"`: no
/// flow, no drained face): once the load's wave has died out under the
/// damping, every particle carries p_ex = B q and σ′_yy = −(1 − B) q
/// (B = K_f/(K_f + M) = 0.9524; the closed form of undrained 1D loading).
/// Checked below the top cell: the traction acts at the top row of particles
/// (Y0 = 0.9875), which hands a quarter of it to the nodes at y = 0.95, so the
/// top cell carries 3/4 of q (measured there: p_ex 0.239 q below B q).
#[test]
fn undrained_column_takes_the_load_in_its_pore_water_in_an_explicit_run() {
    let text = std::fs::read_to_string(crate::common::problem("terzaghi.toml")).unwrap();
    let text = text
        .replace("drainage = \"coupled\"", "drainage = \"undrained\"")
        .replace("hydraulic_conductivity = 1.0e-4\n", "")
        .replace("water_unit_weight = 1.0e4\n", "")
        .replace(
            "face = \"ymax\"\ncondition = \"drained\"",
            "face = \"xmin\"\ncondition = \"roller\"",
        );
    let (summary, dir) = crate::common::run_text(
        &text,
        &["solver.end_time=0.5", "output.particle_times=[0.5]"],
    );
    assert_eq!(summary.unwrap().status, Status::Completed);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let b = K_F / (K_F + M);
    let below: Vec<usize> = (0..p.len()).filter(|&i| p.col("Y0")[i] < 0.95).collect();
    assert_eq!(below.len(), 4 * 19);
    let (pex, syy) = (p.col("p_excess"), p.col("syy"));
    let worst_p = (below.iter())
        .map(|&i| (pex[i] - b * Q).abs() / Q)
        .fold(0.0, f64::max);
    let worst_s = (below.iter())
        .map(|&i| (syy[i] + pex[i] + (1.0 - b) * Q).abs() / Q)
        .fold(0.0, f64::max);
    println!("max |p_ex − B q|/q {worst_p:.2e}, max |σ′_yy + (1 − B) q|/q {worst_s:.2e}");
    assert_within("max |p_ex − B q|/q", worst_p, 1e-3);
    assert_within("max |σ′_yy + (1 − B) q|/q", worst_s, 1e-3);
}

/// A prescribed pore pressure (`pore_pressure` on a drained face): the
/// unloaded column drained at its top (p = 0) with the excess pressure P0 =
/// 10 kPa held at its base from t = 0. The total stress stays zero, so p
/// diffuses with the same c_v from p = 0 to the linear steady profile:
///   p(z, t) = P0 z/H + Σ_n (2 P0 (−1)ⁿ/(nπ)) sin(nπ z/H) exp(−n²π² T_v),
/// z the depth. Measured max |p − p_exact|/P0: 0.044 at T_v = 0.1 and 0.025
/// at T_v = 0.5 (bounds 0.05 and 0.03), at the particles next to the two
/// held faces (a held node pulls the projection of its one-sided particles to
/// its value); 10 → 20 cells halves it at T_v = 0.5 (0.0502 → 0.0249, first
/// order; asserted > 0.8).
#[test]
fn a_held_pore_pressure_diffuses_into_the_column_as_the_closed_form() {
    let text = std::fs::read_to_string(crate::common::problem("terzaghi.toml")).unwrap();
    let i = text.find("# The top row of particles").unwrap();
    let j = text.find("[solver]").unwrap();
    let held = "[[boundary]]\nface = \"ymin\"\ncondition = \"drained\"\npore_pressure = 1.0e4\n\n";
    let text = format!("{}{held}{}", &text[..i], &text[j..]);
    let p_exact = |z: f64, tv: f64| {
        let series: f64 = (1..400)
            .map(|n| {
                let a = n as f64 * std::f64::consts::PI;
                2.0 * Q * (-1f64).powi(n) / a * (a * z / H).sin() * (-a * a * tv).exp()
            })
            .sum();
        Q * z / H + series
    };
    let worst = |cells: &str, times: &str| -> Vec<f64> {
        let (summary, dir) =
            crate::common::run_text(&text, &[cells, "solver.end_time=5.25", times]);
        assert_eq!(summary.unwrap().status, Status::Completed);
        let index = Table::read(&dir.path().join("particle_times.csv")).unwrap();
        let files = index.text_column("file").unwrap();
        (index.col("t").iter().zip(files))
            .map(|(&t, file)| {
                let p = Table::read(&dir.path().join(file)).unwrap();
                let tv = c_v() * t / (H * H);
                (p.col("Y0").iter().zip(p.col("p_excess")))
                    .map(|(y, pex)| (pex - p_exact(H - y, tv)).abs() / Q)
                    .fold(0.0, f64::max)
            })
            .collect()
    };
    let fine = worst("grid.cells=[1,20]", "output.particle_times=[1.05,5.25]");
    println!("max |p − p_exact|/P0 at T_v = 0.1, 0.5: {fine:.4?}");
    assert_within("max |p − p_exact|/P0 at T_v = 0.1", fine[0], 0.05);
    assert_within("max |p − p_exact|/P0 at T_v = 0.5", fine[1], 0.03);
    let coarse = worst("grid.cells=[1,10]", "output.particle_times=[5.25]");
    let rate = (coarse[0] / fine[1]).log2();
    println!(
        "T_v = 0.5: {:.4} (10 cells), {:.4} (20 cells): rate {rate:.2}",
        coarse[0], fine[1]
    );
    assert!(rate > 0.8, "rate {rate:.2} (measured 1.0)");
}
