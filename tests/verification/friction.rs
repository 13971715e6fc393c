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

use crate::common::{assert_within, run_problem, Table};
use mpm::run::summary::Status;

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
    assert_eq!(summary.status, Status::Completed);
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
    // (θ, μ, tolerance): frictionless, and two sliding cases well above the
    // threshold (near it, at θ = 45°, μ = 0.5, the ringing base pressure costs
    // 2 %). Measured +0.043 %, +0.25 %, −0.11 %.
    for (theta, mu, tolerance) in [(30.0, 0.0, 1e-3), (30.0, 0.3, 6e-3), (45.0, 0.3, 3e-3)] {
        let (t, x) = slide(theta, mu, 0.0);
        let exact = closed_form(theta, mu, t);
        println!("theta {theta} mu {mu}: x = {x:.5} m, closed form {exact:.5} m");
        let what = format!("theta {theta} mu {mu}: error");
        assert_within(&what, x / exact - 1.0, tolerance);
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

/// history.csv of `problems/NAME` with its solver lines `from` replaced by
/// `to` (an implicit run of an explicit scene); the run must complete.
fn history_with_solver(name: &str, from: &str, to: &str) -> Table {
    let text = std::fs::read_to_string(crate::common::problem(name)).unwrap();
    assert!(text.contains(from), "{name} has no `{from}`");
    let (result, dir) = crate::common::run_text(&text.replace(from, to), &[]);
    assert_eq!(result.unwrap().status, Status::Completed);
    Table::read(&dir.path().join("history.csv")).unwrap()
}

/// Outputs of a run (for byte comparisons).
fn outputs(dir: &tempfile::TempDir, files: &[&str]) -> Vec<Vec<u8>> {
    files
        .iter()
        .map(|f| std::fs::read(dir.path().join(f)).unwrap())
        .collect()
}

#[test]
fn friction_face_is_fixed_in_implicit_steps() {
    // The smooth Tresca footing (3 load steps to 1.5 mm, into the plastic range)
    // on a friction base instead of a fixed one: the same constraints, so the
    // same reactions, load–settlement curve and particles, byte for byte.
    let base = ["solver.load_steps=3", "solver.end_time=0.15"];
    let (fixed, dir_fixed) = run_problem("footing_tresca.toml", &base);
    fixed.unwrap();
    let friction = [
        "solver.load_steps=3",
        "solver.end_time=0.15",
        "boundary.2.condition=friction",
        "boundary.2.friction_coefficient=0.1",
    ];
    let (rough, dir_rough) = run_problem("footing_tresca.toml", &friction);
    let rough = rough.unwrap();
    let files = ["footing.csv", "particles_final.csv", "newton.csv"];
    let (a, b) = (outputs(&dir_fixed, &files), outputs(&dir_rough, &files));
    for (k, f) in files.iter().enumerate() {
        // newton.csv carries wall-clock seconds: compare it without them.
        let strip = |t: &[u8]| -> Vec<String> {
            String::from_utf8_lossy(t)
                .lines()
                .map(|l| {
                    let mut c: Vec<&str> = l.split(',').collect();
                    if c.len() > 7 {
                        c.remove(7);
                    }
                    c.join(",")
                })
                .collect()
        };
        assert!(
            strip(&a[k]) == strip(&b[k]),
            "{f} differs: friction base vs fixed base"
        );
    }
    assert!(rough.footing.unwrap().limit_pressure > 0.0);

    // A block on a base tilted by 30° with μ = 0.3 < tan 30° slides in the
    // explicit solver (sliding_block_follows_the_closed_form); in a quasi-static
    // implicit step the base holds it: only the elastic shear of the block moves
    // its centre, by about ρ g sin θ H² / (3G) = 1.1e-4 m in 1D simple shear
    // (measured 1.3e-4 m; the slide would be 0.29 m in 0.5 s).
    let h = history_with_solver(
        "sliding_block.toml",
        "kind = \"explicit\"\nend_time = 0.5\ncfl = 0.5",
        "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 2",
    );
    let x = h.col("body0_x");
    let moved = x.last().unwrap() - x[0];
    println!("implicit block on a friction base tilted 30°, μ = 0.3: centre moved {moved:.2e} m");
    let shear = 1000.0 * G * 0.5 * 0.25 / (3.0 * 1.0e7 / 2.6);
    assert!(
        moved.abs() < 2.0 * shear,
        "the block slid {moved} m in an implicit step (elastic shear {shear} m)"
    );
}

/// Newmark's sliding block (Newmark 1965, Géotechnique 15(2), the single
/// rectangular pulse): `problems/newmark_sliding_block.toml`, a stiff block on a
/// rough base inclined at θ = 20° (μ = 0.5, tilted gravity), the base (the
/// friction face) shaken along itself by an acceleration pulse A = 0.5 g for
/// t0 = 0.2 s from t = 0.3 s. The yield acceleration a_y = g (μ cos θ − sin θ)
/// = 1.254 m/s² < A, so the block slips down the slope relative to the base by
///   d = A (A − a_y) t0² / (2 a_y) = 0.2856 m
/// and then stays. Measured at the end (1.4 s): +0.72 % (bound 5 %, the
/// issue's), the slip over the last 0.2 s 1.6e-4 m; on a grid twice as fine
/// +2.0 % (a slow creep after the stop, 1.5 mm per 0.1 s). A pulse below the
/// yield acceleration (A = 0.1 g) moves the block by 0.19 mm (bound 1 mm). The base's
/// displacement is −A F₂(t) with F₂ the double integral of the pulse.
#[test]
fn shaken_block_slips_by_newmarks_displacement() {
    let th = 20f64.to_radians();
    let a_y = G * (0.5 * th.cos() - th.sin());
    let (t0, start) = (0.2, 0.3);
    // F₂ of the pulse (1 on [start, start + t0], ramps of 1e-4 s at its ends:
    // their effect on the base's displacement is below 1e-5 of d).
    let base = |t: f64, a: f64| {
        let tau = (t - start).clamp(0.0, t0);
        -a * (0.5 * tau * tau + t0 * (t - start - t0).max(0.0))
    };
    let slip = |a: f64| {
        let (result, dir) = run_problem(
            "newmark_sliding_block.toml",
            &[&format!("boundary.0.acceleration=[{},0.0]", -a)],
        );
        assert_eq!(result.unwrap().status, Status::Completed);
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let (t, x) = (h.col("t"), h.col("body0_x"));
        let rel: Vec<f64> = (t.iter().zip(x))
            .map(|(&s, &xs)| xs - x[0] - base(s, a))
            .collect();
        let n = t.len();
        let back = t.iter().position(|&s| s >= t[n - 1] - 0.2).unwrap();
        (rel[n - 1], rel[n - 1] - rel[back])
    };
    let a = 0.5 * G;
    let exact = a * (a - a_y) * t0 * t0 / (2.0 * a_y);
    let (d, late) = slip(a);
    println!("slip {d:.4} m against Newmark's {exact:.4} m; over the last 0.2 s {late:.2e} m");
    assert_within("slip / Newmark − 1", d / exact - 1.0, 0.05);
    assert!(
        late.abs() < 0.01 * exact,
        "still slipping: {late:.2e} m in 0.2 s"
    );
    let (small, _) = slip(0.1 * G);
    println!("below the yield acceleration: slip {small:.2e} m");
    assert!(
        small.abs() < 1e-3,
        "slipped {small:.2e} m under A = 0.1 g < a_y"
    );
    // Newmark implicit steps hold a friction face's nodes to the wall: the block
    // rides with the shaken base (which moves 0.98 m) up to its elastic shear
    // (measured |x − u_base| ≤ 3.8e-4 m).
    let h = history_with_solver(
        "newmark_sliding_block.toml",
        "kind = \"explicit\"\nend_time = 1.4\ncfl = 0.5\nflip = 0.0\n",
        "kind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 1.4\ndt = 0.01\n",
    );
    let (t, x) = (h.col("t"), h.col("body0_x"));
    let worst =
        (t.iter().zip(x)).fold(0.0f64, |w, (&s, &xs)| w.max((xs - x[0] - base(s, a)).abs()));
    println!(
        "implicit: |x − u_base| ≤ {worst:.2e} m (base {:.3} m)",
        base(1.4, a)
    );
    assert!(
        worst < 1e-3,
        "the block left the implicit wall by {worst:.2e} m"
    );
}
