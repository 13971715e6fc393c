//! Rough rigid base (`condition = "friction"`): an elastic block on a base tilted
//! by rotating gravity, g = 9.81 (sin θ, −cos θ) (`problems/sliding_block.toml`).
//! Rigid-body closed form: the centre of mass moves x(t) = ½ g t² (sin θ − μ cos θ)
//! when tan θ > μ, and not at all when tan θ ≤ μ.
//!
//! The block starts stress-free, so its weight comes on suddenly and the base
//! pressure rings between 0 and twice the weight (period 4H/c = 0.02 s); averaged
//! over a slide this does not matter, but near the threshold the lightly loaded
//! instants let a sticking block creep. The sticking case therefore uses a little
//! local damping (10 %), which would only slow a frictionless block by 10 %.
//! FLIP 0.99: pure FLIP with a one-sided wall gains energy slowly (the block
//! hops on its base); a touch of PIC removes that.

mod common;
use common::{run_problem, Table};

const G: f64 = 9.81;

/// Centre-of-mass displacement along the base at the end (0.5 s).
fn slide(theta_deg: f64, mu: f64, damping: f64) -> (f64, f64) {
    let th = theta_deg.to_radians();
    let gravity = format!("gravity=[{},{}]", G * th.sin(), -G * th.cos());
    let mu = format!("boundary.0.friction_coefficient={mu}");
    let damping = format!("solver.damping={damping}");
    let (result, dir) = run_problem(
        "sliding_block.toml",
        &[&gravity, &mu, &damping, "solver.flip=0.99"],
    );
    let summary = result.unwrap();
    assert_eq!(summary.json["status"], "completed");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, x) = (h.col("t"), h.col("body0_x"));
    (*t.last().unwrap(), x.last().unwrap() - x[0])
}

fn closed_form(theta_deg: f64, mu: f64, t: f64) -> f64 {
    let th = theta_deg.to_radians();
    0.5 * G * t * t * (th.sin() - mu * th.cos()).max(0.0)
}

#[test]
fn sliding_block_follows_the_closed_form() {
    // (θ, μ): frictionless, and two sliding cases well above the threshold (near
    // it, at θ = 45°, μ = 0.5, the ringing base pressure costs 2 %).
    for (theta, mu) in [(30.0, 0.0), (30.0, 0.3), (45.0, 0.3)] {
        let (t, x) = slide(theta, mu, 0.0);
        let exact = closed_form(theta, mu, t);
        let err = (x / exact - 1.0).abs();
        println!("theta {theta} mu {mu}: x = {x:.5} m, closed form {exact:.5} m, error {err:.2e}");
        assert!(err < 0.02, "theta {theta} mu {mu}: x = {x}, exact {exact}");
    }
}

#[test]
fn block_sticks_when_tan_theta_is_below_mu() {
    // tan 30° = 0.577 < μ = 0.7: the block must stay, while without friction the
    // same damped run slides ~0.55 m.
    let (_, x) = slide(30.0, 0.7, 0.1);
    let (t, free) = slide(30.0, 0.0, 0.1);
    println!(
        "stick: x = {x:.2e} m; frictionless damped: {free:.3} m (undamped closed form {:.3})",
        closed_form(30.0, 0.0, t)
    );
    assert!(free > 0.5, "frictionless damped run moved only {free}");
    assert!(x.abs() < 2e-3, "block crept {x} m with tan θ < μ");
}
