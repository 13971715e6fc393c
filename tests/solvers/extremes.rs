//! Stability and accuracy at the extremes: particles crossing many cells (and so
//! passing through tiny nodal masses), a nearly incompressible material, and a
//! 1000× stiffness contrast. (Time steps at and beyond the critical one are in
//! `stability.rs`.)

use crate::common::{assert_within, run_problem, run_text, shape_functions, Block, Table};
use mpm::scene::{Scheme, ShapeFunction};
use strum::IntoEnumIterator;

/// A free block translating at v = (1.0, 0.5) across 12 cells: every shape function
/// reproduces a uniform velocity field, so the block must stay unstressed and keep
/// its velocity to round-off while its particles cross cell boundaries (where nodal
/// masses become tiny), for every scheme except USL with linear hats (see below).
#[test]
fn rigid_translation_across_cells_stays_unstressed() {
    let text = Block {
        grid_max: [16.0, 8.0],
        cells: [16, 8],
        model: "neo_hookean",
        poisson_ratio: 0.3,
        body_min: [1.0, 1.0],
        body_max: [3.0, 3.0],
        body_keys: "particles_per_cell = 3\nvelocity = [1.0, 0.5]",
        solver: "kind = \"explicit\"\nend_time = 10.0\ncfl = 0.5",
        output: "frames = 0\nhistory_interval = 1.0",
        ..Block::DEFAULT
    }
    .toml();
    for shape in ShapeFunction::iter() {
        for scheme in Scheme::iter() {
            let (shape, scheme) = (shape.name(), scheme.name());
            if (shape, scheme) == ("linear", "usl") {
                // USL's stress update uses (p_I + Δt f_I)/m_I, ill-conditioned where a
                // particle barely touches a node; with linear hats (gradients that do
                // not vanish with the weight) round-off grows there until the run
                // diverges (step 87 here). Smoother shape functions, USF and MUSL are fine.
                continue;
            }
            let (result, dir) = run_text(
                &text,
                &[
                    &format!("grid.shape_function={shape}"),
                    &format!("solver.scheme={scheme}"),
                ],
            );
            result.unwrap_or_else(|e| panic!("{shape} {scheme}: {e}"));
            let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
            let (mut moved, mut dv, mut s) = (0f64, 0f64, 0f64);
            for i in 0..p.col("id").len() {
                moved = moved.max(
                    (p.col("x")[i] - p.col("X0")[i] - 10.0).abs()
                        + (p.col("y")[i] - p.col("Y0")[i] - 5.0).abs(),
                );
                dv = dv.max((p.col("vx")[i] - 1.0).abs() + (p.col("vy")[i] - 0.5).abs());
                for c in ["sxx", "syy", "szz", "sxy"] {
                    s = s.max(p.col(c)[i].abs());
                }
            }
            // Round-off only (the stress scale of the motion is ρ c |v| ≈ 130):
            // floors of about 1e-12 of the travel (10 m), the speed and that
            // stress, not 2–3 times the measured values (at most 1.3e-13 m,
            // 1.5e-14 m/s, 6.8e-13 Pa over every family and scheme).
            let what = format!("{shape} {scheme}");
            assert_within(&format!("{what}: position error (m)"), moved, 1e-11);
            assert_within(&format!("{what}: velocity error (m/s)"), dv, 1e-12);
            assert_within(&format!("{what}: stress (Pa)"), s, 1e-10);
        }
    }
}

/// Nearly incompressible: ν = 0.49 shrinks the CFL step through λ + 2G; the disks
/// still collide, rebound and recover their energy.
#[test]
fn nearly_incompressible_disks() {
    for model in ["linear_elastic", "neo_hookean"] {
        let (result, dir) = run_problem(
            "disks.toml",
            &[
                "material.0.poisson_ratio=0.49",
                &format!("material.0.model={model}"),
                "output.frames=0",
            ],
        );
        let s = result.unwrap_or_else(|e| panic!("{model}: {e}"));
        let h = Table::read(&dir.path().join("history.csv")).unwrap();
        let e: Vec<f64> = h
            .col("kinetic")
            .iter()
            .zip(h.col("strain"))
            .map(|(k, s)| k + s)
            .collect();
        let (e0, e_end) = (e[0], e[e.len() - 1]);
        let e_min = e.iter().cloned().fold(f64::INFINITY, f64::min);
        println!(
            "{model} ν = 0.49: {} steps, total energy min {:.4} E0, final {:.4} E0",
            s.steps,
            e_min / e0,
            e_end / e0
        );
        assert!(e_min > 0.85 * e0, "{model}: energy min {e_min}, E0 {e0}");
        // Measured −0.44 % and −0.30 %.
        assert_within(
            &format!("{model}: final energy / E0 − 1"),
            e_end / e0 - 1.0,
            1.2e-2,
        );
        assert!(
            *h.col("body0_vx").last().unwrap() < -0.05,
            "{model}: the disks rebound"
        );
    }
}

/// Two layers, the lower 1000× stiffer, under self-weight (dynamic relaxation).
/// The exact σ_yy = −ρg(l0 − Y) does not depend on the stiffness. Standard MPM keeps
/// every particle within about ρ g h / 4 of it (measured 111 Pa against 100). Shape functions with a particle domain or a
/// wider support (GIMP, CPDI, B-splines) mix the soft layer's strain rate into the
/// stiff particles of the cell below the interface: there the error is O(1) (20–35 %
/// of the base stress here) although the run is stable and accurate elsewhere.
#[test]
fn stiffness_contrast_of_a_thousand() {
    let text = r#"dimension = 2
gravity = [0.0, -10.0]
[grid]
min = [0.0, 0.0]
max = [0.5, 10.0]
cells = [1, 20]
[[material]]
name = "soft"
model = "linear_elastic"
density = 80.0
youngs_modulus = 1.0e6
poisson_ratio = 0.0
[[material]]
name = "stiff"
model = "linear_elastic"
density = 80.0
youngs_modulus = 1.0e9
poisson_ratio = 0.0
[[body]]
material = "stiff"
shape = "rectangle"
min = [0.0, 0.0]
max = [0.5, 5.0]
[[body]]
material = "soft"
shape = "rectangle"
min = [0.0, 5.0]
max = [0.5, 10.0]
[[boundary]]
face = "xmin"
condition = "roller"
[[boundary]]
face = "xmax"
condition = "roller"
[[boundary]]
face = "ymin"
condition = "fixed"
[solver]
kind = "explicit"
end_time = 2.0
damping = 0.5
flip = 0.0
[output]
frames = 0
history_interval = 0.1
"#;
    // ρ g h / 4 = 100 Pa.
    let quarter_cell = 80.0 * 10.0 * 0.5 / 4.0;
    // Measured with cubic B-splines: 15.1 kPa next to the interface (1.9 times
    // the base stress; quadratic 2.8 kPa), 3.0 kPa beyond 1 m, 0.9 kPa beyond
    // 2 m, 0.48 kPa at the free top (a finding, not yet explained).
    let cubic = "its error spreads beyond 1 m of the interface (3.0 kPa there)";
    for shape in shape_functions(&[(ShapeFunction::Bspline3, cubic)]) {
        let (degree, shape) = (shape.degree(), shape.name());
        let (result, dir) = run_text(text, &[&format!("grid.shape_function={shape}")]);
        result.unwrap_or_else(|e| panic!("{shape}: {e}"));
        let ke = *Table::read(&dir.path().join("history.csv"))
            .unwrap()
            .col("kinetic")
            .last()
            .unwrap();
        // Stored energy ≈ 10 J: 1e-5 J is relaxed to 1e-6.
        assert!(ke < 1e-5, "{shape}: not relaxed, kinetic energy {ke}");
        let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
        let errors: Vec<(f64, f64)> = p
            .col("Y0")
            .iter()
            .zip(p.col("syy"))
            .map(|(y, s)| ((s + 800.0 * (10.0 - y)).abs(), *y))
            .collect();
        let worst = errors.iter().map(|e| e.0).fold(0.0, f64::max);
        let far = errors
            .iter()
            .filter(|(_, y)| (y - 5.0).abs() > 1.0)
            .map(|e| e.0)
            .fold(0.0, f64::max);
        println!("{shape}: max error {worst:.0} Pa, beyond one metre of the interface {far:.0} Pa (base stress 8000 Pa)");
        if shape == "linear" {
            // Measured 111 Pa: twice ρ g h / 4, the linear basis' intrinsic error.
            assert_within("linear: max error (Pa)", worst, 2.0 * quarter_cell);
        } else {
            // Measured 102 to 103 Pa (uGIMP, cpGIMP, CPDI), 356 Pa (quadratic
            // B-splines), 422 Pa (averaged over the domains).
            let bound = if degree > 1 { 8.0 } else { 2.5 } * quarter_cell;
            assert_within(
                &format!("{shape}: error beyond 1 m of the interface (Pa)"),
                far,
                bound,
            );
        }
    }
}
