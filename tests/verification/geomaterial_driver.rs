//! Single-material-point tests of the finite-strain Drucker–Prager and
//! Mohr–Coulomb models against closed forms (reference README item 9): drained
//! triaxial compression and extension at constant confining pressure, and
//! direct simple shear at constant normal stress, through the mixed-control
//! driver (lateral or normal stretches solved with the models' consistent
//! tangents). Tension is positive.
//!
//! The yield functions act on the Kirchhoff stress τ = Jσ. Under a constant
//! Cauchy confining stress σ_c the Kirchhoff one is Jσ_c, so the Cauchy limits
//! below carry c/J in place of c (the infinitesimal formulas have J = 1); the
//! printed "small-strain" values are the formulas with J = 1.

use mpm::dim::Mat3;
use mpm::material::driver::{run_mixed, MixedResponse, StressControl};
use mpm::material::drucker_prager::DruckerPrager;
use mpm::material::drucker_prager::{Cone, MohrCoulombFit};
use mpm::material::mohr_coulomb::MohrCoulomb;
use mpm::material::mohr_coulomb::Softening;
use mpm::material::return_mapping::Elasticity;
use mpm::material::Material;
use mpm::material::Strength;

const E: f64 = 5.0e7;
const NU: f64 = 0.3;
const C: f64 = 1.0e4;
const CONFINING: f64 = 1.0e5;

fn strength(c: f64, phi_deg: f64, psi_deg: f64) -> Strength {
    Strength {
        cohesion: c,
        friction_angle: phi_deg.to_radians(),
        dilation_angle: psi_deg.to_radians(),
    }
}

fn mc(c: f64, phi_deg: f64, psi_deg: f64) -> MohrCoulomb {
    MohrCoulomb {
        density: 2000.0,
        youngs_modulus: E,
        poisson_ratio: NU,
        peak: strength(c, phi_deg, psi_deg),
        softening: None,
        tensile_strength: None,
    }
}

fn dp(fit: MohrCoulombFit, phi_deg: f64, psi_deg: f64) -> DruckerPrager {
    DruckerPrager {
        density: 2000.0,
        youngs_modulus: E,
        poisson_ratio: NU,
        cohesion: C,
        friction_angle: phi_deg.to_radians(),
        dilation_angle: psi_deg.to_radians(),
        fit,
    }
}

/// Drained triaxial test: the axial (z) stretch goes linearly to 1 + `axial`
/// (negative: compression), the lateral stresses stay −σ_c (x and y stretch
/// alike). Starts from the
/// isotropic stress −σ_c at F = I.
fn triaxial<M: Material + ?Sized>(m: &M, axial: f64, steps: usize) -> MixedResponse {
    let stretch = |k: usize| 1.0 + axial * k as f64 / steps as f64;
    let increments: Vec<Mat3> = (1..=steps)
        .map(|k| Mat3::from_diagonal(&[1.0, 1.0, stretch(k) / stretch(k - 1)].into()))
        .collect();
    // One unknown for both lateral stretches (axisymmetry).
    let controls = [StressControl {
        stress: (0, 0),
        target: -CONFINING,
        free: (0, 0),
        mirror: Some((1, 1)),
    }];
    run_mixed(
        m,
        &increments,
        &controls,
        0.0,
        Mat3::identity() * -CONFINING,
        vec![0.0; m.n_history()],
        1e-12,
    )
    .expect("triaxial path converges")
}

/// Direct simple shear: ΔF = I + Δγ e_x⊗e_y + x e_y⊗e_y with x solved so that
/// σ_yy = −σ_c; ε_xx = ε_zz = 0 (plane strain), free dilation in y.
fn simple_shear<M: Material + ?Sized>(m: &M, gamma: f64, steps: usize) -> MixedResponse {
    let mut df = Mat3::identity();
    df[(0, 1)] = gamma / steps as f64;
    let control = StressControl {
        stress: (1, 1),
        target: -CONFINING,
        free: (1, 1),
        mirror: None,
    };
    run_mixed(
        m,
        &vec![df; steps],
        &[control],
        0.0,
        Mat3::identity() * -CONFINING,
        vec![0.0; m.n_history()],
        1e-12,
    )
    .expect("simple shear path converges")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Mohr–Coulomb limits in Cauchy stress (module documentation): triaxial
/// compression and extension deviators.
fn mc_compression(c: f64, phi: f64, j: f64) -> f64 {
    2.0 * (c * phi.cos() / j + CONFINING * phi.sin()) / (1.0 - phi.sin())
}

fn mc_extension(c: f64, phi: f64, j: f64) -> f64 {
    2.0 * (c * phi.cos() / j + CONFINING * phi.sin()) / (1.0 + phi.sin())
}

/// Plastic principal strain increments over the last `n` increments of a
/// coaxial (diagonal) path: Δ(ln λ − ε_e) with ε_e from the Kirchhoff stress.
fn plastic_increment(resp: &MixedResponse, n: usize) -> [f64; 3] {
    let r = &resp.response;
    let el = Elasticity::new(E, NU);
    let plastic = |k: usize| {
        let j = r.f[k].determinant();
        let eps_e = el.strain_of_stress(&(r.stress[k] * j));
        [0, 1, 2].map(|a| r.f[k][(a, a)].ln() - eps_e[(a, a)])
    };
    let (a, b) = (plastic(r.f.len() - 1 - n), plastic(r.f.len() - 1));
    [0, 1, 2].map(|i| b[i] - a[i])
}

#[test]
fn mohr_coulomb_triaxial_compression_and_extension() {
    for (c, phi_deg, psi_deg) in [
        (C, 30.0, 10.0),
        (0.0, 35.0, 35.0),
        (C, 0.0, 0.0),
        (C, 20.0, 0.0),
    ] {
        let m = mc(c, phi_deg, psi_deg);
        let (phi, psi) = (f64::to_radians(phi_deg), f64::to_radians(psi_deg));
        let resp = triaxial(&m, -0.06, 60);
        let s = resp.response.stress.last().unwrap();
        let j = resp.response.f.last().unwrap().determinant();
        let q = s[(0, 0)] - s[(2, 2)];
        let expect = mc_compression(c, phi, j);
        let small = mc_compression(c, phi, 1.0);
        let e = rel(q, expect);
        eprintln!(
            "MC compression c = {c:.0e} φ = {phi_deg} ψ = {psi_deg}: q = {q:.6e}, closed form {expect:.6e} (small-strain {small:.6e}, J = {j:.5}), rel. error {e:.1e}"
        );
        assert!(e < 1e-9, "triaxial compression limit to 1e-9: {e:e}");
        // Dilatancy: Δε_v^p / Δε_a^p = −2 sin ψ / (1 − sin ψ) on the compression edge.
        let d = plastic_increment(&resp, 10);
        let ratio = (d[0] + d[1] + d[2]) / d[2];
        let expect = -2.0 * psi.sin() / (1.0 - psi.sin());
        eprintln!("   plastic dilatancy Δε_v/Δε_a = {ratio:.10}, closed form {expect:.10}");
        assert!((ratio - expect).abs() < 1e-8, "dilatancy ratio to 1e-8");
        let resp = triaxial(&m, 0.06, 60);
        let s = resp.response.stress.last().unwrap();
        let j = resp.response.f.last().unwrap().determinant();
        let q = s[(2, 2)] - s[(0, 0)];
        let expect = mc_extension(c, phi, j);
        let e = rel(q, expect);
        eprintln!("MC extension   c = {c:.0e} φ = {phi_deg} ψ = {psi_deg}: q = {q:.6e}, closed form {expect:.6e}, rel. error {e:.1e}");
        assert!(e < 1e-9, "triaxial extension limit to 1e-9: {e:e}");
        // Extension edge: Δε_v^p / Δε_a^p = 2 sin ψ / (1 + sin ψ).
        let d = plastic_increment(&resp, 10);
        let ratio = (d[0] + d[1] + d[2]) / d[2];
        let expect = 2.0 * psi.sin() / (1.0 + psi.sin());
        assert!(
            (ratio - expect).abs() < 1e-8,
            "extension dilatancy {ratio} vs {expect}"
        );
    }
}

#[test]
fn drucker_prager_triaxial_limits_match_the_fitted_vertices() {
    for (phi_deg, psi_deg) in [(30.0, 10.0), (25.0, 25.0), (30.0, 0.0)] {
        let (phi, psi) = (f64::to_radians(phi_deg), f64::to_radians(psi_deg));
        for fit in [
            MohrCoulombFit::Outer,
            MohrCoulombFit::Inner,
            MohrCoulombFit::PlaneStrain,
        ] {
            let m = dp(fit, phi_deg, psi_deg);
            let cone = Cone::fit(fit, C, phi, psi);
            let resp = triaxial(&m, -0.06, 60);
            let s = resp.response.stress.last().unwrap();
            let j = resp.response.f.last().unwrap().determinant();
            let q = s[(0, 0)] - s[(2, 2)];
            // q + 3α σ_m = σ_Y with σ_m = −σ_c − q/3 (Kirchhoff: × J).
            let expect =
                (cone.yield_stress / j + 3.0 * cone.alpha * CONFINING) / (1.0 - cone.alpha);
            let e = rel(q, expect);
            eprintln!("DP {fit:?} compression φ = {phi_deg} ψ = {psi_deg}: q = {q:.6e}, closed form {expect:.6e}, rel. error {e:.1e}");
            assert!(e < 1e-9, "DP triaxial compression limit to 1e-9");
            if fit == MohrCoulombFit::Outer {
                let e = rel(q, mc_compression(C, phi, j));
                assert!(e < 1e-9, "outer cone = Mohr–Coulomb in compression: {e:e}");
            }
            // Dilatancy of the cone: Δε_v^p / Δε_a^p = −3β / (1 − β).
            let d = plastic_increment(&resp, 10);
            let ratio = (d[0] + d[1] + d[2]) / d[2];
            let expect = -3.0 * cone.beta / (1.0 - cone.beta);
            assert!(
                (ratio - expect).abs() < 1e-8,
                "DP dilatancy {ratio} vs {expect}"
            );
            let resp = triaxial(&m, 0.06, 60);
            let s = resp.response.stress.last().unwrap();
            let j = resp.response.f.last().unwrap().determinant();
            let q = s[(2, 2)] - s[(0, 0)];
            let expect =
                (cone.yield_stress / j + 3.0 * cone.alpha * CONFINING) / (1.0 + cone.alpha);
            let e = rel(q, expect);
            eprintln!("DP {fit:?} extension   φ = {phi_deg} ψ = {psi_deg}: q = {q:.6e}, closed form {expect:.6e}, rel. error {e:.1e}");
            assert!(e < 1e-9, "DP triaxial extension limit to 1e-9");
            if fit == MohrCoulombFit::Inner {
                let e = rel(q, mc_extension(C, phi, j));
                assert!(e < 1e-9, "inner cone = Mohr–Coulomb in extension: {e:e}");
            }
        }
    }
}

/// Davis (1968): in plane-strain simple shear at constant normal stress σ_n the
/// limit shear stress on the horizontal (zero-extension) plane is
/// τ = cos ψ (c cos φ − σ_n sin φ) / (1 − sin φ sin ψ): c − σ_n tan φ for ψ = φ,
/// c cos φ − σ_n sin φ for ψ = 0. In Kirchhoff stress with σ_n → Jσ_n.
#[test]
fn simple_shear_limits_for_associated_and_non_dilatant_flow() {
    let phi_deg = 30.0;
    let phi = f64::to_radians(phi_deg);
    let mut limits = Vec::new();
    for psi_deg in [30.0, 0.0] {
        let psi = f64::to_radians(psi_deg);
        let models: [(&str, Box<dyn Material>); 2] = [
            ("MC", Box::new(mc(C, phi_deg, psi_deg))),
            (
                "DP plane strain",
                Box::new(dp(MohrCoulombFit::PlaneStrain, phi_deg, psi_deg)),
            ),
        ];
        for (name, m) in models {
            let resp = simple_shear(m.as_ref(), 0.05, 100);
            let f = resp.response.f.last().unwrap();
            let j = f.determinant();
            let tau = resp.response.stress.last().unwrap() * j;
            let normal = -CONFINING * j;
            let expect =
                psi.cos() * (C * phi.cos() - normal * phi.sin()) / (1.0 - phi.sin() * psi.sin());
            let e = rel(tau[(0, 1)], expect);
            eprintln!(
                "{name} simple shear φ = {phi_deg} ψ = {psi_deg}: τ_xy = {:.6e}, Davis limit {expect:.6e}, rel. error {e:.1e} (J = {j:.5}, max Newton residual history {:?})",
                tau[(0, 1)],
                resp.residuals.last().unwrap()
            );
            // The limit holds for coaxial small elastic strains; at finite strain the
            // material spin turns the elastic state by O(γ_e), γ_e = τ/G the elastic
            // shear strain at the limit (observed: the error falls from 1.7e-3 to
            // 2.8e-4 when E is raised tenfold, ψ = 0).
            let gamma_e = expect / Elasticity::new(E, NU).mu;
            assert!(
                e < gamma_e,
                "{name} ψ = {psi_deg}: simple-shear limit to γ_e = {gamma_e:.1e}, got {e:e}"
            );
            limits.push(tau[(0, 1)]);
        }
    }
    let (assoc, nondil) = (limits[0], limits[2]);
    assert!(
        assoc > 1.1 * nondil,
        "ψ = φ carries more shear than ψ = 0 ({assoc:e} vs {nondil:e})"
    );
}

/// Softening path: c, φ, ψ fall from peak to residual with ε̄p; the deviator
/// follows the current strength and ends at the residual triaxial strength.
#[test]
fn mohr_coulomb_softening_triaxial_ends_at_the_residual_strength() {
    let mut m = mc(C, 30.0, 10.0);
    m.softening = Some(Softening {
        residual_cohesion: 0.2 * C,
        residual_friction_angle: 25f64.to_radians(),
        residual_dilation_angle: 0.0,
        start: 0.005,
        end: 0.04,
    });
    let resp = triaxial(&m, -0.12, 240);
    let r = &resp.response;
    let mut peak: f64 = 0.0;
    for k in 1..r.stress.len() {
        let s = &r.stress[k];
        let j = r.f[k].determinant();
        let q = s[(0, 0)] - s[(2, 2)];
        peak = peak.max(q);
        let kappa = r.history[k][0];
        if kappa > r.history[k - 1][0] {
            let (st, _) = m.strength(kappa);
            let expect = mc_compression(st.cohesion, st.friction_angle, j);
            assert!(
                rel(q, expect) < 1e-9,
                "on the current yield surface at ε̄p = {kappa}"
            );
        }
    }
    let kappa = r.history.last().unwrap()[0];
    let j = r.f.last().unwrap().determinant();
    let q = {
        let s = r.stress.last().unwrap();
        s[(0, 0)] - s[(2, 2)]
    };
    let residual = mc_compression(0.2 * C, 25f64.to_radians(), j);
    let peak_form = mc_compression(C, 30f64.to_radians(), 1.0);
    eprintln!(
        "MC softening: peak q = {peak:.6e} (closed form {peak_form:.6e}), final q = {q:.6e} at ε̄p = {kappa:.4}, residual closed form {residual:.6e}"
    );
    assert!(kappa > 0.04, "the path passes the residual strain");
    assert!(
        rel(q, residual) < 1e-9,
        "ends at the residual strength to 1e-9"
    );
    assert!(
        rel(peak, peak_form) < 5e-3,
        "peak within 0.5 % of the closed form"
    );
    let iterations: usize = resp.residuals.iter().map(|r| r.len() - 1).max().unwrap();
    assert!(iterations <= 6, "mixed-control Newton with the consistent tangent: ≤ 6 iterations per increment, got {iterations}");
}
