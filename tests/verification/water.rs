//! Effective stress with a prescribed pore-water field (`[water]`,
//! docs/pore_water.md): σ = σ′ − p I in the momentum balance, σ′ in the models.
//!
//! - Hydrostatic column: a column (one cell wide, rollers on the sides, fixed
//!   base, one particle per cell) loaded by gravity from zero stress in one
//!   quasi-static step, water table 3 m below its top. With one particle per cell
//!   the cell's force is the weight above the particle, so the discrete column is
//!   exact: σ_yy = −γ_sat (H − Y), p = γ_w (h − Y)⁺, σ′_yy = σ_yy + p,
//!   σ′_xx = σ′_zz = ν/(1 − ν) σ′_yy (laterally confined), σ_xx = σ′_xx − p, at
//!   round-off of Newton's tolerance.
//! - K0 with a water table: `[geostatic]` with K0 = ν/(1 − ν) sets
//!   σ′_v = σ_v + p, σ′_h = K0 σ′_v; it is in equilibrium with the water, so a
//!   quasi-static stage with full gravity and 0.2 s of explicit dynamics leave it
//!   there (without the pore pressure in the explicit force the unbalanced
//!   γ_w/γ_sat g would move it 0.1 m).

use crate::common::{face, run_text, Block, Table};

/// γ_sat = ρ g = 20, γ_w = 10 (units m, kN, kPa, Mg).
const GAMMA_SAT: f64 = 20.0;
const GAMMA_W: f64 = 10.0;
const NU: f64 = 0.25;

/// A 1 m wide, 10 m high column with its water table at y = 7.
const COLUMN: Block = Block {
    gravity: Some([0.0, -10.0]),
    grid_max: [1.0, 10.0],
    cells: [1, 10],
    density: 2.0,
    youngs_modulus: 1.0e5,
    poisson_ratio: NU,
    body_max: [1.0, 10.0],
    body_keys: "particles_per_cell = 1",
    faces: &[
        face("xmin", "roller"),
        face("xmax", "roller"),
        face("ymin", "fixed"),
    ],
    tables: "[water]\nunit_weight = 10.0\nlevel = 7.0",
    solver: "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\nload_steps = 1",
    ..Block::DEFAULT
};

/// The closed-form pore pressure at height y below a table at `level`.
fn pore(level: f64, y: f64) -> f64 {
    GAMMA_W * (level - y).max(0.0)
}

/// Largest |a − b| over the particles, for columns `a` and the values `b`.
fn worst(a: &[f64], b: impl Fn(usize) -> f64) -> f64 {
    (0..a.len())
        .map(|i| (a[i] - b(i)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn hydrostatic_column_under_gravity_has_the_closed_form_stresses() {
    let (result, dir) = run_text(&COLUMN.toml(), &[]);
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (y0, sxx, syy, szz, pw) = (
        p.col("Y0"),
        p.col("sxx"),
        p.col("syy"),
        p.col("szz"),
        p.col("p_water"),
    );
    let k0 = NU / (1.0 - NU);
    let scale = GAMMA_SAT * 10.0;
    // The one step's pore pressure is evaluated at its start: the reference positions.
    let e_p = worst(pw, |i| pore(7.0, y0[i]));
    let effective_v = |i: usize| -GAMMA_SAT * (10.0 - y0[i]) + pore(7.0, y0[i]);
    let e_v = worst(syy, effective_v);
    let e_h = worst(sxx, |i| k0 * effective_v(i)).max(worst(szz, |i| k0 * effective_v(i)));
    // Total stresses σ = σ′ − p I.
    let total_v: Vec<f64> = (0..y0.len()).map(|i| syy[i] - pw[i]).collect();
    let total_h: Vec<f64> = (0..y0.len()).map(|i| sxx[i] - pw[i]).collect();
    let e_tv = worst(&total_v, |i| -GAMMA_SAT * (10.0 - y0[i]));
    let e_th = worst(&total_h, |i| k0 * effective_v(i) - pore(7.0, y0[i]));
    eprintln!(
        "hydrostatic column (errors / γ_sat H): p {:.1e}, σ′_v {:.1e}, σ′_h {:.1e}, σ_v {:.1e}, σ_h {:.1e}",
        e_p / scale,
        e_v / scale,
        e_h / scale,
        e_tv / scale,
        e_th / scale
    );
    assert!(pw.contains(&0.0) && pw.iter().any(|&x| x > 0.0));
    // Round-off of the pore pressure; Newton's tolerance (1e-9 of the load) on the stresses.
    assert!(e_p < 1e-12 * scale, "p: {e_p:.3e}");
    for (what, e) in [("σ′_v", e_v), ("σ′_h", e_h), ("σ_v", e_tv), ("σ_h", e_th)] {
        assert!(e < 1e-8 * scale, "{what}: {e:.3e} of γ_sat H = {scale}");
    }
    // Quadratic Newton: one correction brings the linear-looking problem to round-off.
    let newton = crate::common::read_newton(&dir.path().join("newton.csv"));
    let r = newton.col("residual");
    eprintln!("hydrostatic column: Newton residuals {r:?}");
    assert!(r.len() <= 4, "Newton took {} iterations", r.len());
}

/// Level ground 4 m deep on a 5 m grid, 2 × 2 particles per cell, water table
/// at y = 3, K0 = ν/(1 − ν).
const LEVEL: Block = Block {
    gravity: Some([0.0, -10.0]),
    grid_max: [2.0, 5.0],
    cells: [2, 5],
    density: 2.0,
    poisson_ratio: NU,
    body_max: [2.0, 4.0],
    faces: &[
        face("xmin", "roller"),
        face("xmax", "roller"),
        face("ymin", "fixed"),
    ],
    tables: "[geostatic]\nk0 = 0.3333333333333333\n[water]\nunit_weight = 10.0\nlevel = 3.0",
    solver: "kind = \"implicit\"\nintegrator = \"quasi_static\"\nend_time = 1.0\n\
             load_steps = 1\ngravity_ramp = false",
    ..Block::DEFAULT
};

/// The largest displacement and the largest stress errors against the K0 state
/// with the water table at y = 3, relative to γ_sat H.
fn k0_errors(p: &Table) -> (f64, f64, f64) {
    let (x0, y0, x, y) = (p.col("X0"), p.col("Y0"), p.col("x"), p.col("y"));
    let u = (0..x.len())
        .map(|i| (x[i] - x0[i]).hypot(y[i] - y0[i]))
        .fold(0.0, f64::max);
    let effective_v = |i: usize| -GAMMA_SAT * (4.0 - y0[i]) + pore(3.0, y0[i]);
    let scale = GAMMA_SAT * 4.0;
    let e_v = worst(p.col("syy"), effective_v) / scale;
    let e_h = (worst(p.col("sxx"), |i| effective_v(i) / 3.0))
        .max(worst(p.col("szz"), |i| effective_v(i) / 3.0))
        / scale;
    (u, e_v, e_h)
}

#[test]
fn k0_state_with_a_water_table_stays_at_the_closed_form() {
    let (result, dir) = run_text(&LEVEL.toml(), &[]);
    result.unwrap();
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let (u, e_v, e_h) = k0_errors(&p);
    let e_p = worst(p.col("p_water"), |i| pore(3.0, p.col("Y0")[i]));
    eprintln!(
        "K0 with water: displacement {u:.2e} m, σ′_v error {e_v:.1e}, σ′_h error {e_h:.1e}, p error {e_p:.1e}"
    );
    assert!(e_p < 1e-12 * 80.0, "p: {e_p:.3e}");
    assert!(
        e_v < 1e-9 && e_h < 1e-9,
        "σ′ stays at the K0 state: {e_v:.2e} {e_h:.2e}"
    );
    assert!(u < 1e-9, "the K0 state stays put: {u:.3e}");
}

#[test]
fn k0_state_with_a_water_table_is_at_rest_in_the_explicit_solver() {
    // 0.2 s of MUSL on the box scatter and on the node map.
    for transfer in ["solver.transfer=\"auto\"", "solver.transfer=\"gather\""] {
        let explicit = "kind = \"explicit\"\nend_time = 0.2";
        let block = Block {
            solver: explicit,
            ..LEVEL
        };
        let (result, dir) = run_text(&block.toml(), &[transfer]);
        result.unwrap();
        let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
        let (u, e_v, e_h) = k0_errors(&p);
        let v = (p.col("vx").iter().zip(p.col("vy")))
            .map(|(a, b)| a.hypot(*b))
            .fold(0.0, f64::max);
        eprintln!("explicit K0 with water ({transfer}): displacement {u:.2e}, speed {v:.2e}, σ′ errors {e_v:.1e} {e_h:.1e}");
        // γ_w/γ_sat g of unbalanced acceleration would move it ½ 5 (0.2)² = 0.1 m.
        assert!(u < 1e-9 && v < 1e-8, "at rest: {u:.3e} m, {v:.3e} m/s");
        assert!(e_v < 1e-9 && e_h < 1e-9);
    }
}

/// Strength reduction with a water table (`problems/slope_water_table.toml` on
/// the test grid h = 1 m): the Griffiths & Lane slope, dry F = 1.41 on this grid
/// (strength_reduction.rs), loses strength to the pore pressure below its
/// phreatic line (8 m at the back to the toe): measured F = 1.3094.
#[test]
fn water_table_lowers_the_factor_of_safety_of_the_slope() {
    let (result, _dir) =
        crate::common::search_problem("slope_water_table.toml", &["grid.cells=[40,12]"]);
    let s = result.unwrap();
    let fos = s.factor_of_safety.unwrap();
    let (dry, _dry_dir) = crate::common::search_problem(
        "slope_water_table.toml",
        &["grid.cells=[40,12]", "water.unit_weight=1e-9"],
    );
    let f_dry = dry.unwrap().factor_of_safety.unwrap();
    eprintln!("slope with a water table: F = {fos:.4} (dry, the same scene: {f_dry:.4})");
    assert!((fos - 1.3094).abs() < 0.02, "F = {fos:.4}, measured 1.3094");
    assert!(
        f_dry - fos > 0.07,
        "the pore pressure weakens the slope: {f_dry:.4} vs {fos:.4}"
    );
}

/// Undrained gravity loading of the confined column (problems/column.toml,
/// Hencky, ν = 0, E = 1 MPa, quasi-static Newton) with K_w/n = 2 MPa: every
/// particle's excess pore pressure is −K_f ln J and its effective stress the
/// skeleton's Kirchhoff τ′ = E ln λ over J (1D, λ = J), so the stored stress
/// σ′ − p_ex I splits the load in the closed-form ratio. Measured first run
/// (2026-12-02): bottom particle p_ex 25.73 kPa of σ_yy −38.76 kPa.
#[test]
fn undrained_column_shares_its_weight_with_the_pore_water() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/problems/column.toml"
    ))
    .unwrap()
    .replace(
        "poisson_ratio = 0.0",
        "poisson_ratio = 0.0\ndrainage = \"undrained\"\nporosity = 0.5\nwater_bulk_modulus = 1.0e6",
    );
    let (result, out) = crate::common::run_text(&text, &[]);
    result.unwrap_or_else(|e| panic!("{e}"));
    let p = crate::common::Table::read(&out.path().join("particles_final.csv")).unwrap();
    let (syy, pex, v, v0) = (
        p.col("syy"),
        p.col("p_excess"),
        p.col("volume"),
        p.col("volume0"),
    );
    let (e, k_f) = (1.0e6, 2.0e6);
    let mut worst = 0.0f64;
    for q in 0..syy.len() {
        let ln_j = (v[q] / v0[q]).ln();
        let effective = syy[q] + pex[q];
        worst = worst
            .max((pex[q] + k_f * ln_j).abs() / syy[q].abs())
            .max((effective - e * ln_j / (v[q] / v0[q])).abs() / syy[q].abs());
    }
    let bottom = (0..syy.len())
        .max_by(|&a, &b| pex[a].total_cmp(&pex[b]))
        .unwrap();
    eprintln!(
        "undrained column: bottom p_ex {:.1} Pa of σ_yy {:.1} Pa; worst closed-form error {worst:.1e} of |σ_yy|",
        pex[bottom], syy[bottom]
    );
    assert!(
        pex[bottom] > 0.6 * syy[bottom].abs(),
        "the water carries about 2/3"
    );
    assert!(
        worst < 1e-8,
        "p_ex = −K_f ln J and σ′ = E ln J / J: {worst:.1e}"
    );
}
