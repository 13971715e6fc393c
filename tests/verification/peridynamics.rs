//! Bond-based (PMB) peridynamic bodies in explicit runs (issue 51, first
//! slice; `physics::peridynamics`): the elastic bar wave speed against
//! c0 = √(E/ρ), the shipped notched plate cracking from its notch, and the
//! scene keys' errors. The exact unit checks (Σ F = 0, rigid motions, a single
//! bond breaking, cut-bond energy against G0, interior energy against the
//! classical one) are next to the code (`physics::peridynamics::pmb`).

use crate::common::{assert_within, rejected_at, run_problem, run_text, Table};
use mpm::scene::Scene;

/// A free–free plane-stress bar L × W, Δx = 0.5 mm, m = 3, in its first
/// axial mode v = v0 cos(πx/L): the kinetic energy vanishes first at a quarter
/// period, T/4 = L/(2c), c the bar's wave speed.
fn bar(length: f64, width: f64) -> String {
    let cells = (length / 1e-3).round() as usize + 4;
    let rows = (width / 1e-3).round() as usize + 4;
    format!(
        r#"
dimension = 2
[grid]
min = [-0.002, -0.002]
max = [{gx}, {gy}]
cells = [{cells}, {rows}]
shape_function = "linear"
[[material]]
name = "al"
model = "linear_elastic"
density = 2700.0
youngs_modulus = 70e9
poisson_ratio = 0.333333
[[body]]
kind = "peridynamic"
plane = "stress"
material = "al"
shape = "rectangle"
min = [0.0, 0.0]
max = [{length}, {width}]
particles_per_cell = 2
velocity_expr = ["0.1*cos(pi*x/{length})", "0"]
[solver]
kind = "explicit"
end_time = {end}
[output]
frames = 0
history_interval = 0.0
"#,
        gx = length + 0.002,
        gy = width + 0.002,
        end = 0.4 * length / (70e9f64 / 2700.0).sqrt(),
    )
}

/// The first minimum of the kinetic energy: the time of the row before the
/// first rise, refined by a parabola through it and its neighbours.
fn first_minimum(t: &[f64], k: &[f64]) -> f64 {
    let i = (1..k.len() - 1)
        .find(|&i| k[i] <= k[i - 1] && k[i] < k[i + 1])
        .expect("the kinetic energy has a minimum");
    let (a, b, c) = (k[i - 1], k[i], k[i + 1]);
    let h = t[i] - t[i - 1];
    t[i] + 0.5 * h * (a - c) / (a - 2.0 * b + c)
}

#[test]
fn the_bar_wave_speed_is_the_elastic_one_to_the_surface_error() {
    let c0 = (70e9f64 / 2700.0).sqrt();
    let (length, width) = (0.1, 0.01);
    let (summary, dir) = run_text(&bar(length, width), &[]);
    summary.expect("the bar runs");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let quarter = first_minimum(h.col("t"), h.col("kinetic"));
    let c = length / (2.0 * quarter);
    // Bond-based with free surfaces: the bonds missing within δ of the bar's
    // four faces make it softer than E (no surface correction in this slice).
    assert_within("bar wave speed c/c0 − 1", c / c0 - 1.0, 0.10);
    // The mode is elastic: it lost no bond.
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    assert!(p.col("damage").iter().all(|&d| d == 0.0));
}

#[test]
fn the_notched_plate_cracks_from_its_notch() {
    let (summary, dir) = run_problem("peridynamic_plate.toml", &[]);
    let summary = summary.expect("the plate runs");
    println!("steps {}", summary.steps);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (x, y, d) = (p.col("X0"), p.col("Y0"), p.col("damage"));
    let max = d.iter().cloned().fold(0.0, f64::max);
    // Damage across the bottom half of the ligament below the notch (x within
    // 2δ of the middle), and none far from it in the corners.
    let band = |q: usize| (x[q] - 0.02).abs() < 0.003;
    let cracked = (0..d.len())
        .filter(|&q| band(q) && y[q] < 0.008 && d[q] > 0.3)
        .count();
    let corners = (0..d.len())
        .filter(|&q| (x[q] - 0.02).abs() > 0.012 && d[q] > 0.3)
        .count();
    println!("max damage {max:.3}, cracked below the notch {cracked}, in the corners {corners}");
    assert!(cracked > 0 && corners == 0);
}

const BODY: &str = r#"
dimension = 2
[grid]
min = [0.0, 0.0]
max = [1.0, 1.0]
cells = [10, 10]
[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 1.0
poisson_ratio = 0.25
[[body]]
kind = "peridynamic"
material = "m"
shape = "rectangle"
min = [0.2, 0.2]
max = [0.8, 0.8]
"#;

fn with(extra_body: &str, rest: &str) -> String {
    format!("{BODY}{extra_body}\n[solver]\nkind = \"explicit\"\nend_time = 1.0\n{rest}")
}

#[test]
fn the_scene_keys_of_a_peridynamic_body_are_checked_by_key() {
    // Runs as given (plane strain, ν = 1/4, m = 3).
    Scene::parse("scene.toml", &with("", ""), &[]).expect("valid");
    rejected_at(
        &with("plane = \"stress\"", ""),
        "material.0.poisson_ratio",
        &["1/3", "0.333333", "plane stress"],
    );
    rejected_at(&with("horizon = -1.0", ""), "body.0.horizon", &["positive"]);
    rejected_at(
        &with("horizon = 0.1\nhorizon_factor = 3.0", ""),
        "body.0.horizon_factor",
        &["not both"],
    );
    rejected_at(
        &with("horizon = 0.01", ""),
        "body.0.horizon",
        &["below the particle spacing"],
    );
    rejected_at(
        &with("fracture_energy = 1.0\ncritical_stretch = 0.01", ""),
        "body.0.critical_stretch",
        &["not both"],
    );
    rejected_at(
        &with("motion = \"free\"", ""),
        "body.0.motion",
        &["peridynamic"],
    );
    let implicit = with("", "").replace("kind = \"explicit\"", "kind = \"implicit\"");
    rejected_at(&implicit, "solver.kind", &["explicit stages only"]);
    // Its keys on a continuum body.
    let continuum = with("", "").replace("kind = \"peridynamic\"", "kind = \"continuum\"");
    rejected_at(
        &continuum.replace(
            "shape = \"rectangle\"",
            "shape = \"rectangle\"\nhorizon = 0.3",
        ),
        "body.0.horizon",
        &["not kind = \"peridynamic\""],
    );
    // Beside an MPM body (contact through the grid is a later slice).
    let two = format!(
        "{}\n[[material]]\nname = \"n\"\nmodel = \"linear_elastic\"\ndensity = 1.0\nyoungs_modulus = 1.0\npoisson_ratio = 0.3\n[[body]]\nmaterial = \"n\"\nshape = \"rectangle\"\nmin = [0.0, 0.0]\nmax = [0.1, 0.1]\n",
        with("", "")
    );
    rejected_at(&two, "body.1.kind", &["peridynamic bodies only"]);
}
