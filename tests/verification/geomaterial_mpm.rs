//! Drucker–Prager and Mohr–Coulomb inside the MPM solvers: plane-strain
//! unconfined compression of a block by a smooth rigid platen
//! (`problems/unconfined_compression.toml`) in the explicit, implicit
//! quasi-static and implicit Newmark paths. The stress stays homogeneous with
//! σ_xx = 0, and σ_yy must reach the plane-strain unconfined strength
//! −2c cos φ/(1 − sin φ) (Mohr–Coulomb, and Drucker–Prager fitted to it in plane
//! strain) once the block has been compressed three times its yield strain.
//! The quasi-static runs also check the Newton iterations of the plastic steps.

use crate::common::{
    assert_within, newton_order, problem, read_newton, run_text, step_residuals, Table,
};
use mpm::run::summary::Status;

const C: f64 = 1.0e4;

/// The strength at volume ratio J: the yield function acts on τ = Jσ, so the
/// Cauchy limit carries c/J (J − 1 is the plastic dilation, below 1 %).
fn strength(j: f64) -> f64 {
    let phi = 30f64.to_radians();
    -2.0 * C * phi.cos() / (j * (1.0 - phi.sin()))
}

/// Drucker–Prager fitted in plane strain. Its limit needs steady plastic flow
/// (σ_zz settles at s_zz = −2βq/3), so the platen goes four times further
/// (2 % strain) than for Mohr–Coulomb.
const DP: [&str; 3] = [
    "material.0.model=drucker_prager",
    "material.0.mohr_coulomb_fit=plane_strain",
    "boundary.2.velocity=[0.0,-0.02]",
];

/// The problem with its `[solver]` table replaced by `solver` (None: as shipped).
fn scene(solver: Option<&str>) -> String {
    let text = std::fs::read_to_string(problem("unconfined_compression.toml")).unwrap();
    match solver {
        None => text,
        Some(s) => {
            let (head, tail) = text.split_once("[solver]").unwrap();
            let (_, output) = tail.split_once("[output]").unwrap();
            format!("{head}{s}\n[output]{output}")
        }
    }
}

/// Mean stresses of a run.
struct Result {
    syy: f64,
    /// Mean |σ_xx|.
    sxx: f64,
    /// Largest deviation of σ_yy from its mean.
    spread: f64,
    /// Mean volume ratio V/V0.
    j: f64,
}

/// Run and return the mean stresses and the output directory.
fn run(text: &str, overrides: &[&str]) -> (Result, tempfile::TempDir) {
    let (result, dir) = run_text(text, overrides);
    let summary = result.unwrap_or_else(|e| panic!("{overrides:?}: {e}"));
    assert_eq!(summary.status, Status::Completed);
    let p = Table::read(&dir.path().join("particles_final.csv")).unwrap();
    let n = p.col("syy").len() as f64;
    let syy = p.col("syy").iter().sum::<f64>() / n;
    let sxx = p.col("sxx").iter().map(|s| s.abs()).sum::<f64>() / n;
    let spread = p
        .col("syy")
        .iter()
        .map(|s| (s - syy).abs())
        .fold(0.0, f64::max);
    let j = p
        .col("volume")
        .iter()
        .zip(p.col("volume0"))
        .map(|(v, v0)| v / v0)
        .sum::<f64>()
        / n;
    (
        Result {
            syy,
            sxx,
            spread,
            j,
        },
        dir,
    )
}

/// The mean σ_yy within `tol` of the strength, the mean |σ_xx| within
/// `sxx_tol` of it.
fn check(name: &str, r: &Result, tol: f64, sxx_tol: f64) {
    let limit = strength(r.j);
    let e = (r.syy - limit).abs() / limit.abs();
    eprintln!(
        "{name}: σ_yy = {:.5e} (plane-strain unconfined strength {limit:.5e} at J = {:.5}; {:.5e} at J = 1), rel. error {e:.1e}; mean |σ_xx| = {:.1e}, spread of σ_yy = {:.1e}",
        r.syy, r.j, strength(1.0), r.sxx, r.spread
    );
    assert_within(&format!("{name}: σ_yy against the strength"), e, tol);
    assert_within(
        &format!("{name}: mean |σ_xx| (0 at the free side) / the strength"),
        r.sxx / limit.abs(),
        sxx_tol,
    );
}

#[test]
fn quasi_static_reaches_the_limit_with_quadratic_newton() {
    let text = scene(None);
    // Yield at a strain of 1.7e-3: Mohr–Coulomb in 3 steps of 1.67e-3 (steps 2 and
    // 3 plastic), Drucker–Prager in 6 steps of 3.3e-3 (all plastic).
    let mc = ["solver.load_steps=3"];
    let dp = ["solver.load_steps=6", DP[0], DP[1], DP[2]];
    // Measured: MC 3.1e-9 and 3.2e-9 (Newton's tolerance), DP 6.1e-5; mean
    // |σ_xx| 6.1e-5 to 6.7e-5 of the strength.
    for (name, overrides, tol) in [
        ("MC ψ = 10°", mc.to_vec(), 1e-8),
        ("MC ψ = 0", vec![mc[0], "material.0.dilation_angle=0"], 1e-8),
        ("DP plane strain ψ = 10°", dp.to_vec(), 1.5e-4),
    ] {
        let (r, dir) = run(&text, &overrides);
        check(&format!("quasi-static {name}"), &r, tol, 1.5e-4);
        let newton = read_newton(&dir.path().join("newton.csv"));
        for s in [2.0, 3.0] {
            let r = step_residuals(&newton, s);
            let (order, iterations) = newton_order(&r);
            eprintln!("   step {s}: residuals {r:?}: order {order:.2}, {iterations} iterations");
            assert!(
                iterations <= 8,
                "{name} step {s}: at most 8 Newton iterations"
            );
            assert!(
                order > 1.8,
                "{name} step {s}: quadratic convergence (order {order:.2} > 1.8)"
            );
        }
    }
}

/// Explicit and Newmark: a dense block (ρ = 2000 kg/m³, no gravity) starting with
/// the velocity field of the platen, v_y = −v y / (1 m) (no impact wave).
#[test]
fn explicit_and_newmark_reach_the_limit() {
    let base = ["material.0.density=2000.0", "gravity=[0.0,0.0]"];
    let start = |v: &str| format!("body.0.velocity_expr=[\"0\",\"-{v}*y\"]");
    let explicit = scene(Some("[solver]\nkind = \"explicit\"\nend_time = 1.0\n"));
    let newmark = scene(Some(
        "[solver]\nkind = \"implicit\"\nintegrator = \"newmark\"\nend_time = 1.0\ndt = 0.05\n",
    ));
    for (solver, text) in [("explicit", &explicit), ("Newmark", &newmark)] {
        let (mc_start, dp_start) = (start("0.005"), start("0.02"));
        for (name, mut extra) in [
            ("MC", vec![mc_start.as_str()]),
            ("DP plane strain", vec![dp_start.as_str()]),
        ] {
            if name.starts_with("DP") {
                extra.extend(DP);
            }
            let overrides: Vec<&str> = base.iter().copied().chain(extra).collect();
            let (r, _dir) = run(text, &overrides);
            // Measured 1.3e-3 to 7.0e-3; mean |σ_xx| up to 2.5e-3 of the strength.
            check(&format!("{solver} {name}"), &r, 1e-2, 1e-2);
        }
    }
}

/// The matrix-free path (GMRES on finite-difference Jacobian products, no
/// assembled plastic tangent) reaches the same limit as the direct path, for
/// both models, and ends on the same stresses.
#[test]
fn matrix_free_newton_krylov_reaches_the_limit() {
    let text = scene(None);
    let krylov = ["solver.linear_solver=gmres", "solver.krylov_tolerance=1e-8"];
    let mc = ["solver.load_steps=3"];
    let dp = ["solver.load_steps=6", DP[0], DP[1], DP[2]];
    for (name, models, tol) in [
        ("MC ψ = 10°", mc.to_vec(), 1e-8),
        ("DP plane strain ψ = 10°", dp.to_vec(), 1.5e-4),
    ] {
        let (direct, _d) = run(&text, &models);
        let overrides: Vec<&str> = models.iter().chain(krylov.iter()).copied().collect();
        let (gmres, g) = run(&text, &overrides);
        check(&format!("GMRES {name}"), &gmres, tol, 1.5e-4);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(g.path().join("summary.json")).unwrap())
                .unwrap();
        let (solver, iterations) = (&summary["linear_solver"], &summary["krylov_iterations"]);
        eprintln!("   {solver}: {iterations} Krylov iterations");
        assert_eq!(solver, "gmres");
        assert!(iterations.as_u64().unwrap() > 0);
        let diff = (gmres.syy - direct.syy).abs() / direct.syy.abs();
        let dj = (gmres.j - direct.j).abs();
        eprintln!("   GMRES vs direct σ_yy: {diff:.1e}, V/V0: {dj:.1e}");
        // Measured 2.2e-16 and 1.4e-14 at most: round-off, with floors.
        assert_within(&format!("{name}: GMRES against direct, V/V0"), dj, 1e-12);
        assert_within(&format!("{name}: GMRES against direct, σ_yy"), diff, 1e-10);
    }
}
