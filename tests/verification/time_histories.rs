//! Time histories (`time_history`, `gravity_history`; `scene::curve`): a load,
//! gravity and a face's acceleration following a piecewise-linear curve,
//! each against the closed-form motion of a mass, explicit and Newmark.
//!
//! A free elastic block under a force shared by all its particles (or under
//! gravity) moves as a rigid body: its centre of mass follows
//! x(t) = (F / M) F2(t), with F2 the second integral of the curve from t = 0.
//! The curve is the triangle f = (0, 0) → (0.1, 1) → (0.3, 0), held at 0
//! after: F2(0.5) = 1/600 + 0.05·0.2 + 0.2²/2 − 2.5·0.2³/3 + 0.15·0.2 = 0.055
//! (written out below as the triangle's pieces, independently of the code's
//! evaluator).

use crate::common::{assert_within, run_text, Block, Table};

/// F2(t) of the triangle (0, 0), (0.1, 1), (0.3, 0), 0 after, in closed form.
fn triangle_f2(t: f64) -> f64 {
    let (f1_a, f2_a) = (0.05, 5.0 * 0.1f64.powi(3) / 3.0); // at t = 0.1
    match t {
        t if t <= 0.1 => 5.0 * t.powi(3) / 3.0,
        t if t <= 0.3 => {
            let s = t - 0.1;
            f2_a + f1_a * s + s * s / 2.0 - 2.5 * s.powi(3) / 3.0
        }
        t => triangle_f2(0.3) + 0.15 * (t - 0.3),
    }
}

/// A point force of 2 N on the whole block, following the triangle.
const FORCE: &str = "[[load]]\nkind = \"point\"\nregion_min = [0.0, 0.0]\nregion_max = [1.0, 1.0]\nforce = [2.0, 0.0]\ntime_history = [[0.0, 0.0], [0.1, 1.0], [0.3, 0.0]]\n";

/// The unit block (ρ = 1, M = 1) free in a larger grid, 0.5 s.
const FREE: Block = Block {
    grid_min: [-1.0, -1.0],
    grid_max: [2.0, 2.0],
    cells: [12, 12],
    output: "frames = 0",
    ..Block::DEFAULT
};

const NEWMARK: &str = "kind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 0.5\ndt = 0.005";
const EXPLICIT: &str = "kind = \"explicit\"\nend_time = 0.5";

/// The mean particle displacement (the centre of mass: equal masses) at the end.
fn mean_displacement(text: &str) -> [f64; 2] {
    let (result, dir) = run_text(text, &[]);
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let n = p.col("x").len() as f64;
    let mean = |a: &str, b: &str| {
        (p.col(a).iter().zip(p.col(b)))
            .map(|(x, x0)| x - x0)
            .sum::<f64>()
            / n
    };
    [mean("x", "X0"), mean("y", "Y0")]
}

/// A point force of 2 N on the whole block following the triangle: x(0.5) =
/// 2 F2(0.5) = 0.11 m, explicit and Newmark.
#[test]
fn a_force_history_moves_a_free_block_as_a_mass() {
    let exact = 2.0 * triangle_f2(0.5);
    for (solver, tolerance) in [(EXPLICIT, 2e-5), (NEWMARK, 1e-9)] {
        let block = Block {
            tables: FORCE,
            solver,
            ..FREE
        };
        let [x, y] = mean_displacement(&block.toml());
        // Measured: explicit 7.3e-6 (the force of the step start); Newmark
        // 8.7e-15: the trapezoidal rule's error over a step of a linear force,
        // Δt² (a_n − a_n+1)/12, telescopes to zero over a pulse from 0 to 0
        // (a round-off floor of 1e-9).
        assert_within(
            &format!("{solver}: x / exact − 1"),
            x / exact - 1.0,
            tolerance,
        );
        assert!(y.abs() < 1e-12, "{y}");
    }
}

/// Gravity (0, −3) following the triangle from a CSV file next to the scene:
/// y(0.5) = −3 F2(0.5).
#[test]
fn a_gravity_history_from_a_csv_file() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("gravity.csv");
    std::fs::write(&csv, "time, factor\n0.0, 0.0\n0.1, 1.0\n0.3, 0.0\n").unwrap();
    let exact = -3.0 * triangle_f2(0.5);
    for (solver, tolerance) in [(EXPLICIT, 3e-5), (NEWMARK, 1e-9)] {
        let block = Block {
            gravity: Some([0.0, -3.0]),
            solver,
            ..FREE
        };
        let text = format!("gravity_history = \"gravity.csv\"\n{}", block.toml());
        let file = dir.path().join("scene.toml");
        std::fs::write(&file, &text).unwrap();
        let scene = mpm::scene::Scene::load(&file, &[]).unwrap();
        let out = tempfile::tempdir().unwrap();
        let opts = mpm::run::RunOptions::default();
        crate::common::one_thread(|| mpm::run::run(&scene, out.path(), &opts)).unwrap();
        let p = Table::read(&out.path().join("particles_final.csv")).unwrap();
        let n = p.col("y").len() as f64;
        let y = (p.col("y").iter().zip(p.col("Y0")))
            .map(|(y, y0)| y - y0)
            .sum::<f64>()
            / n;
        // Measured: explicit 1.2e-5, Newmark 3.7e-15 (as above).
        assert_within(
            &format!("{solver}: y / exact − 1"),
            y / exact - 1.0,
            tolerance,
        );
    }
}

/// A block [0, 1]² whose two x faces both follow a motion along x that is
/// slow beside its first mode (50 Hz), so that it moves as the faces do:
/// - acceleration 0.01 m/s² times the triangle (0, 0), (0.5, 1), (1, 0) (rest
///   after): u(1.5) = 0.01 F2(1.5) = 0.01 (0.25 + 0.5 · 0.5) = 5 mm;
/// - velocity 0.004 m/s times the same triangle: u = 0.004 F1 = 2 mm;
/// - displacement 2 mm times the ramp (0, 0), (1, 1), held: u = 2 mm.
///
/// The histories are integrated exactly (`FaceMotion::step_velocity`), so the
/// error is the block's dynamic response only.
#[test]
fn a_face_follows_an_acceleration_velocity_or_displacement_history() {
    const TRIANGLE: &str = "time_history = [[0.0, 0.0], [0.5, 1.0], [1.0, 0.0]]";
    // (vector, history, exact u, tolerance). Measured: acceleration 1.0e-9;
    // velocity 2.8e-6 and displacement 1.7e-5, the ringing of the block
    // after the jump of the faces' acceleration (velocity) or velocity
    // (displacement) at t = 0.
    let motions = [
        (
            "acceleration = [0.01, 0.0]",
            TRIANGLE,
            0.01 * (0.25 + 0.5 * 0.5),
            3e-9,
        ),
        ("velocity = [0.004, 0.0]", TRIANGLE, 0.004 * 0.5, 1e-5),
        (
            "displacement = [0.002, 0.0]",
            "time_history = [[0.0, 0.0], [1.0, 1.0]]",
            0.002,
            5e-5,
        ),
    ];
    let solvers = [
        "kind = \"explicit\"\nend_time = 1.5",
        "kind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 1.5\ndt = 0.01",
    ];
    for (vector, history, exact, tolerance) in motions {
        for solver in solvers {
            let block = Block {
                solver,
                ..Block::DEFAULT
            };
            let mut text = block.toml();
            for face in ["xmin", "xmax"] {
                text += &format!(
                    "[[boundary]]\nface = \"{face}\"\ncondition = \"velocity\"\n{vector}\ncomponents = [\"x\"]\n{history}\n"
                );
            }
            let [x, _] = mean_displacement(&text);
            let what = format!("{vector}, {solver}: u / exact − 1");
            assert_within(&what, x / exact - 1.0, tolerance);
        }
    }
}
