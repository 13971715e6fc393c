//! Loads, prescribed velocities and the energy balance with gravity, each against
//! a closed-form static or energy result.

use crate::common::{assert_within, face, face_with, run_problem, run_text, Block, Table, GOOD};

/// A bar [0,10]×[0,1] fixed at x = 0, loaded at its free end, relaxed dynamically
/// (PIC + local damping). E = 10⁴, ν = 0, so a end load of 10 N per unit width gives
/// σ_xx = 10 everywhere (strain 10⁻³).
const BAR: Block = Block {
    grid_max: [12.0, 1.0],
    cells: [12, 1],
    body_max: [10.0, 1.0],
    body_keys: "name = \"bar\"\nparticles_per_cell = [2, 2]",
    faces: &[
        face("xmin", "fixed"),
        face("ymin", "roller"),
        face("ymax", "roller"),
    ],
    solver: "kind = \"explicit\"\nend_time = 5.0\ndamping = 0.5\nflip = 0.0",
    output: "frames = 0\nhistory_interval = 0.5",
    ..Block::DEFAULT
};

/// σ_xx of the particles outside the loaded cell [9, 10]: a particle load reaches
/// the grid through its shape functions (75 % / 25 % to the nodes at x = 10 and 9
/// for the particle at 9.75), so inside that cell the stress is 7.5, not 10.
fn end_load_stress(load: &str) -> Vec<f64> {
    let (result, dir) = run_text(&format!("{}{load}", BAR.toml()), &[]);
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    p.col("sxx")
        .iter()
        .zip(p.col("X0"))
        .filter(|(_, x)| **x < 9.0)
        .map(|(s, _)| *s)
        .collect()
}

/// Every σ_xx within `tolerance` of `expected`, relative.
fn assert_uniform(sxx: &[f64], expected: f64, what: &str, tolerance: f64) {
    let worst = sxx
        .iter()
        .map(|s| s / expected - 1.0)
        .fold(0.0, |w: f64, e| if e.abs() > w.abs() { e } else { w });
    assert_within(
        &format!("{what}: largest σ_xx / {expected} − 1"),
        worst,
        tolerance,
    );
}

#[test]
fn traction_on_the_end_face() {
    let load = "[[load]]\nkind = \"traction\"\nregion_min = [9.5, 0.0]\nregion_max = [10.0, 1.0]\nface = \"xmax\"\ntraction = [10.0, 0.0]\n";
    // Measured −1.0e-3.
    assert_uniform(&end_load_stress(load), 10.0, "traction", 2.5e-3);
}

#[test]
fn point_load_shared_by_the_end_particles() {
    let load = "[[load]]\nkind = \"point\"\nbody = \"bar\"\nregion_min = [9.5, 0.0]\nregion_max = [10.0, 1.0]\nforce = [10.0, 0.0]\nramp_time = 1.0\n";
    // Measured −1.0e-3.
    assert_uniform(&end_load_stress(load), 10.0, "point load", 2.5e-3);
}

/// A block filling the grid, stretched by a prescribed velocity on xmax
/// (v = 10⁻³ m/s for 1 s, slowly compared with the wave transit of 0.01 s):
/// σ_xx = E ln(1 + v t / L) for the Jaumann-rate material in uniaxial strain.
#[test]
fn prescribed_velocity_stretches_a_block() {
    const STRETCHED: Block = Block {
        faces: &[
            face("xmin", "roller"),
            face("ymin", "roller"),
            face_with(
                "xmax",
                "velocity",
                "velocity = [1.0e-3, 0.0]\ncomponents = [\"x\"]",
            ),
        ],
        solver: "kind = \"explicit\"\nend_time = 1.0\ndamping = 0.3\nflip = 0.0",
        output: "frames = 0\nhistory_interval = 0.1",
        ..Block::DEFAULT
    };
    let (result, dir) = run_text(&STRETCHED.toml(), &[]);
    result.unwrap();
    let expected = 1.0e4 * (1.0f64 + 1.0e-3).ln();
    assert_uniform(
        Table::read(&dir.path().join("particles_final.csv"))
            .unwrap()
            .col("sxx"),
        expected,
        "prescribed velocity",
        1.5e-3, // measured +5.0e-4
    );
}

/// Without damping, the work of gravity equals kinetic plus strain energy
/// (column under sudden gravity, MUSL with FLIP, 2 s ≈ one period).
#[test]
fn energy_balance_with_gravity() {
    let (result, dir) = run_problem(
        "column_explicit.toml",
        &[
            "solver.damping=0",
            "solver.flip=1",
            "solver.end_time=2",
            "grid.cells=[1,32]",
            "output.frames=0",
            "output.history_interval=0",
        ],
    );
    result.unwrap();
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let w_max = h.col("external_work").iter().cloned().fold(0.0, f64::max);
    let worst = (0..h.col("t").len())
        .map(|i| (h.col("kinetic")[i] + h.col("strain")[i] - h.col("external_work")[i]).abs())
        .fold(0.0, f64::max);
    println!("max |K + U − W| = {worst:.4e} with max W = {w_max:.4e}");
    assert!(w_max > 1e4, "gravity does work: {w_max}");
    assert!(
        worst < 0.03 * w_max,
        "energy balance off by {:.2} % of the work",
        100.0 * worst / w_max
    );
}

#[test]
fn gravity_raised_over_a_ramp_time_gives_the_ramped_free_fall() {
    // An elastic block in free fall (nothing touches it) with gravity raised
    // linearly over T = 0.1 s: y(t) = −g ((t − T/2)²/2 + T²/24) for t ≥ T, the
    // fall of a sudden load at T/2 plus g T²/24; with g = 1 at t = 0.3 s
    // 0.031667 m against 0.045 m for gravity at once. The kinetic energy is the
    // work gravity did. Measured: 0.031654 m (−4.06e-4), kinetic energy equal to
    // the work to 1.4e-15.
    let text = GOOD
        .replace("dimension = 2", "dimension = 2\ngravity = [0.0, -1.0]")
        .replace("cfl = 0.5", "cfl = 0.5\ngravity_ramp_time = 0.1")
        .replace(
            "min = [0.0, 0.0]\nmax = [4.0, 1.0]\ncells = [4, 1]",
            "min = [-0.5, -0.5]\nmax = [2.5, 1.5]\ncells = [30, 20]",
        );
    let (result, dir) = run_text(&text, &["solver.end_time=0.3", "output.frames=0"]);
    result.expect("the block falls");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let t = *h.col("t").last().unwrap();
    let fall = h.col("body0_y")[0] - h.col("body0_y").last().unwrap();
    let (g, ramp) = (1.0, 0.1);
    let te = t - 0.5 * ramp;
    let exact = g * (0.5 * te * te + ramp * ramp / 24.0);
    let (kinetic, work) = (
        *h.col("kinetic").last().unwrap(),
        *h.col("external_work").last().unwrap(),
    );
    println!(
        "ramped free fall at t = {t}: {fall:.6} m against {exact:.6} m ({:.2e}); kinetic {kinetic:.6e}, work {work:.6e}",
        fall / exact - 1.0
    );
    assert_within(
        "ramped free fall / closed form − 1",
        fall / exact - 1.0,
        1e-3,
    );
    // Measured −1.4e-15: round-off, with a floor.
    assert_within("kinetic energy / work − 1", kinetic / work - 1.0, 1e-12);
}
