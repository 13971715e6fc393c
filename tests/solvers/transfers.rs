//! The explicit step's two transfer paths (`solver.transfer`, docs/scene.md):
//! the scatter on a box of nodes (`solver::explicit::scatter`) against the node
//! map's gathers (`solver::explicit`). Their sums differ in order only, so the
//! two runs agree to round-off, with every scheme and separable family, face
//! conditions, a friction face, local damping, a PIC/FLIP blend, a point load
//! and a material with history. The scatter is what runs by default where it
//! serves, and it refuses nothing silently: where it cannot serve, the node
//! map runs and summary.json says so.

use crate::common::{run_problem, run_text, Table};
use mpm::run::summary::Summary;
use mpm::solver::report::TransferPath;

/// An elastic block thrown at a rough floor against a roller wall: gravity, a
/// point load on its top corner, local damping, a PIC/FLIP blend.
const BLOCK: &str = r#"dimension = 2
gravity = [0.0, -9.81]
[grid]
min = [0.0, 0.0]
max = [1.0, 0.5]
cells = [40, 20]
[[material]]
name = "m"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e5
poisson_ratio = 0.3
[[body]]
name = "b"
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [0.5, 0.25]
particles_per_cell = 2
velocity = [0.2, -0.05]
[[boundary]]
face = "xmin"
condition = "roller"
[[boundary]]
face = "ymin"
condition = "friction"
friction_coefficient = 0.3
[[load]]
kind = "point"
body = "b"
region_min = [0.45, 0.2]
region_max = [0.5, 0.25]
force = [0.0, -20.0]
[solver]
kind = "explicit"
end_time = 0.1
cfl = 0.3
flip = 0.95
damping = 0.05
[output]
frames = 0
history_interval = 0.01
"#;

/// The particle columns compared, and the largest difference between two runs
/// in each relative to the column's largest magnitude.
fn differences(a: &Table, b: &Table) -> Vec<(&'static str, f64)> {
    ["x", "y", "vx", "vy", "sxx", "syy", "szz", "sxy", "volume"]
        .into_iter()
        .map(|c| {
            let (a, b) = (a.col(c), b.col(c));
            let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            (c, diff / scale)
        })
        .collect()
}

/// Run `scene` (text, or a problem name) with `transfer` and the overrides;
/// the particles at the end and the path summary.json reports.
fn run(scene: &str, transfer: &str, overrides: &[&str]) -> (Table, TransferPath) {
    let set = format!("solver.transfer=\"{transfer}\"");
    let all = [overrides, &[set.as_str()]].concat();
    let (summary, dir) = match scene.ends_with(".toml") {
        true => run_problem(scene, &all),
        false => run_text(scene, &all),
    };
    let summary: Summary = summary.unwrap_or_else(|e| panic!("{scene} {all:?}: {e}"));
    let particles = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    (particles, summary.solver.transfer.expect("explicit"))
}

/// Scatter and gather agree to `tol` (relative to each column's largest value).
fn agree(scene: &str, overrides: &[&str], tol: f64) {
    let (scatter, path) = run(scene, "auto", overrides);
    assert_eq!(
        path,
        TransferPath::Scatter,
        "{overrides:?}: the scatter serves"
    );
    let (gather, path) = run(scene, "gather", overrides);
    assert_eq!(path, TransferPath::Gather);
    for (column, d) in differences(&scatter, &gather) {
        assert!(
            d <= tol,
            "{overrides:?}: {column} differs by {d:.2e} (relative)"
        );
    }
}

#[test]
fn scatter_and_gather_agree_for_every_scheme_and_separable_family() {
    // Elastic, 159 steps: the differences stay at round-off (measured at most
    // 2e-13 of each column's largest value).
    for shape in ["linear", "ugimp", "cpgimp", "bspline2"] {
        for scheme in ["usl", "usf", "musl"] {
            if scheme == "usf" && shape == "cpgimp" {
                continue; // the node map runs (below)
            }
            if scheme == "usl" && shape == "linear" {
                // Hats with USL lose this block at step 48 on both paths alike
                // (an inverted particle at the loaded corner, where a node
                // holds a sliver of mass: the cell-crossing failure of USL).
                continue;
            }
            let shape = format!("grid.shape_function=\"{shape}\"");
            let scheme = format!("solver.scheme=\"{scheme}\"");
            agree(BLOCK, &[&shape, &scheme], 1e-11);
        }
    }
}

#[test]
fn scatter_and_gather_agree_with_apic() {
    // APIC's affine moments on the box (per-axis inertia) and on the node map
    // (the whole D_p): the block without its FLIP fraction, every scheme.
    let block = BLOCK.replace("flip = 0.95\n", "velocity_transfer = \"apic\"\n");
    for shape in ["ugimp", "bspline2"] {
        for scheme in ["usl", "usf", "musl"] {
            let shape = format!("grid.shape_function=\"{shape}\"");
            let scheme = format!("solver.scheme=\"{scheme}\"");
            agree(&block, &[&shape, &scheme], 1e-11);
        }
    }
}

#[test]
fn scatter_and_gather_agree_for_a_collapsing_frictional_column() {
    // Mohr–Coulomb with history, the rough base of the collapse scene, 0.025 s
    // (measured: at most 9e-13 of each column's largest value at 0.05 s).
    for scheme in ["usl", "musl"] {
        let scheme = format!("solver.scheme=\"{scheme}\"");
        agree(
            "collapse.toml",
            &["solver.end_time=0.025", "output.frames=0", &scheme],
            1e-10,
        );
    }
}

#[test]
fn the_node_map_runs_where_the_scatter_does_not_serve() {
    for set in [
        ["grid.shape_function=\"cpgimp\"", "solver.scheme=\"usf\""],
        ["grid.shape_function=\"cpdi\"", "solver.scheme=\"usl\""],
        ["solver.fbar=true", "solver.scheme=\"usl\""],
    ] {
        let (_, path) = run(BLOCK, "auto", &[set[0], set[1], "solver.end_time=0.01"]);
        assert_eq!(path, TransferPath::Gather, "{set:?}");
    }
}
