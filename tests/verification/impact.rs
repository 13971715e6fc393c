//! Impact: a planar shock against the Mie–Grüneisen Hugoniot (with and without
//! the artificial bulk viscosity) and the Taylor bar against the measured final
//! shape (Johnson & Holmquist 1988, review `002_…` Table 1).

use crate::common::{
    assert_within, face, face_with, read_output, run_cli, run_problem, run_text, Block, Table,
};

/// Copper Hugoniot at u_p = 500 m/s: U_s = c0 + S u_p, p_H = ρ0 U_s u_p.
const U_P: f64 = 500.0;
const U_S: f64 = 3940.0 + 1.49 * U_P;
const P_H: f64 = 8930.0 * U_S * U_P;

/// (y, −σ_yy/p_H, v_y) of every particle of problems/shock_plate.toml at its end.
fn plate(extra: &[&str]) -> Vec<(f64, f64, f64)> {
    let (result, dir) = run_problem("shock_plate.toml", extra);
    result.expect("the plate runs");
    let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (y, syy, vy) = (t.col("y"), t.col("syy"), t.col("vy"));
    (0..y.len()).map(|i| (y[i], -syy[i] / P_H, vy[i])).collect()
}

/// Mean and standard deviation of the stress and the standard deviation of the
/// velocity behind the shock (1 mm < y < 7 mm, the front is at 8.4 mm).
fn plateau(p: &[(f64, f64, f64)]) -> (f64, f64, f64) {
    let behind: Vec<_> = p.iter().filter(|q| q.0 > 1e-3 && q.0 < 7e-3).collect();
    let n = behind.len() as f64;
    let mean = behind.iter().map(|q| q.1).sum::<f64>() / n;
    let std = (behind.iter().map(|q| (q.1 - mean).powi(2)).sum::<f64>() / n).sqrt();
    let v_mean = behind.iter().map(|q| q.2).sum::<f64>() / n;
    let v_std = (behind.iter().map(|q| (q.2 - v_mean).powi(2)).sum::<f64>() / n).sqrt();
    (mean, std, v_std)
}

#[test]
fn planar_impact_reaches_the_hugoniot_pressure_and_shock_speed() {
    let p = plate(&[]);
    let (mean, std, _) = plateau(&p);
    println!("p/p_H behind the shock: mean {mean:.4}, std {std:.4}");
    // Tolerance 2 % on the mean pressure behind the shock.
    assert!((mean - 1.0).abs() < 0.02, "mean p/p_H {mean}");
    // The front (highest particle above half the Hugoniot pressure) at
    // (U_s − u_p) t = 8.37 mm, within two cells (0.2 mm).
    let front = p
        .iter()
        .filter(|q| q.1 > 0.5)
        .map(|q| q.0)
        .fold(0.0, f64::max);
    let expected = (U_S - U_P) * 2.0e-6;
    println!(
        "front at {:.3} mm, expected {:.3} mm",
        front * 1e3,
        expected * 1e3
    );
    assert!(
        (front - expected).abs() < 0.2e-3,
        "front {front} vs {expected}"
    );
}

#[test]
fn bulk_viscosity_removes_the_ringing_behind_the_shock() {
    let (_, std_q, v_std_q) = plateau(&plate(&[]));
    let off = [
        "solver.bulk_viscosity_quadratic=0.0",
        "solver.bulk_viscosity_linear=0.0",
    ];
    let (_, std_0, v_std_0) = plateau(&plate(&off));
    println!("stress std {std_q:.4} vs {std_0:.4} without; velocity std {v_std_q:.1} vs {v_std_0:.1} m/s");
    assert!(std_q < 0.6 * std_0, "stress ringing {std_q} vs {std_0}");
    assert!(
        v_std_q < 0.5 * v_std_0,
        "velocity ringing {v_std_q} vs {v_std_0}"
    );
}

/// Final length L, impact-face diameter D and the diameter W at 0.2 L0 above the
/// anvil (mm) of a Taylor bar: a 3D quarter (axis z, anvil z = 0) or the
/// axisymmetric r–z model (x = r, y = z). Each particle's final radius is scaled
/// by R/r0, over the outermost ring of particles of a layer; L is the highest
/// particle plus its initial distance to the top face
/// (papers/taylor_bar/measure.py does the same).
fn taylor_shape(t: &Table) -> (f64, f64, f64) {
    taylor_shape_of(t, &|_| true)
}

/// `taylor_shape` over the particles (rows) that `keep` selects.
fn taylor_shape_of(t: &Table, keep: &dyn Fn(usize) -> bool) -> (f64, f64, f64) {
    let (l0, radius) = (25.4, 3.8);
    let mm = |v: f64| v * 1e3;
    let three_d = t.column("z").is_ok();
    let zeros = vec![0.0; t.col("x").len()];
    let (x0, x) = (t.col("X0"), t.col("x"));
    let (y0, y, z0, z) = match three_d {
        true => (t.col("Y0"), t.col("y"), t.col("Z0"), t.col("z")),
        false => (&zeros[..], &zeros[..], t.col("Y0"), t.col("y")),
    };
    let rows: Vec<usize> = (0..z.len()).filter(|&i| keep(i)).collect();
    let bottom = rows.iter().map(|&i| z0[i]).fold(f64::INFINITY, f64::min);
    let spacing = 2.0 * mm(bottom);
    let top = *rows
        .iter()
        .max_by(|&&a, &&b| z[a].total_cmp(&z[b]))
        .unwrap();
    let length = mm(z[top]) + l0 - mm(z0[top]);
    let diameter = |select: &dyn Fn(usize) -> bool| {
        rows.iter()
            .copied()
            .filter(|&i| select(i))
            .filter_map(|i| {
                let r0 = mm(x0[i].hypot(y0[i]));
                (r0 > radius - spacing).then(|| 2.0 * mm(x[i].hypot(y[i])) * radius / r0)
            })
            .fold(0.0, f64::max)
    };
    let d = diameter(&|i| (z0[i] - bottom).abs() < 1e-9);
    let w = diameter(&|i| (mm(z[i]) - 0.2 * l0).abs() < 0.5 * spacing);
    (length, d, w)
}

/// Errors of (L, D, W) against the test's 16.2, 13.5, 10.1 mm and their mean.
fn taylor_errors((l, d, w): (f64, f64, f64)) -> ([f64; 3], f64) {
    let errors = [l / 16.2 - 1.0, d / 13.5 - 1.0, w / 10.1 - 1.0];
    (errors, errors.iter().map(|e| e.abs()).sum::<f64>() / 3.0)
}

/// The coarse Taylor bar: h = 0.76 mm (MPM3D's cell), 2 particles per direction.
const COARSE: &[&str] = &["grid.cells=[11,11,35]"];

#[test]
fn taylor_bar_matches_the_measured_final_shape() {
    let (result, dir) = run_problem("taylor_bar.toml", COARSE);
    result.expect("the Taylor bar runs");
    let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (l, d, w) = taylor_shape(&t);
    let (errors, mean) = taylor_errors((l, d, w));
    println!(
        "L {l:.2} D {d:.2} W {w:.2} mm against 16.2 13.5 10.1: errors {:.3} {:.3} {:.3}, mean {mean:.3}",
        errors[0], errors[1], errors[2]
    );
    // MPM3D's mean error on this test is 0.031 (review Table 1): the same bar.
    // Measured: mean 0.005, L +1.1 %.
    assert_within("mean error against the test", mean, 0.015);
    for (name, e) in ["L", "D", "W"].iter().zip(errors) {
        assert_within(&format!("{name} against the test"), e, 0.03);
    }

    // Energy: kinetic + internal never exceeds the impact energy; the anvil
    // (nodal momentum zeroed at the face) and the bulk viscosity take the rest.
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (kinetic, internal) = (h.col("kinetic"), h.col("strain"));
    let e0 = kinetic[0];
    let ratios: Vec<f64> = (0..kinetic.len())
        .map(|i| (kinetic[i] + internal[i]) / e0)
        .collect();
    let last = *ratios.last().unwrap();
    println!("(kinetic + internal)/E0 at the end: {last:.4}");
    assert!(
        ratios.iter().all(|&r| r <= 1.0 + 1e-6),
        "energy created: {ratios:?}"
    );
    assert!(
        last > 0.94,
        "{last}: more than 6 % of the impact energy unaccounted"
    );
    assert!(
        kinetic.last().unwrap() / e0 < 0.01,
        "the bar is still moving"
    );
}

#[test]
#[ignore = "slow tier, 17 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn axisymmetric_taylor_bar_matches_the_test_and_the_3d_quarter() {
    // h = 0.38 mm against the test.
    let (result, dir) = run_problem("taylor_bar_axisymmetric.toml", &[]);
    result.expect("the axisymmetric Taylor bar runs");
    let fine = taylor_shape(&Table::read(&dir.path().join("particles_final.csv")).unwrap());
    let (errors, mean) = taylor_errors(fine);
    println!("axisymmetric h = 0.38 mm: {fine:.2?}, errors {errors:.3?}, mean {mean:.3}");
    // Measured: mean 0.003, D −0.5 %.
    assert_within("axisymmetric: mean error against the test", mean, 0.01);
    for (name, e) in ["L", "D", "W"].iter().zip(errors) {
        assert_within(&format!("axisymmetric: {name} against the test"), e, 0.015);
    }
    // h = 0.76 mm against the 3D quarter at the same cell size and particles per
    // cell direction: the same solid, so within 1 % (L) and 3 % (D, W).
    let (r_axi, d_axi) = run_problem("taylor_bar_axisymmetric.toml", &["grid.cells=[11,35]"]);
    r_axi.expect("runs");
    let (r_3d, d_3d) = run_problem("taylor_bar.toml", COARSE);
    r_3d.expect("runs");
    let axi = taylor_shape(&Table::read(&d_axi.path().join("particles_final.csv")).unwrap());
    let full = taylor_shape(&Table::read(&d_3d.path().join("particles_final.csv")).unwrap());
    println!("h = 0.76 mm: axisymmetric {axi:.2?}, 3D {full:.2?}");
    assert!((axi.0 / full.0 - 1.0).abs() < 0.01);
    assert!((axi.1 / full.1 - 1.0).abs() < 0.03);
    assert!((axi.2 / full.2 - 1.0).abs() < 0.03);
}

#[test]
fn axisymmetric_taylor_bar_with_cpdi_matches_the_test() {
    // CPDI in axisymmetric mode (plane r–z domain weights, the hoop terms at the
    // particle's centre, as for GIMP): h = 0.38 mm.
    let (result, dir) = run_problem(
        "taylor_bar_axisymmetric.toml",
        &["grid.shape_function=\"cpdi\""],
    );
    result.expect("the axisymmetric Taylor bar runs with CPDI");
    let shape = taylor_shape(&Table::read(&dir.path().join("particles_final.csv")).unwrap());
    let (errors, mean) = taylor_errors(shape);
    println!("axisymmetric CPDI h = 0.38 mm: {shape:.2?}, errors {errors:.3?}, mean {mean:.3}");
    // Measured: mean 0.004, D −0.5 %, W +0.5 %.
    assert_within(
        "axisymmetric CPDI: mean error against the test",
        mean,
        0.012,
    );
    for (name, e) in ["L", "D", "W"].iter().zip(errors) {
        assert_within(
            &format!("axisymmetric CPDI: {name} against the test"),
            e,
            0.015,
        );
    }
}

#[test]
fn taylor_bar_does_not_depend_on_the_number_of_threads() {
    let set = ["grid.cells=[11,11,35]", "solver.end_time=1.0e-5"];
    let one = run_cli("taylor_bar.toml", 1, &set);
    let two = run_cli("taylor_bar.toml", 2, &set);
    for file in ["particles_final.csv", "history.csv"] {
        assert!(
            read_output(&one, file) == read_output(&two, file),
            "{file} differs between 1 and 2 threads"
        );
    }
}

/// A Johnson–Cook block (no analytic tangent) compressed 5 % in uniaxial strain,
/// implicit quasi-static through matrix-free GMRES, in 10 load steps.
const JC_BLOCK: Block = Block {
    cells: [2, 2],
    shape_function: Some("linear"),
    material_name: "copper",
    model: "johnson_cook",
    density: 8930.0,
    youngs_modulus: 117.0e9,
    poisson_ratio: 0.35,
    material_keys:
        "yield_stress = 90.0e6\nhardening_modulus = 292.0e6\nhardening_exponent = 0.31\n\
                    eos = \"mie_gruneisen\"\nsound_speed = 3940.0\nhugoniot_slope = 1.49\n\
                    gruneisen_gamma = 1.96",
    faces: &[
        face("xmin", "roller"),
        face("xmax", "roller"),
        face("ymin", "roller"),
        face_with(
            "ymax",
            "velocity",
            "velocity = [0.0, -0.05]\ncomponents = [\"y\"]",
        ),
    ],
    solver: "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 10\n\
             linear_solver = \"gmres\"\nresidual_tolerance = 1e-10",
    ..Block::DEFAULT
};

#[test]
fn johnson_cook_runs_implicitly_through_the_krylov_path() {
    use mpm::material::{driver, registry};
    let (result, dir) = crate::common::run_text(&JC_BLOCK.toml(), &[]);
    let summary = result.expect("the implicit Johnson-Cook block runs");
    assert!(
        summary.solver.krylov_iterations.unwrap_or(0) > 0,
        "not through the Krylov path"
    );
    let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    // The single point along the same ten increments of uniaxial strain: the top
    // face's nodes move 0.005 per step while the grid is reset, so each step's
    // ΔF_yy = 0.995 and F_yy = 0.995^k.
    let values: toml::Table = toml::from_str(
        "youngs_modulus = 117.0e9\npoisson_ratio = 0.35\nyield_stress = 90.0e6\nhardening_modulus = 292.0e6\nhardening_exponent = 0.31\neos = \"mie_gruneisen\"\nsound_speed = 3940.0\nhugoniot_slope = 1.49\ngruneisen_gamma = 1.96",
    )
    .unwrap();
    let m = registry::build("material.0", "johnson_cook", 8930.0, &values).unwrap();
    let path: Vec<_> = (0..=10)
        .map(|k| {
            nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 0.995f64.powi(k), 1.0))
        })
        .collect();
    let point = driver::run(m.as_ref(), &path, 0.0);
    let expected = point.stress.last().unwrap();
    let eps_p = point.history.last().unwrap()[0];
    assert!(eps_p > 0.01, "the point yields ({eps_p})");
    for (col, (i, j)) in [("sxx", (0, 0)), ("syy", (1, 1)), ("szz", (2, 2))] {
        let e = expected[(i, j)];
        let worst = t
            .col(col)
            .iter()
            .fold(0.0f64, |w, s| w.max((s / e - 1.0).abs()));
        // Measured 4.8e-15: round-off, with a floor.
        assert_within(&format!("{col} against the single point"), worst, 1e-9);
    }
    let worst = t
        .col("eps_p")
        .iter()
        .fold(0.0f64, |w, e| w.max((e / eps_p - 1.0).abs()));
    assert_within("ε̄p against the single point", worst, 1e-9);
}

#[test]
fn eroded_particles_leave_the_transfers_with_their_mass_and_energy_accounted() {
    let (result, dir) = run_problem("erosion_rod.toml", &[]);
    result.expect("the rod runs");
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (mass, eps_p, x0, vx) = (p.col("mass"), p.col("eps_p"), p.col("X0"), p.col("vx"));
    // D = ε̄p/D1 with a constant fracture strain: failed ⇔ ε̄p ≥ 0.2.
    let failed: f64 = (0..mass.len())
        .filter(|&q| eps_p[q] >= 0.2 * (1.0 - 1e-12))
        .map(|q| mass[q])
        .sum();
    let eroded = *h.col("eroded_mass").last().unwrap();
    let total: f64 = mass.iter().sum();
    println!("eroded mass {eroded:.4e} of {total:.4e}");
    assert!(eroded > 0.0 && eroded < 0.2 * total, "{eroded}");
    assert!(
        (eroded / failed - 1.0).abs() < 1e-12,
        "{eroded} vs {failed}"
    );
    // Energy never created; the eroded particles' energy stays in the sums.
    let (kinetic, strain, lost) = (h.col("kinetic"), h.col("strain"), h.col("eroded_energy"));
    let e0 = kinetic[0];
    for i in 0..kinetic.len() {
        assert!(kinetic[i] + strain[i] <= e0 * (1.0 + 1e-6), "row {i}");
        assert!(lost[i] <= kinetic[i] + strain[i]);
    }
    // The halves separate symmetrically: momentum zero to round-off.
    let side = |left: bool| {
        let q: Vec<usize> = (0..x0.len()).filter(|&q| (x0[q] < 6e-3) == left).collect();
        q.iter().map(|&q| mass[q] * vx[q]).sum::<f64>() / q.iter().map(|&q| mass[q]).sum::<f64>()
    };
    let (left, right) = (side(true), side(false));
    println!("halves at {left:.3} and {right:.3} m/s");
    assert!(left < -5.0 && right > 5.0);
    assert!(
        (left + right).abs() < 1e-9 * right,
        "momentum {left} + {right}"
    );
    // Eroded particles are out of the transfers: those failed by 15 µs (the
    // eroded mass is constant from 8 µs on) sit at 20 µs where they were, with the
    // same velocity.
    let (r15, d15) = run_problem("erosion_rod.toml", &["solver.end_time=1.5e-5"]);
    r15.expect("runs");
    let p15 = Table::read(&d15.path().join("particles_final.csv")).unwrap();
    let h15 = Table::read(&d15.path().join("history.csv")).unwrap();
    assert_eq!(h15.col("eroded_mass").last(), Some(&eroded));
    let mut frozen = 0;
    for q in (0..mass.len()).filter(|&q| p15.col("eps_p")[q] >= 0.2 * (1.0 - 1e-12)) {
        for c in ["x", "y", "vx", "vy"] {
            assert_eq!(
                p15.col(c)[q],
                p.col(c)[q],
                "eroded particle {q} moved ({c})"
            );
        }
        frozen += 1;
    }
    assert!(frozen > 10, "{frozen}");
    // Thread independence of the erosion.
    let one = run_cli("erosion_rod.toml", 1, &["solver.end_time=1.0e-5"]);
    let two = run_cli("erosion_rod.toml", 2, &["solver.end_time=1.0e-5"]);
    assert!(read_output(&one, "particles_final.csv") == read_output(&two, "particles_final.csv"));
    assert!(read_output(&one, "history.csv") == read_output(&two, "history.csv"));
}

#[test]
fn a_scene_without_erosion_has_no_erosion_columns() {
    let (result, dir) = run_problem("shock_plate.toml", &["solver.end_time=1.0e-7"]);
    result.expect("runs");
    let text = std::fs::read_to_string(dir.path().join("history.csv")).unwrap();
    assert!(
        text.starts_with("t,kinetic,strain,external_work,body0_x"),
        "{}",
        &text[..80]
    );
}

#[test]
#[ignore = "slow tier, 29 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn taylor_bar_on_a_rigid_anvil_through_contact_matches_the_grid_face_anvil() {
    // The anvil as a rigid body below the bar, met through frictionless contact
    // (issue 14's explicit contact), against the grid face z = 0 as the anvil.
    let path = crate::common::problem("taylor_bar.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let text = text
        .replace(
            "min = [0.0, 0.0, 0.0]\nmax = [8.36e-3, 8.36e-3, 26.6e-3]\ncells = [22, 22, 70]",
            "min = [0.0, 0.0, -1.52e-3]\nmax = [8.36e-3, 8.36e-3, 26.6e-3]\ncells = [11, 11, 37]",
        )
        .replace(
            "[[body]]\nname = \"bar\"",
            "[[material]]\nname = \"anvil\"\nmodel = \"rigid\"\ndensity = 7850.0\n\n\
             [[body]]\nname = \"anvil\"\nmaterial = \"anvil\"\nshape = \"box\"\n\
             min = [0.0, 0.0, -1.52e-3]\nmax = [8.36e-3, 8.36e-3, 0.0]\n\n\
             [[contact]]\nfriction_coefficient = 0.0\n\n[[body]]\nname = \"bar\"",
        );
    assert!(text.contains("[[contact]]") && text.contains("cells = [11, 11, 37]"));
    let (result, dir) = crate::common::run_text(&text, &[]);
    result.expect("the bar on the rigid anvil runs");
    let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    // The bar's particles (body 1).
    let body = t.col("body");
    let contact = taylor_shape_of(&t, &|q| body[q] == 1.0);
    let (r_face, d_face) = run_problem("taylor_bar.toml", COARSE);
    r_face.expect("runs");
    let face = taylor_shape(&Table::read(&d_face.path().join("particles_final.csv")).unwrap());
    println!("contact anvil {contact:.2?}, grid-face anvil {face:.2?}");
    // Measured +0.85 %, −1.84 %, +0.20 %; mean error 1.25 %.
    assert_within(
        "contact anvil: L / grid-face L − 1",
        contact.0 / face.0 - 1.0,
        0.02,
    );
    assert_within(
        "contact anvil: D / grid-face D − 1",
        contact.1 / face.1 - 1.0,
        0.03,
    );
    assert_within(
        "contact anvil: W / grid-face W − 1",
        contact.2 / face.2 - 1.0,
        6e-3,
    );
    let (_, mean) = taylor_errors(contact);
    assert_within("contact anvil: mean error against the test", mean, 0.03);
}

#[test]
fn axisymmetric_contact_with_a_rigid_anvil_matches_the_grid_face_anvil() {
    // The axisymmetric bar (h = 0.38 mm) on a rigid anvil met through
    // frictionless contact, against the grid face z = 0 as the anvil: contact
    // works on the per-radian masses and volume gradients unchanged.
    let path = crate::common::problem("taylor_bar_axisymmetric.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let text = text
        .replace(
            "min = [0.0, 0.0]\nmax = [8.36e-3, 26.6e-3]\ncells = [22, 70]",
            "min = [0.0, -0.76e-3]\nmax = [8.36e-3, 26.6e-3]\ncells = [22, 72]",
        )
        .replace(
            "[[body]]\nname = \"bar\"",
            "[[material]]\nname = \"anvil\"\nmodel = \"rigid\"\ndensity = 7850.0\n\n\
             [[body]]\nname = \"anvil\"\nmaterial = \"anvil\"\nshape = \"rectangle\"\n\
             min = [0.0, -0.76e-3]\nmax = [8.36e-3, 0.0]\n\n\
             [[contact]]\nfriction_coefficient = 0.0\n\n[[body]]\nname = \"bar\"",
        );
    assert!(text.contains("[[contact]]") && text.contains("cells = [22, 72]"));
    let (result, dir) = crate::common::run_text(&text, &[]);
    result.expect("the axisymmetric bar on the rigid anvil runs");
    let t = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let body = t.col("body");
    let contact = taylor_shape_of(&t, &|q| body[q] == 1.0);
    let (r_face, d_face) = run_problem("taylor_bar_axisymmetric.toml", &[]);
    r_face.expect("runs");
    let face = taylor_shape(&Table::read(&d_face.path().join("particles_final.csv")).unwrap());
    println!("axisymmetric: contact anvil {contact:.2?}, grid-face anvil {face:.2?}");
    // Measured +0.72 %, −0.098 %, +0.093 %.
    let what = |c: &str| format!("axisymmetric contact anvil: {c} / grid-face {c} − 1");
    assert_within(&what("L"), contact.0 / face.0 - 1.0, 0.02);
    assert_within(&what("D"), contact.1 / face.1 - 1.0, 3e-3);
    assert_within(&what("W"), contact.2 / face.2 - 1.0, 3e-3);
}

/// A free elastic block flying at 10 m/s towards the x = 1 face of the grid
/// (no boundary conditions, no gravity): it leaves the grid at t ≈ 0.05 s.
const FLYING_BLOCK: Block = Block {
    cells: [10, 10],
    shape_function: Some("cpgimp"),
    density: 1000.0,
    youngs_modulus: 1.0e6,
    poisson_ratio: 0.3,
    body_min: [0.3, 0.3],
    body_max: [0.5, 0.5],
    body_keys: "velocity = [10.0, 0.0]",
    solver: "kind = \"explicit\"\nend_time = 0.1",
    output: "frames = 0\nhistory_interval = 0.005",
    ..Block::DEFAULT
};

#[test]
fn particles_leaving_the_grid_stop_the_run_or_are_removed_with_their_mass_and_energy() {
    // Default: the first particle out stops the run, naming it.
    let (result, _dir) = run_text(&FLYING_BLOCK.toml(), &[]);
    let message = result.expect_err("a particle leaves the grid").to_string();
    assert!(message.contains("left the grid"), "{message}");
    // Implicit: the step that takes it out is committed, so the run stops
    // there; cutting the step back would retry from the committed particles
    // (before: 5 cut-backs, each moving the block on, "t = 5.015625e-2").
    let implicit = [
        "solver.kind=\"implicit\"",
        "solver.integrator=\"newmark\"",
        "solver.dt=0.005",
    ];
    let (result, _dir) = run_text(&FLYING_BLOCK.toml(), &implicit);
    let message = result.expect_err("a particle leaves the grid").to_string();
    assert!(
        message.contains("left the grid")
            && message.contains("t = 5.5")
            && !message.contains("cut-back"),
        "{message}"
    );

    // "remove": the run ends; every particle is out, frozen within one step's
    // travel of the face (v Δt < v h/(2(c + v)) = 0.011 m), with its velocity,
    // and history.csv counts all the mass and the kinetic energy as removed.
    let (result, dir) = run_text(&FLYING_BLOCK.toml(), &["grid.particles_outside=\"remove\""]);
    result.expect("the run ends");
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (x, vx, mass) = (p.col("x"), p.col("vx"), p.col("mass"));
    let total: f64 = mass.iter().sum();
    for q in 0..x.len() {
        assert!(
            x[q] > 1.0 && x[q] < 1.0 + 0.011,
            "particle {q} at x = {}",
            x[q]
        );
        assert!(
            (vx[q] / 10.0 - 1.0).abs() < 1e-9,
            "particle {q}: vx = {}",
            vx[q]
        );
    }
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (removed, lost, kinetic) = (
        h.col("eroded_mass"),
        h.col("eroded_energy"),
        h.col("kinetic"),
    );
    assert_eq!(removed[0], 0.0);
    assert!((removed.last().unwrap() / total - 1.0).abs() < 1e-12);
    let e0 = 0.5 * total * 100.0;
    assert!((kinetic[0] / e0 - 1.0).abs() < 1e-12);
    assert!(
        (lost.last().unwrap() / e0 - 1.0).abs() < 1e-9,
        "{}",
        lost.last().unwrap()
    );
    // Partly out at t = 0.06 s: the mass removed grows monotonically.
    assert!(removed.windows(2).all(|w| w[1] >= w[0]));
    assert!(removed.iter().any(|&m| m > 0.0 && m < total));
}

/// The Hanchak RHT perforation (papers/penetration_hanchak) on `cells` to
/// `end` ms: the rod's residual velocity, checked to have left the slab (constant
/// over the last 0.05 ms), with no concrete particle inside the rod at the end
/// and the energy never created.
fn hanchak_residual_velocity(cells: &str, end: f64) -> f64 {
    use mpm::model::geometry::Geometry;
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/papers/penetration_hanchak/hanchak_rht.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let cells = format!("grid.cells={cells}");
    let (result, dir) = run_text(&text, &[&cells, &format!("solver.end_time={end}")]);
    result.expect("the perforation runs");
    let h = Table::read(&dir.path().join("history.csv")).unwrap();
    let (t, vy, y) = (h.col("t"), h.col("body1_vy"), h.col("body1_y"));
    let v = -vy.last().unwrap();
    let before = (0..t.len()).rev().find(|&i| t[i] <= end - 0.05).unwrap();
    assert!(
        (v + vy[before]).abs() < 0.2,
        "still slowing: {} then {v}",
        -vy[before]
    );
    let (kinetic, strain) = (h.col("kinetic"), h.col("strain"));
    for i in 1..kinetic.len() {
        assert!(
            kinetic[i] + strain[i] <= kinetic[0] * (1.0 + 1e-9),
            "energy created at row {i}"
        );
    }
    // The rod's polygon of the scene moved with the rod.
    let vertices = text.lines().find(|l| l.starts_with("vertices")).unwrap();
    let numbers: Vec<f64> = (vertices.split(|c: char| !(c.is_ascii_digit() || c == '.')))
        .filter_map(|w| w.parse().ok())
        .collect();
    let dy = y.last().unwrap() - y[0];
    let rod = Geometry::Polygon(numbers.chunks(2).map(|c| vec![c[0], c[1] + dy]).collect());
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (body, px, py) = (p.col("body"), p.col("x"), p.col("y"));
    let inside = (0..body.len())
        .filter(|&i| body[i] == 0.0 && rod.contains(&[px[i], py[i]]))
        .count();
    assert_eq!(inside, 0, "concrete particles inside the rod");
    v
}

#[test]
fn hanchak_perforation_approaches_the_test_from_below() {
    // h = 4 mm (14k particles, reproduce.sh's default): measured 541.9 m/s,
    // −12 % against the test's 615; the resolution study
    // (papers/penetration_hanchak/README.md) gives 541.9, 540.4, 565.0,
    // 591.4 m/s at h = 4, 2.84, 2, 1.41 mm: coarse grids under-predict, and the
    // 112k-particle run is within 5 % (the ignored test below).
    let v = hanchak_residual_velocity("[83,215]", 0.45);
    println!("residual velocity {v:.1} m/s against 615");
    assert!(v < 615.0 && v > 0.85 * 615.0, "{v}");
}

#[test]
#[ignore = "7-8 min on 2 cores: cargo test --release --test verification -- --ignored hanchak"]
fn hanchak_perforation_is_within_5_percent_of_the_test_at_112k_particles() {
    // h = 1.41 mm, 112,190 particles: measured 591.4 m/s (−3.8 %) in 5,393 steps.
    let v = hanchak_residual_velocity("[235,609]", 0.45);
    println!("residual velocity {v:.1} m/s against 615");
    assert!((v / 615.0 - 1.0).abs() < 0.05, "{v}");
}
