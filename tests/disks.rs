//! Two elastic disks colliding (Sulsky, Chen & Schreyer 1994): kinetic energy turns
//! into strain energy during the impact and back after it; the total is conserved
//! to a stated bound, and the disks rebound.

mod common;
use common::{run_problem, Table};

fn disks(scheme: &str) -> (Vec<f64>, Vec<f64>, Vec<f64>, Table) {
    let (result, dir) = run_problem(
        "disks.toml",
        &[&format!("solver.scheme={scheme}"), "output.frames=0"],
    );
    result.unwrap();
    let h = Table::read(&dir.path().join("history.csv"));
    let (k, s) = (h.col("kinetic").to_vec(), h.col("strain").to_vec());
    let total: Vec<f64> = k.iter().zip(&s).map(|(a, b)| a + b).collect();
    (k, s, total, h)
}

#[test]
fn energy_is_exchanged_and_conserved() {
    for scheme in ["usf", "musl"] {
        let (k, s, total, h) = disks(scheme);
        let e0 = total[0];
        // m v² with m = ρπr² per disk, |v|² = 0.02: 2 · ½ · 1000π·0.04 · 0.02 ≈ 2.513 J (lattice area differs slightly)
        assert!(
            (k[0] / 2.513 - 1.0).abs() < 0.05,
            "initial kinetic energy {}",
            k[0]
        );
        let k_min = k.iter().cloned().fold(f64::INFINITY, f64::min);
        let s_max = s.iter().cloned().fold(0.0, f64::max);
        let drift = total.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / e0;
        let vx_end = *h.col("body0_vx").last().unwrap();
        println!("{scheme}: E0 {e0:.4}, min kinetic {:.3} E0, max strain {:.3} E0, max |ΔE|/E0 {drift:.3e}, final lower-disk vx {vx_end:.4}", k_min / e0, s_max / e0);
        assert!(
            k_min < 0.3 * e0,
            "{scheme}: kinetic energy should drop during impact, min {k_min}"
        );
        assert!(
            s_max > 0.5 * e0,
            "{scheme}: strain energy should peak during impact, max {s_max}"
        );
        assert!(
            drift < 0.1,
            "{scheme}: total energy varies by {drift:.3e} (bound 10 %)"
        );
        assert!(
            vx_end < -0.05,
            "{scheme}: lower disk should rebound, final vx {vx_end}"
        );
    }
}
