//! Rigid smooth strip footing on weightless soil, displacement-controlled
//! (`problems/footing_tresca.toml`, `problems/footing_mc.toml`): the plateau of
//! the load–settlement curve against Prandtl's limit pressure, (2 + π) c_u for
//! Tresca and N_c c with N_c = (N_q − 1) cot φ, N_q = e^{π tan φ} tan²(45° + φ/2)
//! for Mohr–Coulomb; quadratic Newton convergence in the plastic steps; the keys
//! of a footing (a velocity condition on a region of a face).

use crate::common::{assert_within, newton_order, run_problem, step_residuals, Table};
use mpm::model::Model;
use mpm::scene::Scene;

/// Prandtl's bearing capacity factor N_c for friction angle φ (degrees).
fn prandtl_nc(phi_deg: f64) -> f64 {
    if phi_deg == 0.0 {
        return 2.0 + std::f64::consts::PI;
    }
    let phi = phi_deg.to_radians();
    let nq = (std::f64::consts::PI * phi.tan()).exp()
        * (std::f64::consts::FRAC_PI_4 + phi / 2.0).tan().powi(2);
    (nq - 1.0) / phi.tan()
}

/// Run a footing scene; check its limit pressure against N_c and the Newton
/// iterations of the last (fully plastic) steps.
/// `max_iterations`: Newton iterations allowed in each of the last two steps;
/// `min_order`: the order their convergence must end at (`newton_order`).
/// Returns the relative error of N_c.
fn footing(
    scene: &str,
    overrides: &[&str],
    phi: f64,
    tol: f64,
    (max_iterations, min_order): (usize, f64),
) -> f64 {
    let (result, dir) = run_problem(scene, overrides);
    let summary = result.unwrap_or_else(|e| panic!("{scene}: {e}"));
    let footing = summary.footing.clone().unwrap();
    let nc = footing.bearing_capacity_factor.unwrap();
    let limit = footing.limit_pressure;
    let plateau = footing.plateau_change;
    let exact = prandtl_nc(phi);
    let error = (nc - exact) / exact;
    eprintln!(
        "{scene}: limit pressure {limit:.5e}, N_c = {nc:.4} (Prandtl {exact:.4}), error {:+.2} %, plateau change {:.2e}, {} Newton iterations in {} steps, {:.1} s",
        100.0 * error,
        plateau,
        summary.solver.newton_iterations.unwrap(),
        summary.steps,
        summary.wall_seconds
    );
    assert_within(&format!("{scene}: N_c error"), error, tol);
    assert!(plateau.abs() < 0.01, "{scene}: the curve has flattened");
    // The curve: starts at zero, rises, and its end is the reported limit.
    let curve = Table::read(&dir.path().join("footing.csv")).unwrap();
    let p = curve.col("pressure");
    assert_eq!(p[0], 0.0);
    assert!(p.len() == summary.steps + 1);
    assert_eq!(*p.last().unwrap(), limit);
    // Newton in the last steps (on the plateau, plastic zone fully developed).
    let newton = Table::read(&dir.path().join("newton.csv")).unwrap();
    let last = newton.col("step").iter().cloned().fold(0.0, f64::max);
    for s in [last - 1.0, last] {
        let r = step_residuals(&newton, s);
        let (order, iterations) = newton_order(&r);
        eprintln!("   step {s}: residuals {r:?}: order {order:.2}, {iterations} iterations");
        assert!(
            iterations <= max_iterations,
            "{scene} step {s}: {iterations} Newton iterations"
        );
        assert!(
            order > min_order,
            "{scene} step {s}: convergence of order {order:.2} (at least {min_order})"
        );
    }
    error
}

#[test]
fn tresca_footing_reaches_prandtl() {
    // Measured +0.64 %.
    // Newton's order at the end of the last two steps: measured 5.1 and 5.1.
    footing("footing_tresca.toml", &[], 0.0, 0.015, (12, 1.8));
}

/// Volumetric locking and F-bar. Tresca flow is isochoric: with bilinear shape
/// functions and 2 × 2 particles per cell the footing locks (N_c +35 % at h = B/8,
/// measured 62, 35, 21, 12 % at h = B/4 … B/32, rate ≈ 0.8), while F-bar (each
/// cell one volume constraint) gives 13.5, 6.5, 2.7, −0.1 % (rate 1.0–1.3, then
/// within 0.1 %; 1094 Newton iterations and 180 s at h = B/32 against 3487 and
/// 542 s locked). Checked on the two coarse grids: the F-bar error within 27 %
/// and 13 % (twice the measured), falling at a rate above 0.9, at most a fifth of the locked one, with
/// quadratic Newton convergence on the plateau (the exact F-bar tangent).
#[test]
fn tresca_footing_with_linear_shapes_locks_and_fbar_cures_it() {
    let linear = |cells: &'static str, fbar: &'static str| {
        ["grid.shape_function=linear", cells, fbar, "output.frames=0"]
    };
    // Measured +13.5 % and +6.5 %: first-order errors, bounded at twice that
    // (the rate and the locked run below hold the line).
    let coarse = footing(
        "footing_tresca.toml",
        &linear("grid.cells=[10,6]", "solver.fbar=true"),
        0.0,
        0.27,
        (12, 1.8), // order measured 2.4 and 2.5
    );
    let fine = footing(
        "footing_tresca.toml",
        &linear("grid.cells=[20,12]", "solver.fbar=true"),
        0.0,
        0.13,
        (12, 1.8), // order measured 8.7 and 2.4
    );
    // Locked, the curve is still rising at the end (plateau change 1.1 %).
    let (result, _dir) = run_problem(
        "footing_tresca.toml",
        &linear("grid.cells=[20,12]", "solver.fbar=false"),
    );
    let nc = result
        .unwrap()
        .footing
        .unwrap()
        .bearing_capacity_factor
        .unwrap();
    let locked = nc / prandtl_nc(0.0) - 1.0;
    let rate = (coarse / fine).log2();
    eprintln!(
        "F-bar N_c errors {coarse:.4}, {fine:.4} (rate {rate:.2}); without F-bar {locked:.4}"
    );
    assert!(rate > 0.9, "F-bar error falls with h at rate {rate:.2}");
    assert!(
        locked > 0.3,
        "bilinear MPM locks without F-bar: +{locked:.3}"
    );
    assert!(
        fine < 0.2 * locked,
        "F-bar: {fine:.3} against {locked:.3} locked"
    );
}

/// φ = 20°, associated flow, with line search (as shipped). On the plateau each
/// step needs 12 to 18 Newton iterations: the residual wanders between 1e-2 and
/// 1e-4 for several iterations (the set of yielding particles still changing)
/// before it drops quadratically (without line search: about 20, and a cut-back).
#[test]
fn mohr_coulomb_footing_reaches_prandtl() {
    // Measured −2.85 % at h = B/16, the first-order error of the footing's edge
    // (`mohr_coulomb_footings_converge_to_prandtl_at_first_order`): bounded at
    // twice that.
    // Newton's order at the end of the last two steps: measured 5.5 and 2.6.
    footing("footing_mc.toml", &[], 20.0, 0.06, (20, 1.8));
}

/// Associated Mohr–Coulomb at φ = 10°, 20° (`footing_mc.toml`) and 30°
/// (`footing_mc_30.toml`: a 10 m × 4.5 m block, E/c = 1e5) at h = B/8 and B/16
/// (issue 16 item 4). The error is the footing's edge: the prescribed control
/// points end at the Greville abscissa B/2 − h/2, the surface is rigid up to
/// B/2 − h only, and the load over the nominal B/2 is low by O(h/B), more so
/// the larger φ. Measured N_c: 8.151, 8.267 (−2.3 %, −0.93 %); 13.989, 14.412
/// (−5.7 %, −2.85 %); 27.522, 28.862 (−8.7 %, −4.2 %); error ratios 2.4, 2.0,
/// 2.05 (first order); the first-order Richardson extrapolation
/// 2 N_c(B/16) − N_c(B/8) = 8.384, 14.835, 30.201 (+0.46 %, +0.00 %, +0.20 %).
/// At B/32 (papers/footing_prandtl): −0.33 %, −1.6 %.
#[test]
#[ignore = "slow tier, 62 s alone on 2 cores (2026-12-04): scripts/slow_tier.sh"]
fn mohr_coulomb_footings_converge_to_prandtl_at_first_order() {
    let cases: [(f64, &str, Vec<&str>); 3] = [
        (
            10.0,
            "footing_mc.toml",
            vec![
                "material.0.friction_angle=10",
                "material.0.dilation_angle=10",
            ],
        ),
        (20.0, "footing_mc.toml", vec![]),
        (30.0, "footing_mc_30.toml", vec![]),
    ];
    for (phi, scene, keys) in cases {
        let exact = prandtl_nc(phi);
        let nc = |fine: bool| {
            let mut overrides = keys.clone();
            if !fine {
                overrides.push(match phi {
                    30.0 => "grid.cells=[40,18]",
                    _ => "grid.cells=[16,10]",
                });
            }
            // The N_c errors are checked below. Newton ends superlinear: at
            // φ = 10°, h = B/8 the last step's residuals fall 2.5e-3, 4.5e-5,
            // 4.0e-8, 2.3e-13, of order 1.75 and 1.72, not 2 (a finding); 2.0 or
            // more in every other step.
            exact * (1.0 + footing(scene, &overrides, phi, 0.2, (60, 1.5)))
        };
        let (coarse, fine) = (nc(false), nc(true));
        let (e_coarse, e_fine) = ((coarse - exact) / exact, (fine - exact) / exact);
        let extrapolated = 2.0 * fine - coarse;
        let e_extrapolated = (extrapolated - exact) / exact;
        eprintln!(
            "φ = {phi}°: N_c {coarse:.4} ({:+.2} %), {fine:.4} ({:+.2} %), ratio {:.2}; \
             Richardson {extrapolated:.4} ({:+.2} %); Prandtl {exact:.4}",
            100.0 * e_coarse,
            100.0 * e_fine,
            e_coarse / e_fine,
            100.0 * e_extrapolated
        );
        // Twice the measured −0.93 %, −2.85 %, −4.24 %: the error is the
        // footing edge's, first order (the ratio, then Richardson, below).
        let tolerance = match phi {
            10.0 => 0.02,
            20.0 => 0.06,
            _ => 0.09,
        };
        assert_within(&format!("φ = {phi}°: N_c error at B/16"), e_fine, tolerance);
        assert!(
            e_coarse < 0.0 && (1.6..3.2).contains(&(e_coarse / e_fine)),
            "φ = {phi}°: first order from below (error ratio 1.6 to 3.2), errors {e_coarse:+.3e}, {e_fine:+.3e}"
        );
        assert!(
            e_extrapolated.abs() < 0.01,
            "φ = {phi}°: extrapolated N_c off by {e_extrapolated:+.3e}"
        );
    }
}

/// φ = 30° within 3 % of Prandtl at h = B/32 (measured 29.436, −2.33 %; 46 080
/// particles, about 3.5 minutes on 2 cores, so not in the default suite):
/// `cargo test --release --test verification -- --ignored mohr_coulomb_30`.
#[test]
#[ignore]
fn mohr_coulomb_30_footing_reaches_prandtl_within_3_percent_at_b_over_32() {
    // Not `footing`: near collapse Newton takes 50–55 iterations a step on this
    // grid and the last step ends on the displacement test at a residual of
    // 7e-9, where its measured order (0.85) says nothing about the tangent.
    let (result, _dir) = run_problem("footing_mc_30.toml", &["grid.cells=[160,72]"]);
    let summary = result.unwrap();
    let footing = summary.footing.unwrap();
    let nc = footing.bearing_capacity_factor.unwrap();
    let error = nc / prandtl_nc(30.0) - 1.0;
    eprintln!(
        "φ = 30° at B/32: N_c = {nc:.4}, error {:+.2} %, plateau change {:.2e}",
        100.0 * error,
        footing.plateau_change
    );
    assert!(error.abs() < 0.03, "N_c off by {error:+.3e}");
    assert!(
        footing.plateau_change.abs() < 0.01,
        "the curve has flattened"
    );
}

/// A footing scene whose `[[boundary]]` table of the footing is replaced by `footing`.
fn with_footing(footing: &str) -> String {
    let text = std::fs::read_to_string(crate::common::problem("footing_tresca.toml")).unwrap();
    let start = text.find("[[boundary]]\nface = \"ymax\"").unwrap();
    let end = text.find("[solver]").unwrap();
    format!("{}{footing}\n{}", &text[..start], &text[end..])
}

#[test]
fn bad_footing_keys_are_named_with_their_line() {
    let base = "[[boundary]]\nface = \"ymax\"\ncondition = \"velocity\"\nvelocity = [0.0, -0.01]\ncomponents = [\"y\"]\n";
    for (extra, key, message) in [
        (
            "region_min = [0.0, 3.0]",
            "boundary.3.region_max",
            "is required",
        ),
        (
            "region_min = [0.0, 3.0]\nregion_max = [1.0]",
            "boundary.3.region_max",
            "needs 2 components",
        ),
        (
            "region_min = [1.0, 3.0]\nregion_max = [0.0, 3.0]",
            "boundary.3.region_max",
            "≥ region_min",
        ),
        (
            "footing_width = -1.0",
            "boundary.3.footing_width",
            "positive width",
        ),
    ] {
        let text = with_footing(&format!("{base}{extra}\n"));
        let e = Scene::parse("footing.toml", &text, &[])
            .expect_err(extra)
            .to_string();
        eprintln!("{e}");
        assert!(
            e.contains("footing.toml:") && e.contains(key) && e.contains(message),
            "{extra}: {e}"
        );
    }
    // Not on fixed faces, and not twice.
    let text =
        with_footing("[[boundary]]\nface = \"ymax\"\ncondition = \"fixed\"\nfooting_width = 1.0\n");
    let e = Scene::parse("footing.toml", &text, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("boundary.3.footing_width") && e.contains("does not apply"),
        "{e}"
    );
    let twice = format!("{base}footing_width = 1.0\n{base}footing_width = 1.0\n");
    let e = Scene::parse("footing.toml", &with_footing(&twice), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("boundary.4.footing_width") && e.contains("only one"),
        "{e}"
    );
    // A region that holds no node of its face is an error at build time.
    let text = with_footing(&format!(
        "{base}region_min = [0.0, 2.0]\nregion_max = [1.0, 2.5]\n"
    ));
    let scene = Scene::parse("footing.toml", &text, &[]).unwrap();
    let e = Model::<2>::build(&scene).unwrap_err().to_string();
    eprintln!("{e}");
    assert!(
        e.contains("boundary.3.region_min") && e.contains("no grid node"),
        "{e}"
    );
}

/// The region selects exactly the face nodes inside the box, edges included, and
/// the footing's load is the sum of their normal reactions.
#[test]
fn region_selects_the_face_nodes_in_the_box() {
    let scene = Scene::load(
        &crate::common::problem("footing_tresca.toml"),
        &["grid.shape_function=linear".into()],
    )
    .unwrap();
    let m = Model::<2>::build(&scene).unwrap();
    let f = m.footing.as_ref().expect("the scene has a footing");
    let g = &m.grid;
    let nodes: Vec<f64> = (0..g.node_count())
        .map(|n| g.node_ijk(n))
        .filter(|&ijk| f.condition.acts_on(g, ijk))
        .map(|ijk| g.node_position(ijk)[0])
        .collect();
    // h = 0.25: x = 0, 0.25, 0.5, 0.75, 1.0 on y = 3.
    assert_eq!(nodes, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    assert_eq!(f.width, 1.0);
    assert_eq!(f.cohesion, Some(1.0e4));
    assert_eq!(f.settlement_rate(), 0.01);
    // Reactions: a node under the footing pushed down by 2, one beside it (not
    // part of the footing) by 5.
    let under = g.node_index([2, 12]) as u32;
    let beside = g.node_index([6, 12]) as u32;
    let r = [
        (under, mpm::dim::Vector::<2>::new(0.3, -2.0)),
        (beside, mpm::dim::Vector::<2>::new(0.0, -5.0)),
    ];
    assert_eq!(f.load(g, &r), 2.0);
}

/// The footing pressure of a 3D scene is the load over W² (a square of side W):
/// a 3D slab W = 0.5 m thick with rollers on both y faces, the footing across
/// the whole thickness, is the plane-strain problem, so its pressure must equal
/// the 2D run's load per unit thickness over W (elastic soil, 2 load steps; the
/// fields are uniform in y, so the two agree to the Newton tolerance; load / W
/// in 3D would give half the pressure).
#[test]
fn footing_pressure_in_3d_is_load_over_width_squared() {
    let common = |dim: usize| {
        let (v, lo, hi, cells, max) = if dim == 2 {
            (
                "[0.0, -0.012]",
                "[0.0, 2.5]",
                "[0.5, 2.5]",
                "[16, 10]",
                "[4.0, 2.5]",
            )
        } else {
            (
                "[0.0, 0.0, -0.012]",
                "[0.0, 0.0, 2.5]",
                "[0.5, 0.5, 2.5]",
                "[16, 2, 10]",
                "[4.0, 0.5, 2.5]",
            )
        };
        let (top, axis) = if dim == 2 {
            ("ymax", "y")
        } else {
            ("zmax", "z")
        };
        let y_rollers = if dim == 3 {
            "[[boundary]]\nface = \"ymin\"\ncondition = \"roller\"\n[[boundary]]\nface = \"ymax\"\ncondition = \"roller\"\n"
        } else {
            ""
        };
        let zero = if dim == 2 {
            "[0.0, 0.0]"
        } else {
            "[0.0, 0.0, 0.0]"
        };
        let base = if dim == 2 { "ymin" } else { "zmin" };
        format!(
            "dimension = {dim}\n[grid]\nmin = {zero}\nmax = {max}\ncells = {cells}\nshape_function = \"bspline2\"\n\
             [[material]]\nname = \"soil\"\nmodel = \"linear_elastic\"\ndensity = 1.0e3\nyoungs_modulus = 1.0e8\npoisson_ratio = 0.3\n\
             [[body]]\nmaterial = \"soil\"\nshape = \"{shape}\"\nmin = {zero}\nmax = {max}\nparticles_per_cell = 2\n\
             [[boundary]]\nface = \"xmin\"\ncondition = \"roller\"\n[[boundary]]\nface = \"xmax\"\ncondition = \"roller\"\n{y_rollers}\
             [[boundary]]\nface = \"{base}\"\ncondition = \"fixed\"\n\
             [[boundary]]\nface = \"{top}\"\ncondition = \"velocity\"\nvelocity = {v}\ncomponents = [\"{axis}\"]\n\
             region_min = {lo}\nregion_max = {hi}\nfooting_width = 0.5\n\
             [solver]\nkind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 2\n\
             residual_tolerance = 1e-10\n[output]\nframes = 0\n",
            shape = if dim == 2 { "rectangle" } else { "box" },
        )
    };
    let pressure = |dim: usize| {
        let (result, _dir) = crate::common::run_text(&common(dim), &[]);
        let summary = result.unwrap_or_else(|e| panic!("{dim}D footing: {e}"));
        summary.footing.expect("a footing summary").limit_pressure
    };
    let (p2, p3) = (pressure(2), pressure(3));
    println!("footing pressure: 2D {p2:.6e}, 3D slab {p3:.6e}");
    assert!(p2 > 1e5, "the elastic footing carries a load: {p2}");
    // Measured −1.1e-15: round-off, with a floor.
    assert_within("3D slab pressure / 2D pressure − 1", p3 / p2 - 1.0, 1e-12);
}
